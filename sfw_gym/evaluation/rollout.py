"""One episode of one agent, start to end: :class:`EpisodeSpec` (what a worker needs) in, the
episode's JSON record out (the env's metrics, the zone-band metric, the coverage curve, the stop
reason), with its ``.npz`` (belief, truth, trajectory, decisions) and GIF written atomically.

Episode ``i`` of every agent resets with the same seed, so every agent meets the same plan,
routers and start pose; the record is the same whichever process runs it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.agents.base import decision_arrays
from sfw_gym.core.atomic import atomic_path
from sfw_gym.envs.explore import unwrap_sfw
from sfw_gym.metrics import zone_band_unknown as _zone_band_unknown


@dataclass(frozen=True)
class EpisodeSpec:
    """One episode of one agent: everything a worker needs to run it.

    Attributes:
        agent: Agent name (see :data:`sfw_gym.agents.AGENTS`).
        episode: Episode index ``i``.
        seed: ``env.reset`` seed (``seed + i``); also the agent's seed.
        env_id: Gymnasium id.
        floorplan: Plan file passed as ``reset(options={"floorplan": ...})``, or None.
        env_kwargs: Extra ``gym.make`` kwargs.
        agent_params: Agent constructor parameters.
        curve_every: Record coverage / IoU / path length every this many steps.
        gif_path: Write a GIF of the episode here (None: no GIF).
        npz_path: Write the final belief, truth, trajectory and the agent's decision log
            (:func:`~sfw_gym.agents.base.decision_arrays`) here (None: not).
        band_m: Half-width of the zone-border bands of the band metric.
        agent_seed: The agent's reset seed (None: the env seed).
    """

    agent: str
    episode: int
    seed: int
    env_id: str = "SfW-Explore-v0"
    floorplan: str | None = None
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    agent_params: dict[str, Any] = field(default_factory=dict)
    curve_every: int = 10
    gif_path: str | None = None
    npz_path: str | None = None
    band_m: float = 0.8
    agent_seed: int | None = None

    @property
    def key(self) -> str:
        """Identity in the checkpoint (an episode with the same key is not run again)."""
        key = f"{self.agent}|{self.episode}|{self.seed}|{self.env_id}|{self.floorplan}"
        return key if self.agent_seed is None else f"{key}|{self.agent_seed}"


# ---------------------------------------------------------------------------------- one episode
def zone_band_unknown(env: Any, band_m: float = 0.8) -> dict[str, float]:
    """:func:`sfw_gym.metrics.zone_band_unknown` of a live env: its ground truth and the
    robot's belief map now (ground truth: for evaluation only)."""
    sfw = unwrap_sfw(env)
    gt = sfw.ground_truth()
    return _zone_band_unknown(gt.truth_u8, sfw.robot_view().belief_u8, gt.grid, gt.radio, band_m)


def run_episode(spec: EpisodeSpec) -> dict[str, Any]:
    """Run one episode and return its JSON-serialisable record."""
    import time

    import gymnasium as gym

    import sfw_gym  # noqa: F401  (registers the envs in a fresh worker)
    from sfw_gym.agents import make_agent

    start = time.perf_counter()
    render = "rgb_array" if spec.gif_path else None
    env = gym.make(spec.env_id, render_mode=render, **spec.env_kwargs)
    options = {"floorplan": spec.floorplan} if spec.floorplan else None
    obs, info = env.reset(seed=spec.seed, options=options)
    entropy_at_start = info["entropy_bits"]
    agent = make_agent(spec.agent, **spec.agent_params)
    agent.reset(env, seed=spec.seed if spec.agent_seed is None else spec.agent_seed)
    frames: list[Any] = [env.render()] if render else []
    curve: list[tuple[int, float, float, float]] = [(0, info["coverage"], info["map_iou"], 0.0)]
    steps, terminated, truncated = 0, False, False
    while not (terminated or truncated):
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        steps += 1
        if steps % spec.curve_every == 0 or terminated or truncated:
            curve.append((steps, info["coverage"], info["map_iou"], info["path_length_m"]))
        if render and (steps % 10 == 0 or terminated or truncated):
            frames.append(env.render())
    summary = dict(info.get("summary", {}))
    summary.update(zone_band_unknown(env, spec.band_m))
    # The map's information gain per metre driven: what the reward pays for, per unit of effort.
    summary["info_gain_total_bits"] = entropy_at_start - info["entropy_bits"]
    path_m = info["path_length_m"]
    summary["info_gain_per_m"] = summary["info_gain_total_bits"] / path_m if path_m > 0 else None
    gt = unwrap_sfw(env).ground_truth()
    reason = agent.stop_reason or ("coverage_target" if terminated else "max_steps")
    record = {
        "key": spec.key,
        "agent": spec.agent,
        "episode": spec.episode,
        "seed": spec.seed,
        "env_id": spec.env_id,
        "floorplan": gt.floorplan.name,
        "floorplan_file": spec.floorplan,
        "area_m2": float(gt.floorplan.area_m2),
        "steps": steps,
        "terminated": bool(terminated),
        "stop_reason": reason,
        "wall_s": time.perf_counter() - start,
        "agent_params": agent.params(),
        "decisions": len(agent.decisions),
        "curve": [list(map(_py, c)) for c in curve],
        **{k: _py(v) for k, v in summary.items()},
    }
    if spec.npz_path:
        _write_npz(
            Path(spec.npz_path),
            truth=gt.truth_u8,
            belief=unwrap_sfw(env).robot_view().belief_u8,
            trajectory=gt.trajectory.astype(np.float32),
            routers=np.asarray(gt.radio.routers),
            origin=np.asarray(gt.grid.origin_xy),
            resolution=np.asarray(gt.grid.resolution_m),
            **decision_arrays(agent.decisions),
        )
    if spec.gif_path:
        _write_gif(Path(spec.gif_path), frames, fps=env.metadata.get("render_fps", 10))
    env.close()
    return record


def _py(v: Any) -> Any:
    if isinstance(v, np.generic):
        return v.item()
    return v


def _write_npz(path: Path, **arrays: Any) -> None:
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, allow_pickle=False, **arrays)


def _write_gif(path: Path, frames: list[np.ndarray], fps: int) -> None:
    import imageio.v3 as iio

    with atomic_path(path) as tmp:
        iio.imwrite(tmp, np.stack(frames), extension=".gif", duration=1000 / fps, loop=0)

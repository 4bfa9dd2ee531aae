"""One episode of one agent, start to end: :class:`EpisodeSpec` (what a worker needs) in, the
episode's JSON record out (the env's metrics, the zone-band metric, the coverage curve, the stop
reason), with its ``.npz`` (belief, truth, trajectory, decisions) and GIF written atomically.

Episode ``i`` of every agent resets with the same seed, so every agent meets the same plan,
routers and start pose; the record is the same whichever process runs it.
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from sfw_gym.agents.base import decision_arrays
from sfw_gym.core.atomic import atomic_path
from sfw_gym.envs.explore import unwrap_sfw
from sfw_gym.metrics import zone_band_unknown as _zone_band_unknown

if TYPE_CHECKING:
    from sfw_gym.envs.episode import GroundTruth


@dataclass(frozen=True)
class EpisodeSpec:
    """One episode of one agent: everything a worker needs to run it.

    Attributes:
        agent: Agent name (see :data:`sfw_gym.agents.AGENTS`).
        episode: Episode index ``i``.
        seed: ``env.reset`` seed (``seed + i``); also the agent's seed.
        env_id: Gymnasium id.
        floorplan: Plan file passed as ``reset(options={"floorplan": ...})``, or None.
        routers: Router positions ``[[x, y], ...]`` (metres) or a count, passed as
            ``reset(options={"routers": ...})``; None: the env's own (k-means) placement.
        env_kwargs: Extra ``gym.make`` kwargs.
        agent_params: Agent constructor parameters.
        curve_every: Record ``[step, coverage, map IoU, path length m, entropy bits]`` every
            this many steps (and at the last).
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
    routers: list[list[float]] | int | None = None
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    agent_params: dict[str, Any] = field(default_factory=dict)
    curve_every: int = 10
    gif_path: str | None = None
    npz_path: str | None = None
    band_m: float = 0.8
    agent_seed: int | None = None

    @property
    def agent_reset_seed(self) -> int:
        """The seed the agent is reset with (``agent_seed``, else the env seed)."""
        return self.seed if self.agent_seed is None else self.agent_seed

    @property
    def key(self) -> str:
        """Identity in the checkpoint (an episode with the same key is not run again)."""
        key = f"{self.agent}|{self.episode}|{self.seed}|{self.env_id}|{self.floorplan}"
        key = key if self.agent_seed is None else f"{key}|{self.agent_seed}"
        return key if self.routers is None else f"{key}|routers={self.routers}"

    @property
    def reset_options(self) -> dict[str, Any]:
        """The episode's ``reset`` options: its plan file and routers, where given."""
        options: dict[str, Any] = {}
        if self.floorplan:
            options["floorplan"] = self.floorplan
        if self.routers is not None:
            options["routers"] = self.routers
        return options


# ---------------------------------------------------------------------------------- one episode
def zone_band_unknown(env: Any, band_m: float = 0.8) -> dict[str, float]:
    """:func:`sfw_gym.metrics.zone_band_unknown` of a live env: its ground truth and the
    robot's belief map now (ground truth: for evaluation only)."""
    sfw = unwrap_sfw(env)
    gt = sfw.ground_truth()
    return _zone_band_unknown(gt.truth_u8, sfw.robot_view().belief_u8, gt.grid, gt.radio, band_m)


class EpisodeRecord:
    """One episode's record, built from what the env returns: the reset's info, each step's
    info, and at the end the episode's ground truth and the robot's final belief. The single
    env (:func:`run_episode`) and the vector env (:mod:`~sfw_gym.evaluation.vector`) both build
    their records here, so that they are the same.

    Args:
        spec: The episode.
        info: The reset's info.
        start: ``time.perf_counter()`` when the episode's work began (its ``wall_s``).
    """

    def __init__(self, spec: EpisodeSpec, info: Mapping[str, Any], start: float) -> None:
        self.spec = spec
        self.start = start
        self.entropy_at_start = info["entropy_bits"]
        self.curve: list[tuple[int, float, float, float, float]] = [
            (0, info["coverage"], info["map_iou"], 0.0, info["entropy_bits"])
        ]
        self.steps = 0

    def step(self, info: Mapping[str, Any], done: bool) -> None:
        """Count a step and sample the curve (every ``curve_every`` steps and the last)."""
        self.steps += 1
        if self.steps % self.spec.curve_every == 0 or done:
            self.curve.append(
                (
                    self.steps,
                    info["coverage"],
                    info["map_iou"],
                    info["path_length_m"],
                    info["entropy_bits"],
                )
            )

    def finish(
        self,
        info: Mapping[str, Any],
        terminated: bool,
        agent: Any,
        truth: GroundTruth,
        belief_u8: np.ndarray,
    ) -> dict[str, Any]:
        """The JSON-serialisable record (and the ``.npz``, if the spec asks for one), from the
        last step's info, whether the episode terminated, the agent, the ground truth and the
        robot's final belief map."""
        spec = self.spec
        summary = dict(info.get("summary", {}))
        summary.update(
            _zone_band_unknown(truth.truth_u8, belief_u8, truth.grid, truth.radio, spec.band_m)
        )
        # The map's information gain per metre driven: what the reward pays for, per unit of
        # effort.
        summary["info_gain_total_bits"] = self.entropy_at_start - info["entropy_bits"]
        path_m = info["path_length_m"]
        summary["info_gain_per_m"] = (
            summary["info_gain_total_bits"] / path_m if path_m > 0 else None
        )
        reason = agent.stop_reason or ("coverage_target" if terminated else "max_steps")
        record = {
            "key": spec.key,
            "agent": spec.agent,
            "episode": spec.episode,
            "seed": spec.seed,
            "env_id": spec.env_id,
            "floorplan": truth.floorplan.name,
            "floorplan_file": spec.floorplan,
            "routers": np.asarray(truth.radio.routers).tolist(),
            "area_m2": float(truth.floorplan.area_m2),
            "steps": self.steps,
            "terminated": bool(terminated),
            "stop_reason": reason,
            "wall_s": time.perf_counter() - self.start,
            "agent_params": agent.params(),
            "privileged": bool(agent.privileged),
            "decisions": len(agent.decisions),
            "curve": [list(map(_py, c)) for c in self.curve],
            **{k: _py(v) for k, v in summary.items()},
        }
        if spec.npz_path:
            _write_npz(
                Path(spec.npz_path),
                truth=truth.truth_u8,
                belief=belief_u8,
                trajectory=truth.trajectory.astype(np.float32),
                routers=np.asarray(truth.radio.routers),
                origin=np.asarray(truth.grid.origin_xy),
                resolution=np.asarray(truth.grid.resolution_m),
                **decision_arrays(agent.decisions),
            )
        return record


def run_episode(spec: EpisodeSpec) -> dict[str, Any]:
    """Run one episode on its own env and return its JSON-serialisable record."""
    import gymnasium as gym

    import sfw_gym  # noqa: F401  (registers the envs in a fresh worker)
    from sfw_gym.agents import make_agent

    start = time.perf_counter()
    render = "rgb_array" if spec.gif_path else None
    env = gym.make(spec.env_id, render_mode=render, **spec.env_kwargs)
    obs, info = env.reset(seed=spec.seed, options=spec.reset_options or None)
    episode = EpisodeRecord(spec, info, start)
    agent = make_agent(spec.agent, **spec.agent_params)
    agent.reset(env, seed=spec.agent_reset_seed)
    frames: list[Any] = [env.render()] if render else []
    terminated = truncated = False
    while not (terminated or truncated):
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        episode.step(info, terminated or truncated)
        if render and (episode.steps % 10 == 0 or terminated or truncated):
            frames.append(env.render())
    sfw = unwrap_sfw(env)
    record = episode.finish(info, terminated, agent, sfw.ground_truth(), sfw.robot_view().belief_u8)
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
    from PIL import Image

    first, *rest = (Image.fromarray(frame) for frame in frames)
    with atomic_path(path) as tmp:  # loop=0: played over and over, not once
        first.save(
            tmp, format="GIF", save_all=True, append_images=rest, duration=1000 / fps, loop=0
        )

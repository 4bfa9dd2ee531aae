"""Run agents on the same floorplans and seeds, in parallel, and compare them.

``sfw-gym evaluate --agents frontier,cross-pass,random --episodes N --seed S`` (or
:func:`evaluate`) runs episode ``i`` of every agent with ``env.reset(seed=S + i)``: the same
procedural floorplan, routers and start pose for every agent (with ``floorplans``, plan file
``i mod n_files`` of the folder). Episodes run in worker processes; each finished episode is added
to a JSONL checkpoint, so a run that is interrupted resumes where it stopped. Outputs, every file
written atomically (a temp file and ``os.replace``):

- ``episodes.jsonl``: one record per episode (metrics, curves, stop reason);
- ``episodes/<agent>_<i>.npz``: the final belief, the ground truth and the trajectory;
- ``results.csv`` and ``results.md``: per agent the mean ± 95 % CI (Student t) of every metric;
- ``coverage_vs_steps.png`` and ``iou_vs_path.png``: mean curves with 95 % CI bands;
- ``trajectories/<i>_<plan>.png``: per floorplan, every agent's path over the ground truth and
  its final belief;
- optionally ``gifs/<agent>_<i>.gif`` (``render_mode="rgb_array"`` frames).

Evaluation may look at the ground truth (agents never do): besides the env's info metrics, it
counts the free cells left unknown in the bands along the borders between the *true* router
dominance zones (noise-free RSSI), the cells that cross-connecting passes target.
"""

from __future__ import annotations

import json
import multiprocessing as mp
import os
from collections.abc import Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.agents.base import decision_arrays
from sfw_gym.core.atomic import atomic_path, remove_stale_temps, write_text_atomic
from sfw_gym.core.constants import U8_FREE
from sfw_gym.core.errors import ConfigError
from sfw_gym.core.processes import die_with_parent
from sfw_gym.envs.explore import unwrap_sfw
from sfw_gym.evaluation.plots import plot_curves, plot_trajectories
from sfw_gym.evaluation.report import paired_markdown, results_csv, results_markdown
from sfw_gym.evaluation.stats import paired_differences, summarize

CHECKPOINT = "episodes.jsonl"


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
    """Free cells left unknown along the borders between the true router dominance zones.

    Zones: each free cell goes to the router with the highest noise-free RSSI there (path
    loss, walls, shadowing). Band: free cells within ``band_m`` of a cell of another zone.
    Ground truth: for evaluation only.

    Returns:
        ``zone_band_cells``, ``zone_band_unknown`` (cells), ``zone_band_unknown_frac``.
    """
    from scipy import ndimage

    from sfw_gym.mapping.grid import belief_classes

    gt = unwrap_sfw(env).ground_truth()
    truth = gt.truth_u8
    free = truth == U8_FREE
    routers = gt.radio.routers
    if len(routers) < 2 or not free.any():
        return {"zone_band_cells": 0, "zone_band_unknown": 0, "zone_band_unknown_frac": 0.0}
    xs, ys = gt.grid.cell_centres()
    zone = np.full(truth.shape, -1, np.int64)
    zone[free] = np.argmax(gt.radio.mean_rssi(np.stack([xs[free], ys[free]], 1)), axis=1)
    border = np.zeros(truth.shape, bool)
    for a, b in (
        ((slice(None, -1), slice(None)), (slice(1, None), slice(None))),
        ((slice(None), slice(None, -1)), (slice(None), slice(1, None))),
    ):
        diff = (zone[a] != zone[b]) & (zone[a] >= 0) & (zone[b] >= 0)
        border[a] |= diff
        border[b] |= diff
    if not border.any():
        return {"zone_band_cells": 0, "zone_band_unknown": 0, "zone_band_unknown_frac": 0.0}
    band = free & (ndimage.distance_transform_edt(~border) * gt.grid.resolution_m <= band_m)
    est_free, wall, _ = belief_classes(unwrap_sfw(env).robot_view().belief_u8)
    unknown = band & ~wall & ~est_free
    n_band = int(band.sum())
    return {
        "zone_band_cells": n_band,
        "zone_band_unknown": int(unknown.sum()),
        "zone_band_unknown_frac": float(unknown.sum() / n_band) if n_band else 0.0,
    }


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


# ---------------------------------------------------------------------------------- atomic I/O
def _write_npz(path: Path, **arrays: Any) -> None:
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, allow_pickle=False, **arrays)


def _write_gif(path: Path, frames: list[np.ndarray], fps: int) -> None:
    import imageio.v3 as iio

    with atomic_path(path) as tmp:
        iio.imwrite(tmp, np.stack(frames), extension=".gif", duration=1000 / fps, loop=0)


def load_checkpoint(path: Path) -> list[dict[str, Any]]:
    """The records of a JSONL checkpoint (an unreadable trailing line is ignored)."""
    if not path.exists():
        return []
    records = []
    for line in path.read_text(encoding="utf-8").splitlines():
        try:
            records.append(json.loads(line))
        except json.JSONDecodeError:
            continue
    return records


def _save_checkpoint(path: Path, records: Iterable[dict[str, Any]]) -> None:
    write_text_atomic(path, "".join(json.dumps(r) + "\n" for r in records))


def _append_record(path: Path, record: dict[str, Any]) -> None:
    """One record onto the checkpoint, on disk before returning (O(1) per episode: a study of
    16,000 episodes must not rewrite the file each time). A line cut by a kill is dropped by
    :func:`load_checkpoint`, and the resume rewrites the file clean before appending again."""
    with path.open("a", encoding="utf-8") as fh:
        fh.write(json.dumps(record) + "\n")
        fh.flush()
        os.fsync(fh.fileno())


# ---------------------------------------------------------------------------------- the runner
def run_specs(
    specs: Sequence[EpisodeSpec],
    out: Path,
    *,
    workers: int = 1,
    backend: str = "local",
    address: str | None = None,
    progress: bool = True,
) -> list[dict[str, Any]]:
    """Run the episodes not yet in ``OUT/episodes.jsonl`` (the checkpoint) and return every
    spec's record, in the order of ``specs``."""
    if backend not in BACKENDS:
        raise ConfigError(f"--backend must be one of {list(BACKENDS)}, got {backend!r}")
    out.mkdir(parents=True, exist_ok=True)
    remove_stale_temps(out)  # of a run killed mid-write
    ckpt = out / CHECKPOINT
    records = load_checkpoint(ckpt)
    _save_checkpoint(ckpt, records)  # clean: no line cut by a kill before the next appends
    done = {r["key"] for r in records}
    todo = [s for s in specs if s.key not in done]
    _run_all(
        todo,
        records,
        ckpt,
        workers,
        progress,
        total=len(specs),
        done=len(specs) - len(todo),
        ray_address=address if backend == "ray" else _LOCAL,
    )
    by_key = {r["key"]: r for r in records}
    return [by_key[s.key] for s in specs]


def episode_specs(
    agents: Sequence[str],
    episodes: int,
    seed: int,
    *,
    out: Path,
    env_id: str = "SfW-Explore-v0",
    floorplans: str | Path | None = None,
    env_kwargs: dict[str, Any] | None = None,
    agent_params: dict[str, dict[str, Any]] | None = None,
    gif_episodes: int = 0,
    curve_every: int = 10,
) -> list[EpisodeSpec]:
    """The episodes of a run, episode-major (every agent's episode 0 first)."""
    plans: list[str | None] = [None]
    if floorplans is not None:
        folder = Path(floorplans)
        if folder.is_file():
            plans = [str(folder)]
        else:
            files = sorted(folder.glob("*.json")) if folder.is_dir() else []
            if not files:
                raise ConfigError(f"--floorplans {floorplans}: no .json floorplan files there")
            plans = [str(p) for p in files]
    specs = []
    for i in range(episodes):
        for name in agents:
            specs.append(
                EpisodeSpec(
                    agent=name,
                    episode=i,
                    seed=seed + i,
                    env_id=env_id,
                    floorplan=plans[i % len(plans)],
                    env_kwargs=dict(env_kwargs or {}),
                    agent_params=dict((agent_params or {}).get(name, {})),
                    curve_every=curve_every,
                    gif_path=str(out / "gifs" / f"{name}_{i:04d}.gif")
                    if i < gif_episodes
                    else None,
                    npz_path=str(out / "episodes" / f"{name}_{i:04d}.npz"),
                )
            )
    return specs


def evaluate(
    agents: Sequence[str],
    episodes: int,
    seed: int = 0,
    *,
    out: str | Path = "evaluation",
    env_id: str = "SfW-Explore-v0",
    floorplans: str | Path | None = None,
    env_kwargs: dict[str, Any] | None = None,
    agent_params: dict[str, dict[str, Any]] | None = None,
    workers: int = 2,
    gif_episodes: int = 0,
    curve_every: int = 10,
    progress: bool = True,
    backend: str = "local",
    address: str | None = None,
) -> dict[str, Any]:
    """Run (or resume) an evaluation and write its table, curves and trajectory figures.

    Args:
        agents: Agent names (see :data:`sfw_gym.agents.AGENTS`).
        episodes: Episodes per agent; episode ``i`` uses ``env.reset(seed=seed + i)``.
        seed: Seed of episode 0.
        out: Output folder (created; holds the checkpoint that a rerun resumes from).
        env_id: Gymnasium id.
        floorplans: A folder of plan files (episode ``i`` uses file ``i mod n``) or one file;
            None: the env's procedural plans.
        env_kwargs: Extra ``gym.make`` kwargs (JSON-serialisable).
        agent_params: Per agent name, constructor parameters.
        workers: Worker processes (1: run in this process).
        gif_episodes: Write GIFs of the first this many episodes of every agent.
        curve_every: Curve sampling interval, steps.
        progress: Show a tqdm progress bar.
        backend: ``"local"`` (worker processes) or ``"ray"`` (episodes as Ray tasks, at most
            ``workers`` at a time; a task whose worker dies runs again); the same records.
        address: Ray's address (``"auto"``: a running cluster); None starts a local Ray.

    Returns:
        ``{"rows": summary rows, "records": episode records, "files": written paths}``; with
        more than one agent, ``paired.md`` holds every other agent's differences from the first
        on the same plans and seeds (mean and 95 % CI).
    """
    import gymnasium as gym

    from sfw_gym.agents import AGENTS, agent_class, known_agent, make_agent

    agents = list(dict.fromkeys(agents))
    if not agents:
        raise ConfigError("--agents: give at least one agent")
    unknown = [a for a in agents if not known_agent(a) and ":" not in a]
    if unknown:
        raise ConfigError(
            f"--agents: unknown agent(s) {unknown}; known: {sorted(AGENTS)} or a "
            "'module:Class' of your own"
        )
    for name in agents:
        agent_class(name)  # an entry point of one's own must import, in this process too
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"--episodes must be an int >= 1, got {episodes!r}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ConfigError(f"--workers must be an int >= 1, got {workers!r}")
    if backend not in BACKENDS:
        raise ConfigError(f"--backend must be one of {list(BACKENDS)}, got {backend!r}")
    if backend == "ray":
        _require_ray()
    for name, params in (agent_params or {}).items():  # fail early on bad parameters
        if not isinstance(params, dict):
            raise ConfigError(f"--agent-params: {name!r}: expected a JSON object, got {params!r}")
        try:
            make_agent(name, **params)
        except ConfigError as exc:
            raise ConfigError(f"--agent-params: {exc}") from None
    try:  # and on bad env kwargs (an unknown env id raises gymnasium's NameNotFound)
        gym.make(env_id, **(env_kwargs or {})).close()
    except (TypeError, ConfigError) as exc:
        raise ConfigError(f"--env-kwargs: {exc}") from None
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    specs = episode_specs(
        agents,
        episodes,
        seed,
        out=out,
        env_id=env_id,
        floorplans=floorplans,
        env_kwargs=env_kwargs,
        agent_params=agent_params,
        gif_episodes=gif_episodes,
        curve_every=curve_every,
    )
    records = load_checkpoint(out / CHECKPOINT)
    manifest = _manifest(
        out, records, agents, episodes, seed, env_id, floorplans, env_kwargs, agent_params
    )
    write_text_atomic(out / "config.json", json.dumps(manifest, indent=2) + "\n")
    mine = run_specs(
        specs, out, workers=workers, backend=backend, address=address, progress=progress
    )
    rows = summarize(mine, agents)
    files = [
        write_text_atomic(out / "results.csv", results_csv(rows)),
        write_text_atomic(out / "results.md", results_markdown(rows)),
    ]
    if len(agents) > 1:  # every other agent against the first, episode by episode
        paired = paired_differences(mine, agents, reference=agents[0])
        files.append(write_text_atomic(out / "paired.md", paired_markdown(paired)))
    else:  # not a stale table of an earlier run in the same folder
        (out / "paired.md").unlink(missing_ok=True)
    files += plot_curves(mine, agents, out)
    files += plot_trajectories(mine, agents, out)
    return {"rows": rows, "records": mine, "files": files}


def _manifest(
    out: Path,
    records: list[dict[str, Any]],
    agents: list[str],
    episodes: int,
    seed: int,
    env_id: str,
    floorplans: str | Path | None,
    env_kwargs: dict[str, Any] | None,
    agent_params: dict[str, dict[str, Any]] | None,
) -> dict[str, Any]:
    """The run's ``config.json``: what its episodes ran with. Resuming in a folder whose
    recorded episodes ran with another env, plans, env kwargs or agent parameters is refused
    (their records would be reused as if they were this run's); more agents or episodes extend
    it."""
    given = json.loads(
        json.dumps(
            {
                "env_id": env_id,
                "floorplans": str(floorplans) if floorplans else None,
                "env_kwargs": env_kwargs or {},
                "agent_params": {name: (agent_params or {}).get(name, {}) for name in agents},
            }
        )
    )
    path = out / "config.json"
    previous: dict[str, Any] = {}
    if records and path.is_file():
        try:
            previous = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, json.JSONDecodeError) as exc:
            raise ConfigError(
                f"{path}: unreadable run manifest ({exc}); use another --out"
            ) from None
    ran = {r["agent"] for r in records}
    for key in ("env_id", "floorplans", "env_kwargs"):
        if previous and previous.get(key) != given[key]:
            raise ConfigError(
                f"{out}: its {len(records)} recorded episodes ran with {key} "
                f"{previous.get(key)!r}, this run asks for {given[key]!r}; use another --out "
                f"(or delete {out / CHECKPOINT} to start over)"
            )
    before = previous.get("agent_params", {})
    for name in agents:
        if previous and name in ran and before.get(name, {}) != given["agent_params"][name]:
            raise ConfigError(
                f"{out}: its recorded {name!r} episodes ran with parameters "
                f"{before.get(name, {})!r}, this run asks for {given['agent_params'][name]!r}; "
                f"use another --out"
            )
    return {
        "agents": list(dict.fromkeys([*previous.get("agents", []), *agents])),
        "episodes": max(episodes, int(previous.get("episodes", 0))),
        "seed": seed,
        **given,
        "agent_params": {**before, **given["agent_params"]},
    }


#: Where episodes run.
BACKENDS = ("local", "ray")
_LOCAL = "local"
#: A Ray task whose worker died runs again this many times (nothing lost, nothing twice: the
#: checkpoint takes each episode's record once, when its task returns).
RAY_RETRIES = 3


def _require_ray() -> Any:
    try:
        import ray
    except ImportError:
        raise ConfigError("--backend ray needs Ray: pip install 'sfw-gym[ray]'") from None
    return ray


def _run_on_ray(todo: list[EpisodeSpec], finish: Any, workers: int, address: str | None) -> None:
    """Episodes as Ray tasks, at most ``workers`` in flight, each record taken as it returns."""
    ray = _require_ray()
    started = not ray.is_initialized()
    if started:
        ray.init(
            address=address,
            num_cpus=workers if address is None else None,
            include_dashboard=False,
            log_to_driver=False,
        )
    task = ray.remote(max_retries=RAY_RETRIES)(run_episode)
    queue: list[EpisodeSpec] = list(todo)
    pending: list[Any] = []
    try:
        while queue or pending:
            while queue and len(pending) < workers:
                pending.append(task.remote(queue.pop(0)))
            finished, pending = ray.wait(pending, num_returns=1)
            for ref in finished:
                finish(ray.get(ref))
    finally:  # on an interrupt, drop the queued episodes; the checkpoint holds the done ones
        for ref in pending:
            ray.cancel(ref, force=True)
        if started:
            ray.shutdown()


def _run_all(
    todo: list[EpisodeSpec],
    records: list[dict[str, Any]],
    ckpt: Path,
    workers: int,
    progress: bool,
    total: int,
    done: int,
    ray_address: str | None = None,
) -> None:
    from tqdm.auto import tqdm

    bar = tqdm(total=total, initial=done, desc="episodes", unit="ep", disable=not progress)

    def finish(record: dict[str, Any]) -> None:
        records.append(record)
        _append_record(ckpt, record)
        bar.set_postfix_str(f"{record['agent']} #{record['episode']} cov {record['coverage']:.2f}")
        bar.update(1)

    try:
        if ray_address != _LOCAL:
            _run_on_ray(todo, finish, workers, ray_address)
            return
        if workers == 1:
            for spec in todo:
                finish(run_episode(spec))
            return
        # "spawn": forking a process that has run numba's OpenMP kernels is unsafe.
        pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=mp.get_context("spawn"),
            initializer=die_with_parent,  # a killed evaluation leaves no worker behind
            initargs=(os.getpid(),),
        )
        try:
            pending: set[Any] = set()
            queue = list(todo)
            while queue or pending:
                while queue and len(pending) < workers:
                    pending.add(pool.submit(run_episode, queue.pop(0)))
                finished, pending = wait(pending, return_when=FIRST_COMPLETED)
                for fut in finished:
                    finish(fut.result())
        finally:  # on an interrupt, drop the queued episodes; the checkpoint holds the done ones
            pool.shutdown(wait=False, cancel_futures=True)
    finally:
        bar.close()

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
import math
import multiprocessing as mp
from collections.abc import Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.atomic import atomic_path, write_text_atomic
from sfw_gym.errors import ConfigError

#: Metrics of the results table: (record key, column label, format).
TABLE_METRICS: tuple[tuple[str, str, str], ...] = (
    ("coverage", "coverage", "{:.3f}"),
    ("map_iou", "IoU", "{:.3f}"),
    ("free_iou", "free IoU", "{:.3f}"),
    ("k_accuracy", "k-accuracy", "{:.3f}"),
    ("path_length_m", "path [m]", "{:.0f}"),
    ("info_gain_per_m", "info gain [bits/m]", "{:.0f}"),
    ("collisions", "collisions", "{:.0f}"),
    ("steps_to_coverage_50", "steps to 50 %", "{:.0f}"),
    ("steps_to_coverage_90", "steps to 90 %", "{:.0f}"),
    ("zone_band_unknown", "unknown zone-band cells", "{:.0f}"),
    ("zone_band_unknown_frac", "unknown zone-band fraction", "{:.3f}"),
)
#: "steps to x %" metrics are averaged over the episodes that got there (count reported).
_REACHED_METRICS = ("steps_to_coverage_50", "steps_to_coverage_90")
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
        npz_path: Write the final belief, truth and trajectory here (None: not).
        band_m: Half-width of the zone-border bands of the band metric.
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

    @property
    def key(self) -> str:
        """Identity in the checkpoint (an episode with the same key is not run again)."""
        return f"{self.agent}|{self.episode}|{self.seed}|{self.env_id}|{self.floorplan}"


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

    from sfw_gym.mapping.grid import classify_u8

    u = env.unwrapped
    truth = u.scene.truth_u8
    free = truth == 255
    routers = u.scene.radio.routers
    if len(routers) < 2 or not free.any():
        return {"zone_band_cells": 0, "zone_band_unknown": 0, "zone_band_unknown_frac": 0.0}
    xs, ys = u.grid.cell_centres()
    zone = np.full(truth.shape, -1, np.int64)
    zone[free] = np.argmax(u.scene.radio.mean_rssi(np.stack([xs[free], ys[free]], 1)), axis=1)
    border = np.zeros(truth.shape, bool)
    for a, b in (((slice(None, -1), slice(None)), (slice(1, None), slice(None))),
                 ((slice(None), slice(None, -1)), (slice(None), slice(1, None)))):  # fmt: skip
        diff = (zone[a] != zone[b]) & (zone[a] >= 0) & (zone[b] >= 0)
        border[a] |= diff
        border[b] |= diff
    if not border.any():
        return {"zone_band_cells": 0, "zone_band_unknown": 0, "zone_band_unknown_frac": 0.0}
    band = free & (ndimage.distance_transform_edt(~border) * u.grid.resolution_m <= band_m)
    wall, est_free = classify_u8(u.mapper.occupancy_u8)
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
    agent.reset(env, seed=spec.seed)
    frames = [env.render()] if render else []
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
    u = env.unwrapped
    reason = agent.stop_reason or ("coverage_target" if terminated else "max_steps")
    record = {
        "key": spec.key,
        "agent": spec.agent,
        "episode": spec.episode,
        "seed": spec.seed,
        "env_id": spec.env_id,
        "floorplan": u.scene.floorplan.name,
        "floorplan_file": spec.floorplan,
        "area_m2": float(u.scene.floorplan.area_m2),
        "steps": steps,
        "terminated": bool(terminated),
        "stop_reason": reason,
        "wall_s": time.perf_counter() - start,
        "agent_params": agent.params(),
        "curve": [list(map(_py, c)) for c in curve],
        **{k: _py(v) for k, v in summary.items()},
    }
    if spec.npz_path:
        _write_npz(
            Path(spec.npz_path),
            truth=u.scene.truth_u8,
            belief=np.asarray(u.mapper.occupancy_u8),
            trajectory=np.asarray(u.trajectory, np.float32),
            routers=np.asarray(u.scene.radio.routers),
            origin=np.asarray(u.grid.origin_xy),
            resolution=np.asarray(u.grid.resolution_m),
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
def _write_npz(path: Path, **arrays: np.ndarray) -> None:
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        np.savez_compressed(fh, **arrays)


def _write_gif(path: Path, frames: list[np.ndarray], fps: int) -> None:
    import imageio.v3 as iio

    with atomic_path(path) as tmp:
        iio.imwrite(tmp, np.stack(frames), extension=".gif", duration=1000 / fps, loop=0)


def _save_figure(fig: Any, path: Path) -> Path:
    import matplotlib.pyplot as plt

    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


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


# ---------------------------------------------------------------------------------- statistics
def mean_ci95(values: Sequence[float]) -> tuple[float, float, int]:
    """Mean, half-width of its 95 % confidence interval (Student t), and n (nan if n = 0)."""
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], np.float64)
    if len(v) == 0:
        return math.nan, math.nan, 0
    if len(v) == 1:
        return float(v[0]), math.nan, 1
    from scipy import stats

    half = float(stats.t.ppf(0.975, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v)))
    return float(v.mean()), half, len(v)


def summarize(records: list[dict[str, Any]], agents: Sequence[str]) -> list[dict[str, Any]]:
    """Per agent: mean, 95 % CI and n of each table metric, and episode counts."""
    rows = []
    for name in agents:
        recs = [r for r in records if r["agent"] == name]
        row: dict[str, Any] = {"agent": name, "episodes": len(recs)}
        for key, _, _ in TABLE_METRICS:
            vals = [r.get(key) for r in recs]
            if key in _REACHED_METRICS:
                vals = [v for v in vals if v is not None and v >= 0]
            mean, ci, n = mean_ci95([v for v in vals if v is not None])
            row[f"{key}_mean"], row[f"{key}_ci95"], row[f"{key}_n"] = mean, ci, n
        cov = [r.get("coverage", 0.0) for r in recs]
        row["episodes_coverage_ge_90"] = int(sum(c >= 0.9 for c in cov))
        row["episodes_coverage_ge_80"] = int(sum(c >= 0.8 for c in cov))
        reasons: dict[str, int] = {}
        for r in recs:
            reasons[r["stop_reason"]] = reasons.get(r["stop_reason"], 0) + 1
        row["stop_reasons"] = ";".join(f"{k}:{v}" for k, v in sorted(reasons.items()))
        rows.append(row)
    return rows


def results_csv(rows: list[dict[str, Any]]) -> str:
    """The summary rows as CSV text."""
    import csv
    import io

    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]) if rows else ["agent"])
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
    return buf.getvalue()


def results_markdown(rows: list[dict[str, Any]]) -> str:
    """The summary rows as a Markdown table (mean ± 95 % CI)."""
    head = ["agent", "episodes"] + [label for _, label, _ in TABLE_METRICS] + ["≥ 90 % cov."]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [row["agent"], str(row["episodes"])]
        for key, _, fmt in TABLE_METRICS:
            mean, ci, n = row[f"{key}_mean"], row[f"{key}_ci95"], row[f"{key}_n"]
            if n == 0:
                cell = "–"
            else:
                cell = fmt.format(mean) + ("" if math.isnan(ci) else " ± " + fmt.format(ci))
            if key in _REACHED_METRICS:
                cell += f" ({n}/{row['episodes']})"
            cells.append(cell)
        cells.append(f"{row['episodes_coverage_ge_90']}/{row['episodes']}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------- figures
def _colours(agents: Sequence[str]) -> dict[str, Any]:
    import matplotlib.pyplot as plt

    cmap = plt.get_cmap("tab10")
    return {a: cmap(i % 10) for i, a in enumerate(agents)}


def _mean_band(curves: list[tuple[np.ndarray, np.ndarray]], grid: np.ndarray):
    """Mean and 95 % CI of step functions sampled on ``grid`` (held at their last value)."""
    from scipy import stats

    ys = []
    for x, y in curves:
        idx = np.clip(np.searchsorted(x, grid, side="right") - 1, 0, len(y) - 1)
        ys.append(y[idx])
    a = np.asarray(ys)
    mean = a.mean(axis=0)
    if len(a) < 2:
        return mean, np.zeros_like(mean)
    half = stats.t.ppf(0.975, len(a) - 1) * a.std(axis=0, ddof=1) / math.sqrt(len(a))
    return mean, half


def plot_curves(records: list[dict[str, Any]], agents: Sequence[str], out: Path) -> list[Path]:
    """``coverage_vs_steps.png`` and ``iou_vs_path.png`` (mean ± 95 % CI per agent)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = _colours(agents)
    written = []
    specs = (
        ("coverage_vs_steps.png", 0, 1, "steps", "coverage (fraction of free cells classified)"),
        ("iou_vs_path.png", 3, 2, "path length [m]", "map IoU (cells known in both maps)"),
    )
    for fname, xi, yi, xlabel, ylabel in specs:
        fig, ax = plt.subplots(figsize=(6.4, 4.2))
        lowest = 1.0
        for name in agents:
            curves = []
            for r in records:
                if r["agent"] != name or not r.get("curve"):
                    continue
                c = np.asarray(r["curve"], np.float64)
                order = np.argsort(c[:, xi], kind="stable")
                curves.append((c[order, xi], c[order, yi]))
            if not curves:
                continue
            x_max = max(float(x[-1]) for x, _ in curves)
            grid = np.linspace(0.0, max(x_max, 1e-9), 200)
            mean, half = _mean_band(curves, grid)
            ax.plot(grid, mean, color=colours[name], label=f"{name} (n={len(curves)})")
            lo, hi = np.clip(mean - half, 0, 1), np.clip(mean + half, 0, 1)
            ax.fill_between(grid, lo, hi, color=colours[name], alpha=0.2)
            lowest = min(lowest, float(lo[len(lo) // 20 :].min()))  # past the first few steps
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        # Coverage spans [0, 1]; IoU stays high: zoom in on its range.
        ax.set_ylim(0.0 if yi == 1 else max(0.0, np.floor(lowest * 20 - 1) / 20), 1.0)
        ax.grid(alpha=0.3)
        ax.legend(loc="lower right")
        written.append(_save_figure(fig, out / fname))
    return written


def plot_trajectories(
    records: list[dict[str, Any]], agents: Sequence[str], out: Path
) -> list[Path]:
    """Per episode (floorplan): every agent's path over the truth, and each final belief."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    colours = _colours(agents)
    written = []
    for episode in sorted({r["episode"] for r in records}):
        recs = {r["agent"]: r for r in records if r["episode"] == episode}
        data = {}
        for name in agents:
            path = out / "episodes" / f"{name}_{episode:04d}.npz"
            if name in recs and path.exists():
                with np.load(path) as z:
                    data[name] = {k: z[k] for k in z.files}
        if not data:
            continue
        first = next(iter(data.values()))
        h, w = first["truth"].shape
        res, (ox, oy) = float(first["resolution"]), first["origin"]
        extent = (ox, ox + w * res, oy, oy + h * res)
        n = 1 + len(data)
        fig, axes = plt.subplots(1, n, figsize=(3.2 * n * max(w / h, 0.5), 3.6), squeeze=False)
        ax = axes[0, 0]
        ax.imshow(first["truth"], cmap="gray", origin="lower", extent=extent, vmin=0, vmax=255)
        for name, d in data.items():
            t = d["trajectory"]
            ax.plot(t[:, 0], t[:, 1], color=colours[name], lw=0.7, label=name)
        ax.scatter(*first["routers"].T, marker="^", color="red", s=30, zorder=5)
        ax.set_title(f"episode {episode}: {recs[next(iter(data))]['floorplan']}", fontsize=8)
        ax.legend(fontsize=6, loc="upper right")
        for ax, (name, d) in zip(axes[0, 1:], data.items(), strict=True):
            ax.imshow(d["belief"], cmap="gray", origin="lower", extent=extent, vmin=0, vmax=255)
            t = d["trajectory"]
            ax.plot(t[:, 0], t[:, 1], color=colours[name], lw=0.5)
            r = recs[name]
            ax.set_title(
                f"{name}: cov {r.get('coverage', 0):.2f}, IoU {r.get('map_iou', 0):.2f}",
                fontsize=8,
            )
        for ax in axes[0]:
            ax.set_xticks([])
            ax.set_yticks([])
        plan = recs[next(iter(data))]["floorplan"][:24].replace("/", "_")
        written.append(_save_figure(fig, out / "trajectories" / f"{episode:04d}_{plan}.png"))
    return written


# ---------------------------------------------------------------------------------- the runner
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

    Returns:
        ``{"rows": summary rows, "records": episode records, "files": written paths}``.
    """
    import gymnasium as gym

    from sfw_gym.agents import AGENTS, make_agent

    agents = list(dict.fromkeys(agents))
    if not agents:
        raise ConfigError("--agents: give at least one agent")
    unknown = [a for a in agents if a not in AGENTS]
    if unknown:
        raise ConfigError(f"--agents: unknown agent(s) {unknown}; known: {sorted(AGENTS)}")
    if isinstance(episodes, bool) or not isinstance(episodes, int) or episodes < 1:
        raise ConfigError(f"--episodes must be an int >= 1, got {episodes!r}")
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ConfigError(f"--workers must be an int >= 1, got {workers!r}")
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
        agents, episodes, seed, out=out, env_id=env_id, floorplans=floorplans,
        env_kwargs=env_kwargs, agent_params=agent_params, gif_episodes=gif_episodes,
        curve_every=curve_every,
    )  # fmt: skip
    ckpt = out / CHECKPOINT
    records = load_checkpoint(ckpt)
    done = {r["key"] for r in records}
    todo = [s for s in specs if s.key not in done]
    write_text_atomic(
        out / "config.json",
        json.dumps(
            {"agents": agents, "episodes": episodes, "seed": seed, "env_id": env_id,
             "floorplans": str(floorplans) if floorplans else None,
             "env_kwargs": env_kwargs or {}, "agent_params": agent_params or {}},
            indent=2,
        ) + "\n",
    )  # fmt: skip
    _run_all(todo, records, ckpt, workers, progress, total=len(specs), done=len(specs) - len(todo))
    keys = {s.key for s in specs}
    mine = [r for r in records if r["key"] in keys]
    rows = summarize(mine, agents)
    files = [
        write_text_atomic(out / "results.csv", results_csv(rows)),
        write_text_atomic(out / "results.md", results_markdown(rows)),
    ]
    files += plot_curves(mine, agents, out)
    files += plot_trajectories(mine, agents, out)
    return {"rows": rows, "records": mine, "files": files}


def _run_all(
    todo: list[EpisodeSpec],
    records: list[dict[str, Any]],
    ckpt: Path,
    workers: int,
    progress: bool,
    total: int,
    done: int,
) -> None:
    from tqdm.auto import tqdm

    bar = tqdm(total=total, initial=done, desc="episodes", unit="ep", disable=not progress)

    def finish(record: dict[str, Any]) -> None:
        records.append(record)
        _save_checkpoint(ckpt, records)
        bar.set_postfix_str(f"{record['agent']} #{record['episode']} cov {record['coverage']:.2f}")
        bar.update(1)

    try:
        if workers == 1:
            for spec in todo:
                finish(run_episode(spec))
            return
        # "spawn": forking a process that has run numba's OpenMP kernels is unsafe.
        pool = ProcessPoolExecutor(max_workers=workers, mp_context=mp.get_context("spawn"))
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

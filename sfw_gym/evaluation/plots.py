"""Figures of an evaluation: mean curves with 95 % CI bands and trajectory overlays."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.core.atomic import atomic_path
from sfw_gym.evaluation.stats import ci95_half_width


def _save_figure(fig: Any, path: Path) -> Path:
    import matplotlib.pyplot as plt

    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    return path


def _colours(agents: Sequence[str]) -> dict[str, Any]:
    import matplotlib.pyplot as plt

    cmap = plt.get_cmap("tab10")
    return {a: cmap(i % 10) for i, a in enumerate(agents)}


def _mean_band(curves: list[tuple[np.ndarray, np.ndarray]], grid: np.ndarray):
    """Mean and 95 % CI of step functions sampled on ``grid`` (held at their last value)."""
    ys = []
    for x, y in curves:
        idx = np.clip(np.searchsorted(x, grid, side="right") - 1, 0, len(y) - 1)
        ys.append(y[idx])
    a = np.asarray(ys)
    mean = a.mean(axis=0)
    if len(a) < 2:
        return mean, np.zeros_like(mean)
    return mean, ci95_half_width(a)


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
        aspect = w / h
        ncols = n if aspect <= 1.2 else math.ceil(n / 2)  # wide plans: two rows, README width
        nrows = math.ceil(n / ncols)
        panel_w = max(2.0, 2.6 * min(aspect, 1.6))  # inches: titles fit even on tall plans
        panel_h = panel_w / max(aspect, 0.6) + 0.5
        fig, axes = plt.subplots(
            nrows,
            ncols,
            figsize=(panel_w * ncols, panel_h * nrows + 0.6),
            squeeze=False,
            layout="constrained",
        )
        axes = axes.reshape(1, -1)
        for spare in axes[0, n:]:
            spare.set_axis_off()
        ax = axes[0, 0]
        ax.imshow(first["truth"], cmap="gray", origin="lower", extent=extent, vmin=0, vmax=255)
        for name, d in data.items():
            t = d["trajectory"]
            ax.plot(t[:, 0], t[:, 1], color=colours[name], lw=0.7, label=name)
        ax.scatter(*first["routers"].T, marker="^", color="red", s=30, zorder=5, label="router")
        ax.set_title("true plan\nall paths", fontsize=8)
        fig.legend(
            *ax.get_legend_handles_labels(), loc="outside lower center", ncol=n + 1, fontsize=8
        )
        for ax, (name, d) in zip(axes[0, 1:n], data.items(), strict=True):
            ax.imshow(d["belief"], cmap="gray", origin="lower", extent=extent, vmin=0, vmax=255)
            t = d["trajectory"]
            ax.plot(t[:, 0], t[:, 1], color=colours[name], lw=0.5)
            r = recs[name]
            scores = f"coverage {r.get('coverage', 0):.2f}, free-IoU {r.get('free_iou', 0):.2f}"
            ax.set_title(f"{name}\n{scores}", fontsize=8)
        for ax in axes[0, :n]:
            ax.set_xticks([])
            ax.set_yticks([])
        fig.suptitle(
            f"episode {episode}: {recs[next(iter(data))]['floorplan']} (final belief maps)",
            fontsize=10,
        )
        plan = recs[next(iter(data))]["floorplan"][:24].replace("/", "_")
        written.append(_save_figure(fig, out / "trajectories" / f"{episode:04d}_{plan}.png"))
    return written

"""The world at a glance: plan, routers, RSSI and true k-regions per router (paper Fig. 1)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from sfw_gym.core.atomic import atomic_path
from sfw_gym.core.constants import U8_FREE
from sfw_gym.world.floorplan import Floorplan
from sfw_gym.world.radio import RadioModel


def draw_world(
    floorplan: Floorplan, radio: RadioModel, out: str | Path, *, resolution_m: float = 0.1
) -> Path:
    """Write a PNG: the plan with its routers, then per router its mean RSSI and its k-regions.

    Walls are black, free space white, outside grey. Written atomically (temp file + rename).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import BoundaryNorm, ListedColormap

    grid, (x0, y0) = floorplan.rasterize(resolution_m)
    rows, cols = grid.shape
    extent = (x0, x0 + cols * resolution_m, y0, y0 + rows * resolution_m)
    ys, xs = np.mgrid[0:rows, 0:cols]
    centres = np.stack([x0 + (xs + 0.5) * resolution_m, y0 + (ys + 0.5) * resolution_m], -1)
    centres = centres.reshape(-1, 2)
    free = grid.reshape(-1) == U8_FREE
    rssi = np.full((len(centres), radio.n_routers), np.nan)
    k = np.full((len(centres), radio.n_routers), np.nan)
    rssi[free] = radio.mean_rssi(centres[free])
    k[free] = radio.true_k(centres[free])
    k_max = int(np.nanmax(k)) if free.any() else 0

    n = radio.n_routers
    fig, axes = plt.subplots(2, n + 1, figsize=(4.2 * (n + 1), 7.6), squeeze=False)
    shown = {"origin": "lower", "extent": extent, "interpolation": "nearest"}
    plan_ax = axes[0, 0]
    plan_ax.imshow(grid, cmap="gray", vmin=0, vmax=255, **shown)
    plan_ax.set_title(f"{floorplan.name}\n{floorplan.area_m2:.0f} m², {n} routers")
    k_colours = ListedColormap(plt.get_cmap("viridis_r")(np.linspace(0, 1, k_max + 1)))
    k_norm = BoundaryNorm(np.arange(-0.5, k_max + 1.5), k_max + 1)
    for r, (rx, ry) in enumerate(radio.routers):
        plan_ax.plot(rx, ry, "r^", ms=10)
        plan_ax.annotate(f"R{r}", (rx, ry), color="red", xytext=(4, 4), textcoords="offset points")
        heat_ax, k_ax = axes[0, r + 1], axes[1, r + 1]
        im = heat_ax.imshow(rssi[:, r].reshape(rows, cols), cmap="inferno", **shown)
        fig.colorbar(im, ax=heat_ax, label="mean RSSI [dBm]", shrink=0.7)
        heat_ax.set_title(f"R{r}: mean RSSI")
        im = k_ax.imshow(k[:, r].reshape(rows, cols), cmap=k_colours, norm=k_norm, **shown)
        fig.colorbar(im, ax=k_ax, label="k (walls crossed)", ticks=range(k_max + 1), shrink=0.7)
        k_ax.set_title(f"R{r}: true k-regions")
        for ax in (heat_ax, k_ax):
            ax.contour(grid == 0, levels=[0.5], colors="k", linewidths=0.6, **_contour(extent))
            ax.plot(rx, ry, "r^", ms=9)
    strongest = np.full(len(centres), np.nan)
    strongest[free] = np.argmax(rssi[free], axis=1)
    dom_ax = axes[1, 0]
    dom_ax.imshow(strongest.reshape(rows, cols), cmap="tab10", vmin=0, vmax=9, **shown)
    dom_ax.set_title("strongest router (dominance zones)")
    for ax in axes.ravel():
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.tight_layout()
    with atomic_path(out) as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)
    return Path(out)


def _contour(extent: tuple[float, float, float, float]) -> dict:
    return {"origin": "lower", "extent": extent}

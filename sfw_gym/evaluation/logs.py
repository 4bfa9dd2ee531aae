"""RSSI logs that can be scored: recorded from the simulator in the SfW authors' CSV layouts, with
the ground-truth plan beside them (``sfw-gym record``), and the score of a map made from one.

:func:`record_log` walks a person (or a surveyor) through a floorplan and writes::

    NAME.csv        x_pixel,y_pixel,rssi                                       (1 router)
                    x_pixel,y_pixel,router1_2.4,router1_5,router2_2.4,router2_5,  (+ the strongest,
                                                                               unnamed)
    NAME.truth.npy  the plan, uint8 (0 wall, 255 free, 127 outside), in the log's frame
    NAME.truth.json the pixel scale, the routers (pixels), the truth grid, the radio, the seed

Positions are canvas pixels of 0.0115 m with y growing downward, as in the authors' files. The
radio disagrees with the mapper's assumptions the way buildings do: spatially correlated
shadowing (the world's :class:`~sfw_gym.world.RadioModel`, one field per band), a transmit-power
offset per router and band, walls that cost more at 5 GHz, temporal noise, and readings missed
now and then (empty cells). :func:`score_map` puts a map made from such a log (e.g. by
``sfw-gym map``) onto the truth's grid and returns the map metrics.
"""

from __future__ import annotations

import json
import logging
import os
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.core.atomic import atomic_path, write_text_atomic
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import GridSpec
from sfw_gym.mapping.metrics import evaluate_map
from sfw_gym.world import Floorplan, RadioConfig, RadioModel, place_routers
from sfw_gym.world.walks import survey, walk

logger = logging.getLogger(__name__)

#: The SfW logs' canvas pixel, metres.
SFW_PIXEL_M = 0.0115
TRUTH_RESOLUTION_M = 0.05
TRAJECTORIES = ("walk", "survey")


def record_log(
    plan: Floorplan,
    out: str | os.PathLike[str],
    *,
    routers: int | np.ndarray = 2,
    seed: int = 0,
    trajectory: str = "walk",
    step_m: float = 0.05,
    pixel_m: float = SFW_PIXEL_M,
    tx_offset_db: float = 4.0,
    wall_loss_5ghz_factor: float = 1.5,
    missed_fraction: float = 0.03,
    noise_sigma_db: float = 2.0,
) -> dict[str, Path]:
    """Record a log of ``plan`` in the SfW layout (module docstring) and its ground truth.

    Args:
        plan: The floorplan.
        out: The CSV path; the ``.truth.npy`` and ``.truth.json`` go beside it.
        routers: A count (placed by :func:`~sfw_gym.world.place_routers`) or ``(R, 2)`` positions
            in metres. One router writes one RSSI column (2.4 GHz); more write both bands per
            router and the strongest reading as the unnamed last column.
        seed: Seeds the routers, the walk and the radio.
        trajectory: ``"walk"`` (a person going from place to place) or ``"survey"`` (walls
            followed, then a lawnmower of 0.5 m passes).
        step_m: Distance between samples along the trajectory.
        pixel_m: Metres per canvas pixel.
        tx_offset_db: Each router's transmit power, per band, is off by up to this (uniform).
        wall_loss_5ghz_factor: Walls cost this many times more at 5 GHz than at 2.4.
        missed_fraction: Probability that a reading is missing (an empty cell).
        noise_sigma_db: Temporal noise of each reading.

    Returns:
        ``{"csv": …, "truth": …, "json": …}``.
    """
    out = Path(out)
    if out.suffix.lower() != ".csv":
        raise ConfigError(f"the log must be a .csv file, got {str(out)!r}")
    if trajectory not in TRAJECTORIES:
        raise ConfigError(f"trajectory must be one of {TRAJECTORIES}, got {trajectory!r}")
    if not 0.0 <= missed_fraction < 1.0:
        raise ConfigError(f"missed_fraction must be in [0, 1), got {missed_fraction!r}")
    rng = np.random.default_rng(seed)
    if isinstance(routers, (int, np.integer)) and not isinstance(routers, bool):
        routers = place_routers(plan, int(routers), rng)
    routers = np.asarray(routers, np.float64).reshape(-1, 2)
    if trajectory == "walk":
        xy = walk(plan, rng, step_m=step_m)
    else:
        xy = survey(plan, 0.5, step_m=step_m)
    n_routers = len(routers)
    bands = ("2.4",) if n_routers == 1 else ("2.4", "5")
    columns = []
    for band in bands:
        factor = wall_loss_5ghz_factor if band == "5" else 1.0
        losses = RadioConfig.preset("default", band).wall_loss_db
        cfg = RadioConfig.preset(
            "default", band, wall_loss_db={m: v * factor for m, v in losses.items()}
        )
        model = RadioModel(plan, routers, cfg, rng)  # mean RSSI; the noise is drawn below
        mean = model.mean_rssi(xy) + rng.uniform(-tx_offset_db, tx_offset_db, n_routers)
        reading = np.rint(mean + rng.normal(0.0, noise_sigma_db, mean.shape))
        reading[(reading < cfg.sensitivity_dbm) | (rng.random(mean.shape) < missed_fraction)] = (
            np.nan
        )
        columns.append(reading)
    rssi = np.stack(columns, axis=2).reshape(len(xy), -1)  # router-major: r1 2.4, r1 5, r2 …
    xmin, _, _, ymax = plan.bounds
    px = np.column_stack([(xy[:, 0] - xmin) / pixel_m, (ymax - xy[:, 1]) / pixel_m])
    routers_px = np.column_stack(
        [(routers[:, 0] - xmin) / pixel_m, (ymax - routers[:, 1]) / pixel_m]
    )
    if n_routers == 1:
        header, table = "x_pixel,y_pixel,rssi", np.column_stack([px, rssi])
    else:
        names = [f"router{r + 1}_{b}" for r in range(n_routers) for b in bands]
        strongest = np.full(len(xy), np.nan)
        heard = ~np.isnan(rssi).all(axis=1)
        strongest[heard] = np.nanmax(rssi[heard], axis=1)
        header = ",".join(["x_pixel", "y_pixel", *names]) + ","
        table = np.column_stack([px, rssi, strongest])
    lines = [header]
    for row in table:
        cells = [f"{row[0]:.1f}", f"{row[1]:.1f}"]
        cells += ["" if np.isnan(v) else f"{v:.0f}" for v in row[2:]]
        lines.append(",".join(cells))
    paths = {"csv": out, "truth": out.with_suffix(".truth.npy")}
    paths["json"] = out.with_suffix(".truth.json")
    write_text_atomic(out, "\n".join(lines) + "\n")
    truth, (x0, y0) = plan.rasterize(TRUTH_RESOLUTION_M)
    with atomic_path(paths["truth"]) as tmp:
        np.save(tmp, truth[::-1].copy(), allow_pickle=False)  # rows follow y downward
    meta = {
        "plan": plan.name,
        "seed": seed,
        "trajectory": trajectory,
        "samples": len(xy),
        "pixel_m": pixel_m,
        "y_down": True,
        "routers_px": routers_px.round(1).tolist(),
        "truth": {
            "file": paths["truth"].name,
            "origin_xy_m": [x0 - xmin, ymax - y0 - truth.shape[0] * TRUTH_RESOLUTION_M],
            "resolution_m": TRUTH_RESOLUTION_M,
            "values": "0 wall, 255 free, 127 outside; [row, col] = [y, x] in the log's frame",
        },
        "radio": {
            "bands": list(bands),
            "tx_offset_db": tx_offset_db,
            "wall_loss_5ghz_factor": wall_loss_5ghz_factor,
            "missed_fraction": missed_fraction,
            "noise_sigma_db": noise_sigma_db,
        },
    }
    write_text_atomic(paths["json"], json.dumps(meta, indent=2) + "\n")
    logger.info("%s: %d samples of %s (%s, %d router(s))", out, len(xy), plan.name, trajectory,
                n_routers)  # fmt: skip
    return paths


def read_log_meta(csv_path: str | os.PathLike[str]) -> dict[str, Any]:
    """The ``.truth.json`` beside a recorded log, with ``truth_u8`` and ``truth_grid`` added."""
    path = Path(csv_path).with_suffix(".truth.json")
    try:
        meta = json.loads(path.read_text())
        truth = np.load(path.parent / meta["truth"]["file"], allow_pickle=False)
        grid = GridSpec(
            tuple(meta["truth"]["origin_xy_m"]), meta["truth"]["resolution_m"], truth.shape
        )
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise ConfigError(f"{path}: not a recorded log's description ({exc})") from None
    return {**meta, "truth_u8": truth, "truth_grid": grid}


def score_map(est_u8: np.ndarray, est_grid: GridSpec, truth_u8: np.ndarray, truth_grid: GridSpec):
    """Map metrics (:func:`~sfw_gym.mapping.metrics.evaluate_map`) of a map on its own grid
    against a truth on another (same frame): the map is read at each truth cell's centre
    (unknown off its grid)."""
    rows, cols = truth_grid.shape
    ox, oy = truth_grid.origin_xy
    res = truth_grid.resolution_m
    xs = ox + (np.arange(cols) + 0.5) * res
    ys = oy + (np.arange(rows) + 0.5) * res
    c = np.floor((xs - est_grid.origin_xy[0]) / est_grid.resolution_m).astype(np.int64)
    r = np.floor((ys - est_grid.origin_xy[1]) / est_grid.resolution_m).astype(np.int64)
    on = (r[:, None] >= 0) & (r[:, None] < est_grid.shape[0])
    on = on & (c[None, :] >= 0) & (c[None, :] < est_grid.shape[1])
    est = np.full(truth_grid.shape, 127, np.uint8)
    rr, cc = np.broadcast_to(r[:, None], on.shape), np.broadcast_to(c[None, :], on.shape)
    est[on] = np.asarray(est_u8)[rr[on], cc[on]]
    return evaluate_map(est, truth_u8)

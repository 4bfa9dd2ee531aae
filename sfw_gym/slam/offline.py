"""Radio SLAM on a recorded log (``sfw-gym slam LOG.csv``).

The log is a CSV with a header: ``time, odom_x, odom_y, odom_theta`` (seconds, metres, radians),
then one column per access point (RSSI in dBm; empty, ``nan`` or ≤ −100 for "not heard"), and
optionally ``true_x, true_y`` (the truth, when known, for the error). Outputs: the corrected
trajectory (CSV), the radio fingerprint map (the fingerprints at their corrected positions,
``.npz``) and a figure of odometry, corrected trajectory and truth.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from sfw_gym.core.atomic import atomic_path, write_text_atomic
from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.slam.metrics import absolute_trajectory_error
from sfw_gym.slam.radio_slam import RadioSlamConfig, RadioSlamResult, radio_slam

ODOMETRY_COLUMNS = ("time", "odom_x", "odom_y", "odom_theta")
TRUTH_COLUMNS = ("true_x", "true_y")


@dataclass(frozen=True)
class SlamLog:
    """A run: times ``(N,)``, odometry ``(N, 3)``, fingerprints ``(N, L)`` in dBm (NaN: not
    heard) with their AP names, and the true positions ``(N, 2)`` where the log has them."""

    path: Path
    time: np.ndarray
    odometry: np.ndarray
    fingerprints: np.ndarray
    access_points: tuple[str, ...]
    truth: np.ndarray | None


def write_slam_log(
    path: str | os.PathLike[str],
    time: np.ndarray,
    odometry: np.ndarray,
    fingerprints: np.ndarray,
    truth: np.ndarray | None = None,
) -> Path:
    """Write a log in the layout :func:`read_slam_log` reads (APs named ``ap0``, ``ap1``, …)."""
    fp = np.asarray(fingerprints, np.float64)
    header = [*ODOMETRY_COLUMNS, *(f"ap{i}" for i in range(fp.shape[1]))]
    columns = [np.asarray(time, np.float64)[:, None], np.asarray(odometry, np.float64), fp]
    if truth is not None:
        header += TRUTH_COLUMNS
        columns.append(np.asarray(truth, np.float64)[:, :2])
    rows = np.hstack(columns)
    lines = [",".join(header)]
    lines += [",".join("" if math.isnan(v) else f"{v:.6g}" for v in row) for row in rows.tolist()]
    return write_text_atomic(path, "\n".join(lines) + "\n")


def read_slam_log(path: str | os.PathLike[str]) -> SlamLog:
    """Read a log; ConfigError naming the file (and line) for a missing column, a short row or
    a value that is not a number."""
    path = Path(path)
    try:
        with open(path, encoding="utf-8-sig", newline="") as fh:
            rows = [(n, row) for n, row in enumerate(csv.reader(fh), 1) if any(row)]
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise ConfigError(f"{path}: cannot read the log: {exc}") from None
    if not rows:
        raise ConfigError(f"{path}: empty log (expected a header {','.join(ODOMETRY_COLUMNS)},…)")
    header = [c.strip() for c in rows[0][1]]
    missing = [c for c in ODOMETRY_COLUMNS if c not in header]
    if missing:
        raise ConfigError(
            f"{path}: columns {missing} missing; found {header[:8]}; a Radio SLAM log has "
            f"{', '.join(ODOMETRY_COLUMNS)}, one column per AP, optionally true_x, true_y"
        )
    has_truth = all(c in header for c in TRUTH_COLUMNS)
    aps = [c for c in header if c not in ODOMETRY_COLUMNS + TRUTH_COLUMNS]
    if not aps:
        raise ConfigError(f"{path}: no access-point columns besides {header}")
    data = np.empty((len(rows) - 1, len(header)))
    for k, (line, row) in enumerate(rows[1:]):
        if len(row) != len(header):
            raise ConfigError(f"{path}:{line}: {len(row)} values, the header has {len(header)}")
        for c, text in enumerate(row):
            text = text.strip()
            try:
                data[k, c] = float(text) if text else math.nan
            except ValueError:
                raise ConfigError(f"{path}:{line}: {header[c]} is not a number: {text!r}") from None
    if len(data) < 2:
        raise ConfigError(f"{path}: {len(data)} data rows; Radio SLAM needs at least 2")
    col = {name: i for i, name in enumerate(header)}
    known = [col[c] for c in ODOMETRY_COLUMNS + (TRUTH_COLUMNS if has_truth else ())]
    bad = np.flatnonzero(~np.isfinite(data[:, known]).all(axis=1))
    if len(bad):
        raise ConfigError(f"{path}:{int(bad[0]) + 2}: time, odometry and truth must be finite")
    fingerprints = data[:, [col[a] for a in aps]]
    fingerprints[~(fingerprints > NOT_HEARD_DBM)] = np.nan
    return SlamLog(
        path=path,
        time=data[:, col["time"]],
        odometry=data[:, [col[c] for c in ODOMETRY_COLUMNS[1:]]],
        fingerprints=fingerprints,
        access_points=tuple(aps),
        truth=data[:, [col[c] for c in TRUTH_COLUMNS]] if has_truth else None,
    )


def slam_log(
    path: str | os.PathLike[str], out_dir: str | os.PathLike[str], config: RadioSlamConfig
) -> tuple[SlamLog, RadioSlamResult, dict[str, Path]]:
    """Radio SLAM on the log at ``path``; writes ``trajectory.csv``, ``fingerprint_map.npz`` and
    ``slam.png`` into ``out_dir``."""
    log = read_slam_log(path)
    result = radio_slam(log.odometry, log.fingerprints, config)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    rows = np.column_stack([log.time, result.poses])
    paths = {
        "trajectory": write_text_atomic(
            out / "trajectory.csv",
            "time,x,y,theta\n" + "".join(",".join(f"{v:.6g}" for v in r) + "\n" for r in rows),
        ),
        "fingerprint_map": out / "fingerprint_map.npz",
        "figure": out / "slam.png",
    }
    with atomic_path(paths["fingerprint_map"]) as tmp:
        np.savez_compressed(
            tmp,
            positions=result.poses[:, :2],
            fingerprints_dbm=log.fingerprints,
            access_points=np.array(log.access_points),
        )
    _draw(log, result, paths["figure"])
    return log, result, paths


def trajectory_errors(log: SlamLog, result: RadioSlamResult) -> tuple[float, float] | None:
    """ATE (m, unaligned: a log starts at its true pose) of the odometry and of the corrected
    trajectory, where the log has the truth."""
    if log.truth is None:
        return None
    return (
        absolute_trajectory_error(log.odometry, log.truth, align=False),
        absolute_trajectory_error(result.poses, log.truth, align=False),
    )


def _draw(log: SlamLog, result: RadioSlamResult, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 6))
    if log.truth is not None:
        ax.plot(*log.truth.T, color="0.3", lw=1.5, label="truth")
    ax.plot(*log.odometry[:, :2].T, color="tab:red", lw=1, label="odometry")
    ax.plot(*result.poses[:, :2].T, color="tab:blue", lw=1, label="Radio SLAM")
    for i, j in result.closures[:: max(1, len(result.closures) // 200)].tolist():
        ax.plot(*result.poses[[i, j], :2].T, color="tab:green", lw=0.4, alpha=0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(f"{log.path.name}: {len(result.closures)} radio loop closures (green)")
    ax.legend()
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=110)
    plt.close(fig)

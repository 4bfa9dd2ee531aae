"""Offline mapping of a recorded RSSI log (``sfw-gym map``).

A log is a CSV in the layouts of the SfW experiments' public logs::

    x_pixel,y_pixel,rssi                                                  (1 router)
    x_pixel,y_pixel,router1_2.4,router1_5,router2_2.4,router2_5,          (2 routers, 2 bands)

The first two columns are the robot's position (whatever their names; canvas pixels in the SfW
files, about 0.0115 m each), the others RSSI in dBm. The 2-router files end their header with a
comma and carry a 7th, unnamed value per row: the strongest of the four readings, which is what
the authors mapped (``rssi_column="max"``, the default: each router's strongest band; the
mapper's focused router is then the strongest of those). :func:`read_rssi_log` parses a log
leniently where the intent is clear and strictly elsewhere, streaming the file:

- a UTF-8 BOM, blank lines, whitespace around cells and quoted cells are accepted;
- a trailing comma (an empty last header cell and/or an empty last cell on data rows) is dropped;
- an unnamed last column with values is the SfW files' strongest reading when it equals the row's
  maximum (``RssiLog.strongest_dbm``), else an RSSI column of its own;
- an empty RSSI cell (or ``nan``/``NA``/``null``) means "not heard" and becomes -100 dBm;
- a row whose position is empty or NaN is skipped and counted;
- a file without a header (first row all numbers) is read as data, columns named ``column<i>``;
- anything else (missing file, no data rows, a non-numeric or infinite cell, a row with the wrong
  number of cells) raises :class:`~sfw_gym.ConfigError` naming the file, the line and the
  problem.

:func:`map_log` runs :class:`~sfw_gym.mapping.SparseInverseKVisibility` over the log on a grid
covering the trajectory and the routers plus a margin; :func:`write_map` writes the belief map as a
PNG, its ``occupancy_u8`` as ``.npy`` and the grid's georeference as ``.json`` (same stem), each
atomically (temp file + rename).
"""

from __future__ import annotations

import csv
import itertools
import json
import logging
import math
import os
import re
import time
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import IO, Any

import numpy as np

from sfw_gym.core.atomic import atomic_path, write_text_atomic
from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import GridSpec, MapperConfig, SparseInverseKVisibility
from sfw_gym.mapping.reference import sfw_reference_map

logger = logging.getLogger(__name__)

BANDS = ("2.4", "5")
#: ``inverse-k``: sparse inverse k-visibility (ours); ``sfw-reference``: the authors' method.
METHODS = ("inverse-k", "sfw-reference")
#: The offline default: every heard router's ray (``router_policy="all"``) and two passes. On
#: recorded two-router walks it beats ``"strongest"`` and one pass on free-space IoU and
#: interior-wall recall (scripts/studies/mapper_logs_study.py, docs/results/mapping.md); with one
#: router the policies coincide and two passes still win.
OFFLINE_CONFIG = MapperConfig(router_policy="all")
OFFLINE_PASSES = 2
PROGRESS_MIN_ROWS = 5000
MAX_GRID_CELLS = 16_000_000
_CHUNK_ROWS = 65_536
_MISSING = frozenset({"", "nan", "na", "n/a", "null", "none"})
_BAND_PATTERNS = {
    "2.4": re.compile(r"(?:^|[^0-9.])2[._]?4\s*(?:g|ghz)?$", re.IGNORECASE),
    "5": re.compile(r"(?:^|[^0-9.])5\s*(?:g|ghz)?$", re.IGNORECASE),
}


@dataclass(frozen=True)
class RssiLog:
    """A parsed RSSI log, in the CSV's own units.

    Attributes:
        path: The file it was read from.
        position_names: Names of the two position columns.
        rssi_names: Names of the RSSI columns.
        positions: ``(N, 2)`` float64 positions of the kept rows.
        rssi_dbm: ``(N, C)`` float64 RSSI; -100 where a cell was empty ("not heard").
        line_numbers: ``(N,)`` line of each kept row in the file (1-based).
        skipped_lines: Lines of rows skipped for a missing/NaN position.
        strongest_dbm: ``(N,)`` the unnamed last column of the SfW 2-router files, the strongest
            of the row's RSSI cells (what the authors mapped), or None.
    """

    path: Path
    position_names: tuple[str, str]
    rssi_names: tuple[str, ...]
    positions: np.ndarray
    rssi_dbm: np.ndarray
    line_numbers: np.ndarray
    skipped_lines: tuple[int, ...]
    strongest_dbm: np.ndarray | None = None

    @property
    def n_samples(self) -> int:
        """Number of usable rows."""
        return len(self.positions)

    @property
    def n_skipped(self) -> int:
        """Number of rows skipped for a missing/NaN position."""
        return len(self.skipped_lines)


@dataclass
class OfflineMap:
    """The result of :func:`map_log`.

    Attributes:
        log: The parsed log.
        occupancy_u8: The map: 0 wall … 127 unknown … 255 free, ``[row, col]`` on ``grid``.
        method: ``"inverse-k"`` (ours) or ``"sfw-reference"`` (the authors' method).
        mapper: Ours: the mapper after the whole log; None for the reference method.
        grid: The map's grid (world metres).
        positions_m: ``(N, 2)`` trajectory in metres.
        routers_m: ``(R, 2)`` router positions in metres.
        columns: RSSI column used for each router.
        scale_m_per_unit: Metres per CSV unit.
        update_us: Wall time of each ``update()`` call (both passes), microseconds; for the
            reference method the whole map's time spread over the samples.
    """

    log: RssiLog
    occupancy_u8: np.ndarray
    method: str
    mapper: SparseInverseKVisibility | None
    grid: GridSpec
    positions_m: np.ndarray
    routers_m: np.ndarray
    columns: tuple[str, ...]
    scale_m_per_unit: float
    update_us: np.ndarray

    @property
    def us_per_sample(self) -> float:
        """Mean mapper time per sample, microseconds (k-means refits included)."""
        return float(self.update_us.mean()) if len(self.update_us) else 0.0

    @property
    def median_us_per_sample(self) -> float:
        """Median mapper time per sample, microseconds."""
        return float(np.median(self.update_us)) if len(self.update_us) else 0.0


# -- reading -------------------------------------------------------------------------------------
def _cell_value(text: str, where: str, name: str) -> float:
    """One cell as a float; NaN for a missing value; ConfigError for anything else."""
    t = text.strip()
    if t.lower() in _MISSING:
        return math.nan
    try:
        v = float(t)
    except ValueError:
        raise ConfigError(f"{where}: column {name!r}: not a number: {t!r}") from None
    if math.isinf(v):
        raise ConfigError(f"{where}: column {name!r}: infinite value {t!r}")
    return v


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_rssi_log(path: str | os.PathLike[str]) -> RssiLog:
    """Read an RSSI log in the SfW CSV layout (see the module docstring for the rules).

    The file is streamed: rows are parsed into float arrays chunk by chunk, so memory grows with
    the numbers (about 8 bytes per cell), not with the text.

    Args:
        path: The CSV file.

    Returns:
        The parsed log, positions and RSSI in the file's units.

    Raises:
        ConfigError: Naming the file (and line) on a missing/unreadable file, an empty file, no
            RSSI columns, a row with the wrong number of cells, a non-numeric or infinite cell, or
            no usable data row.
    """
    path = Path(path)
    try:
        with open(path, encoding="utf-8-sig", newline="") as fh:
            return _parse_rows(path, _numbered_rows(fh))
    except FileNotFoundError:
        raise ConfigError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise ConfigError(f"{path}: is a directory, not a CSV file") from None
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{path}: not UTF-8 text ({exc.reason} at byte {exc.start})") from None
    except csv.Error as exc:
        raise ConfigError(f"{path}: malformed CSV: {exc}") from None
    except OSError as exc:
        raise ConfigError(f"{path}: cannot read: {exc.strerror or exc}") from None
    except ConfigError:
        raise
    except ValueError as exc:  # a NUL in the file name
        raise ConfigError(f"{str(path)!r}: cannot read: {exc}") from None


def _parse_rows(path: Path, rows: Iterator[tuple[int, list[str]]]) -> RssiLog:
    first_row = next(rows, None)
    if first_row is None:
        raise ConfigError(f"{path}: empty file (expected a header 'x,y,rssi1,...' and data rows)")
    first_line, first = first_row
    header_row = not all(_is_number(c) for c in first if c.strip())
    # A trailing empty header cell: a trailing comma, or (the SfW 2-router files) an unnamed
    # last column whose cells hold a value
    unnamed_last = len(first) > 1 and not first[-1].strip()
    if header_row:
        names = [c.strip() for c in first]
        if unnamed_last:
            names.pop()
        names = [n or f"column{j + 1}" for j, n in enumerate(names)]
        data: Iterator[tuple[int, list[str]]] = rows
    else:
        names = [f"column{j + 1}" for j in range(len(first) - unnamed_last)]
        data = itertools.chain([first_row], rows)
    n_cols = len(names)
    if n_cols < 3:
        raise ConfigError(
            f"{path}:{first_line}: need at least 3 columns (x, y and one RSSI column per "
            f"router), got {n_cols}: {names}"
        )
    chunks: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    values = np.empty((_CHUNK_ROWS, n_cols), np.float64)
    lines = np.empty(_CHUNK_ROWS, np.int64)
    extra = np.full(_CHUNK_ROWS, math.nan)  # the unnamed last column's values
    n = 0
    for line, row in data:
        if len(row) == n_cols + 1 and unnamed_last:
            last, row = row[-1].strip(), row[:-1]
            if last:
                extra[n] = _cell_value(last, f"{path}:{line}", "(unnamed last column)")
        elif len(row) == n_cols + 1 and not row[-1].strip():
            row = row[:-1]  # trailing comma
        if len(row) != n_cols:
            raise ConfigError(
                f"{path}:{line}: expected {n_cols} cells like the header ({', '.join(names)}), "
                f"got {len(row)}"
            )
        lines[n] = line
        try:
            values[n] = [float(c) for c in row]  # fast path: all cells numeric
        except ValueError:
            values[n] = [
                _cell_value(c, f"{path}:{line}", name) for c, name in zip(row, names, strict=True)
            ]
        else:
            if not np.isfinite(values[n]).all():  # 'nan' parsed, or 'inf'
                values[n] = [
                    _cell_value(c, f"{path}:{line}", name)
                    for c, name in zip(row, names, strict=True)
                ]
        n += 1
        if n == _CHUNK_ROWS:
            chunks.append((values, lines, extra))
            values, lines = np.empty_like(values), np.empty_like(lines)
            extra, n = np.full(_CHUNK_ROWS, math.nan), 0
    chunks.append((values[:n], lines[:n], extra[:n]))
    all_values, all_lines, all_extra = (np.concatenate(part) for part in zip(*chunks, strict=True))
    del chunks
    if not len(all_values):
        raise ConfigError(f"{path}: no data rows after the header on line {first_line}")

    keep = np.isfinite(all_values[:, :2]).all(axis=1)
    skipped = tuple(int(v) for v in all_lines[~keep])
    if not keep.any():
        raise ConfigError(
            f"{path}: no row has a position ({len(skipped)} data rows, all with a missing x or y)"
        )
    rssi = all_values[keep, 2:]
    rssi[np.isnan(rssi)] = NOT_HEARD_DBM
    rssi_names = tuple(names[2:])
    strongest = None
    unnamed = all_extra[keep]
    if np.isfinite(unnamed).any():
        heard = np.where(np.isnan(unnamed), NOT_HEARD_DBM, unnamed)
        if np.abs(heard - rssi.max(axis=1)).max() <= 0.5:  # the SfW files' strongest reading
            strongest = heard
        else:  # a column of its own, only unnamed
            rssi = np.column_stack([rssi, heard])
            rssi_names += (f"column{n_cols + 1}",)
    return RssiLog(
        path=path,
        position_names=(names[0], names[1]),
        rssi_names=rssi_names,
        positions=all_values[keep, :2],
        rssi_dbm=rssi,
        line_numbers=all_lines[keep],
        skipped_lines=skipped,
        strongest_dbm=strongest,
    )


def _numbered_rows(fh: IO[str]) -> Iterator[tuple[int, list[str]]]:
    """Yield ``(line, cells)`` for every non-blank CSV row (line = where the row starts)."""
    reader = csv.reader(fh, skipinitialspace=True)
    start = 1
    for row in reader:
        if any(c.strip() for c in row):
            yield start, row
        start = reader.line_num + 1


# -- columns -> routers ---------------------------------------------------------------------------
def _band_of(name: str) -> str | None:
    for band, pattern in _BAND_PATTERNS.items():
        if pattern.search(name.strip()):
            return band
    return None


def select_router_columns(log: RssiLog, n_routers: int, band: str | None = None) -> list[int]:
    """Which RSSI column feeds each router.

    With R routers: R RSSI columns are used as they are; 2R columns hold two bands per router. If
    every column name ends in a band tag (``_2.4``, ``_5``, ``_5GHz``, ...) with R columns of each,
    the columns of the chosen band are used in file order; otherwise the layout is taken to be the
    SfW one, interleaved per router (2.4 GHz first, then 5 GHz).

    Args:
        log: The parsed log.
        n_routers: R, the number of router positions given.
        band: ``"2.4"`` or ``"5"``; None = 2.4 GHz where there is a choice.

    Returns:
        Indices into ``log.rssi_names``, one per router.

    Raises:
        ConfigError: If the column count is neither R nor 2R, or ``band`` is unknown or
            contradicts the column names.
    """
    if band is not None and band not in BANDS:
        raise ConfigError(f"band must be one of {BANDS}, got {band!r}")
    names = log.rssi_names
    n_cols = len(names)
    tags = [_band_of(n) for n in names]
    if n_cols == n_routers:
        if band is not None and all(t is not None and t != band for t in tags):
            raise ConfigError(
                f"{log.path}: --band {band} asked for, but the {n_cols} RSSI columns are all "
                f"another band: {', '.join(names)}"
            )
        return list(range(n_cols))
    if n_cols == 2 * n_routers:
        want = band or "2.4"
        if all(t is not None for t in tags) and tags.count("2.4") == n_routers:
            return [j for j, t in enumerate(tags) if t == want]
        return list(range(0 if want == "2.4" else 1, n_cols, 2))
    raise ConfigError(
        f"{log.path}: {n_routers} router positions given, but the file has {n_cols} RSSI columns "
        f"({', '.join(names)}); expected {n_routers} (one per router) or {2 * n_routers} "
        "(2.4 and 5 GHz per router)"
    )


def router_column_groups(
    log: RssiLog, n_routers: int, rssi_column: str | None = None
) -> list[list[int]]:
    """Per router, the RSSI columns (indices into ``log.rssi_names``) whose strongest reading is
    that router's RSSI.

    Args:
        log: The parsed log.
        n_routers: R, the number of router positions given.
        rssi_column: ``"max"`` (each router's strongest band: what the SfW authors mapped, and
            the default), ``"2.4"`` or ``"5"`` (one band, :func:`select_router_columns`), or
            R comma-separated column names in router order.

    Raises:
        ConfigError: Naming the columns found and the choices known.
    """
    if rssi_column in (None, "max"):
        if len(log.rssi_names) == n_routers:
            return [[j] for j in range(n_routers)]
        bands = [select_router_columns(log, n_routers, band) for band in BANDS]
        return [list(pair) for pair in zip(*bands, strict=True)]
    if rssi_column in BANDS:
        return [[j] for j in select_router_columns(log, n_routers, rssi_column)]
    wanted = [name.strip() for name in rssi_column.split(",")]
    unknown = [name for name in wanted if name not in log.rssi_names]
    if unknown or len(wanted) != n_routers:
        problem = f"no column {unknown}" if unknown else f"{len(wanted)} names"
        raise ConfigError(
            f"{log.path}: --rssi-column {rssi_column!r}: {problem}; give 'max', a band "
            f"({', '.join(BANDS)}) or {n_routers} of the RSSI columns "
            f"({', '.join(log.rssi_names)}), one per router"
        )
    return [[log.rssi_names.index(name)] for name in wanted]


# -- mapping --------------------------------------------------------------------------------------
def map_log(
    log: RssiLog | str | os.PathLike[str],
    routers_xy: Sequence[Sequence[float]] | np.ndarray,
    *,
    scale_m_per_unit: float = 1.0,
    resolution_m: float = 0.05,
    margin_m: float = 1.0,
    rssi_column: str | None = None,
    config: MapperConfig | None = None,
    method: str = "inverse-k",
    passes: int = OFFLINE_PASSES,
    progress: bool | None = None,
    max_cells: int = MAX_GRID_CELLS,
) -> OfflineMap:
    """Run the sparse inverse k-visibility mapper over a log.

    Args:
        log: A parsed log or a CSV path.
        routers_xy: ``(R, 2)`` router positions in the CSV's units.
        scale_m_per_unit: Metres per CSV unit, for positions and routers (e.g. 0.05 for pixels).
        resolution_m: Map cell size, metres.
        margin_m: Border around the bounding box of the trajectory and routers, metres.
        rssi_column: Which RSSI feeds each router (:func:`router_column_groups`; default
            ``"max"``: its strongest band, as the SfW authors mapped).
        config: Mapper configuration (default :data:`OFFLINE_CONFIG`: every router's ray).
        method: ``"inverse-k"`` (ours) or ``"sfw-reference"`` (the authors' method,
            :mod:`sfw_gym.mapping.reference`; it ignores ``config`` and ``passes``).
        passes: 2 (the default): the log forward and then reversed through the same mapper (the
            second pass sees the whole trajectory and the final thresholds, as the authors
            do); 1: forward only.
        progress: Show a tqdm bar on stderr; None = only for logs over 5,000 rows.
        max_cells: Refuse grids larger than this (a forgotten ``--scale`` on a pixel log).

    Returns:
        The mapper after the whole log, with the trajectory and per-update timings.

    Raises:
        ConfigError: On bad input (see :func:`read_rssi_log`, :func:`select_router_columns`), a
            non-positive scale, resolution or margin, or a grid over ``max_cells``.
    """
    if method not in METHODS:
        raise ConfigError(f"method must be one of {METHODS}, got {method!r}")
    if passes not in (1, 2):
        raise ConfigError(f"passes must be 1 or 2, got {passes!r}")
    if not isinstance(log, RssiLog):
        log = read_rssi_log(log)
    for name, v in (("scale_m_per_unit", scale_m_per_unit), ("resolution_m", resolution_m)):
        if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
            raise ConfigError(f"{name} must be a finite number > 0, got {v!r}")
    if not (isinstance(margin_m, (int, float)) and math.isfinite(margin_m) and margin_m >= 0):
        raise ConfigError(f"margin_m must be a finite number >= 0, got {margin_m!r}")
    routers = np.asarray(routers_xy, dtype=np.float64)
    if routers.ndim != 2 or routers.shape[1] != 2 or len(routers) == 0:
        raise ConfigError(f"routers_xy must have shape (R, 2) with R >= 1, got {routers.shape}")
    if not np.isfinite(routers).all():
        raise ConfigError(f"routers_xy must be finite, got {routers.tolist()}")
    groups = router_column_groups(log, len(routers), rssi_column)
    positions_m = log.positions * scale_m_per_unit
    routers_m = routers * scale_m_per_unit
    rssi = np.column_stack([log.rssi_dbm[:, g].max(axis=1) for g in groups])

    pts = np.concatenate([positions_m, routers_m])
    # At least one cell of margin: the mapper needs positions strictly inside the grid.
    pad = max(margin_m, resolution_m)
    lo, hi = pts.min(axis=0) - pad, pts.max(axis=0) + pad
    grid = GridSpec.covering((lo[0], lo[1], hi[0], hi[1]), float(resolution_m))
    if grid.shape[0] * grid.shape[1] > max_cells:
        size = (hi - lo).round(1).tolist()
        raise ConfigError(
            f"{log.path}: the map would be {grid.shape[1]} x {grid.shape[0]} cells "
            f"({size[0]} x {size[1]} m at {resolution_m} m), over {max_cells:,}; is --scale "
            f"(metres per CSV unit, now {scale_m_per_unit}) right? Else use a coarser --resolution"
        )
    if method == "sfw-reference":
        start = time.perf_counter()
        occupancy = sfw_reference_map(grid, routers_m, positions_m, rssi)
        mapper, times = None, np.full(len(rssi), (time.perf_counter() - start) / max(len(rssi), 1))
    else:
        mapper = SparseInverseKVisibility(grid, routers_m, config or OFFLINE_CONFIG)
        times = _run_mapper(mapper, log, positions_m, rssi, passes, progress)
        occupancy = mapper.occupancy_u8
    logger.info(
        "%s: %d samples mapped by %s (%d pass(es)), %.1f µs a sample",
        log.path, len(rssi), method, 1 if method == "sfw-reference" else passes,
        times.mean() * 1e6 if len(times) else 0.0,
    )  # fmt: skip
    return OfflineMap(
        log=log,
        occupancy_u8=occupancy,
        method=method,
        mapper=mapper,
        grid=grid,
        positions_m=positions_m,
        routers_m=routers_m,
        columns=tuple(_column_label(log, g) for g in groups),
        scale_m_per_unit=float(scale_m_per_unit),
        update_us=times * 1e6,
    )


def _run_mapper(
    mapper: SparseInverseKVisibility,
    log: RssiLog,
    positions_m: np.ndarray,
    rssi: np.ndarray,
    passes: int,
    progress: bool | None,
) -> np.ndarray:
    """Feed the log (forward, then reversed if ``passes == 2``); each update's seconds."""
    _warm_up(mapper.config)
    n = len(positions_m)
    order = np.arange(n) if passes == 1 else np.concatenate([np.arange(n), np.arange(n)[::-1]])
    times = np.empty(len(order), np.float64)
    show = n > PROGRESS_MIN_ROWS if progress is None else progress
    bar = _progress(len(order), f"mapping {log.path.name}") if show else None
    clock = time.perf_counter
    update = mapper.update
    try:
        for step, i in enumerate(order):
            t0 = clock()
            try:
                update(positions_m[i], rssi[i])
            except ConfigError as exc:
                raise ConfigError(f"{log.path}:{log.line_numbers[i]}: {exc}") from exc
            times[step] = clock() - t0
            if bar is not None and (step & 255) == 255:
                bar.update(256)
    finally:
        if bar is not None:
            bar.update(len(order) - bar.n)
            bar.close()
    return times


def _column_label(log: RssiLog, group: list[int]) -> str:
    names = [log.rssi_names[j] for j in group]
    return names[0] if len(names) == 1 else f"max({', '.join(names)})"


def _warm_up(config: MapperConfig) -> None:
    """Run a throwaway mapper through its first k-means fit.

    So one-time costs (loading the compiled kernels, importing scikit-learn: ~1 s) stay out of
    the per-sample timings.
    """
    grid = GridSpec((0.0, 0.0), 0.1, (40, 40))
    far = -1.0 - config.min_distance_m  # readings nearer than that are not used for fitting
    mapper = SparseInverseKVisibility(grid, [[far, far]], replace(config, outer_bounds_m=None))
    for i in range(min(config.refit_min_samples + 2, 2000)):
        a = 0.37 * i
        pos = (2.0 + 1.5 * math.cos(a), 2.0 + 1.5 * math.sin(a))
        mapper.update(pos, np.array([-45.0 - 15.0 * (i % 3) - (i % 5)]))


def _progress(total: int, desc: str) -> Any:
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit="sample", mininterval=0.5, leave=False)


# -- writing -------------------------------------------------------------------------------------
def write_map(result: OfflineMap, out: str | os.PathLike[str], *, y_down: bool = False) -> dict:
    """Write the map: ``out`` (PNG), and beside it ``.npy`` (occupancy_u8) and ``.json`` (grid).

    The PNG shows the belief map (black wall, grey unknown, white free) with the trajectory and the
    routers, axes in metres, y up (north up). The ``.npy`` is ``occupancy_u8``, indexed
    ``[row, col]`` = ``[y, x]`` with row 0 at ``origin_xy`` y; the ``.json`` holds that origin, the
    resolution, the scale and the routers, so the array can be placed back on the CSV's frame.

    Args:
        result: The output of :func:`map_log`.
        out: PNG path (must end in ``.png``).
        y_down: The CSV's y grows downward (image pixels): draw y downward so the PNG matches the
            floorplan image. The ``.npy`` is unaffected.

    Returns:
        ``{"png": Path, "npy": Path, "json": Path}``.

    Raises:
        ConfigError: If ``out`` does not end in ``.png``.
    """
    out = Path(out)
    if out.suffix.lower() != ".png":
        raise ConfigError(f"--out must be a .png file, got {str(out)!r}")
    npy, meta = out.with_suffix(".npy"), out.with_suffix(".json")
    occ = np.array(result.occupancy_u8)
    with atomic_path(npy) as tmp:
        np.save(tmp, occ, allow_pickle=False)
    info = {
        "source": str(result.log.path),
        "origin_xy_m": list(result.grid.origin_xy),
        "resolution_m": result.grid.resolution_m,
        "shape": list(result.grid.shape),
        "indexing": "[row, col] = [y, x]; cell centre = origin + (index + 0.5) * resolution",
        "values": "0 wall ... 127 unknown ... 255 free",
        "scale_m_per_unit": result.scale_m_per_unit,
        "routers_m": result.routers_m.tolist(),
        "rssi_columns": list(result.columns),
        "n_samples": result.log.n_samples,
        "n_skipped": result.log.n_skipped,
        "method": result.method,
        "mapper_config": result.mapper.config.to_dict() if result.mapper else None,
    }
    text = json.dumps(info, indent=2) + "\n"
    write_text_atomic(meta, text)
    with atomic_path(out) as tmp, open(tmp, "wb") as fh:
        _draw(result, occ, fh, y_down)
    return {"png": out, "npy": npy, "json": meta}


def _draw(result: OfflineMap, occ: np.ndarray, fh: IO[bytes], y_down: bool) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x0, y0, x1, y1 = result.grid.bounds
    aspect = (y1 - y0) / (x1 - x0)
    width = 9.0
    fig, ax = plt.subplots(figsize=(width, min(max(width * aspect, 3.0), 14.0) + 0.8))
    try:
        im = ax.imshow(
            occ,
            cmap="gray",
            vmin=0,
            vmax=255,
            origin="lower",
            extent=(x0, x1, y0, y1),
            interpolation="nearest",
        )
        cbar = fig.colorbar(im, ax=ax, shrink=0.7, ticks=[0, 127, 255])
        cbar.ax.set_yticklabels(["wall", "unknown", "free"])
        p = result.positions_m
        ax.plot(p[:, 0], p[:, 1], "-", color="tab:blue", lw=0.7, alpha=0.7, label="trajectory")
        ax.plot(*p[0], "o", color="tab:green", ms=6, label="start")
        ax.plot(*p[-1], "s", color="tab:orange", ms=6, label="end")
        for r, ((rx, ry), name) in enumerate(zip(result.routers_m, result.columns, strict=True)):
            ax.plot(rx, ry, "r^", ms=10, label="router" if r == 0 else None)
            ax.annotate(
                f"R{r + 1} ({name})",
                (rx, ry),
                color="red",
                xytext=(5, 5),
                textcoords="offset points",
                fontsize=8,
            )
        if y_down:
            ax.invert_yaxis()
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]" + (" (down)" if y_down else ""))
        ax.set_title(
            f"{result.log.path.name}: {result.log.n_samples} samples, "
            f"{result.grid.resolution_m:g} m cells, {result.median_us_per_sample:.0f} µs/sample"
        )
        ax.legend(loc="upper right", fontsize=8, framealpha=0.8)
        fig.tight_layout()
        fig.savefig(fh, format="png", dpi=120, bbox_inches="tight")
    finally:
        plt.close(fig)

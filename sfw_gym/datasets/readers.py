"""Readers: the generic fingerprint CSV (the command line's contract), UJIIndoorLoc (its zip or
CSVs) and WiFine (its per-walk CSVs). pandas parses; every bad input is one ``ConfigError`` line
naming the file, and where it can the line and column."""

from __future__ import annotations

import csv
import io
import os
import zipfile
from dataclasses import replace
from pathlib import Path
from typing import IO, Any

import numpy as np

from sfw_gym.core.errors import ConfigError
from sfw_gym.datasets.fingerprints import META_COLUMNS, Fingerprints

#: The generic CSV's default "not heard" value (UJIIndoorLoc's convention); an empty cell too.
GENERIC_NOT_HEARD = 100.0
UJI_NOT_HEARD = 100.0
WIFINE_NOT_HEARD = -100.0
UJI_SPLITS = {"train": "trainingData.csv", "validation": "validationData.csv"}
#: WiFine's floorIDs → the building's floor numbers, as its layout images are named.
WIFINE_FLOORS = {0: 4, 1: 5, 2: 6}
#: A ROS map_server YAML for a WiFine layout: 0.1 m a pixel, origin at the bottom-left corner,
#: black walls on white (../shared/datasets/README.md).
WIFINE_MAP_YAML = """image: {image}
resolution: 0.1
origin: [0.0, 0.0, 0.0]
negate: 0
occupied_thresh: 0.65
free_thresh: 0.196
"""

Source = str | os.PathLike[str] | IO[str] | IO[bytes]


def read_csv(source: Source, *, not_heard: float = GENERIC_NOT_HEARD) -> Fingerprints:
    """The generic CSV: a header row; ``x``, ``y`` in metres; optional ``floor``, ``building``
    (integers), ``trajectory`` (any label) and ``t`` (seconds); every other column one access
    point's RSSI in dBm, ``not_heard`` or an empty cell meaning not heard. ``source``: a path or
    an open file."""
    name, text = _read_text(source)
    header = _header(name, text)
    if "x" not in header or "y" not in header:
        raise ConfigError(f"{name}: no 'x' and 'y' columns (found {header[:6]})")
    aps = [c for c in header if c not in META_COLUMNS]
    if not aps:
        raise ConfigError(f"{name}: no access point columns (only {header})")
    frame = _parse(name, io.StringIO(text), {"trajectory": str})
    return _fingerprints(name, frame, aps, not_heard, {k: k for k in META_COLUMNS if k in header})


def read_ujiindoorloc(source: str | os.PathLike[str], split: str = "train") -> Fingerprints:
    """UJIIndoorLoc's ``split`` ("train" or "validation") from its zip, the folder holding the
    zip or the CSVs, or one of its CSVs. Positions are Web-Mercator metres (EPSG:3857), as
    the literature reports them."""
    if split not in UJI_SPLITS:
        raise ConfigError(f"split must be one of {sorted(UJI_SPLITS)}, got {split!r}")
    path, member = Path(source), UJI_SPLITS[split]
    if path.is_dir():
        path = path / member if (path / member).is_file() else path / "UJIIndoorLoc.zip"
    name = str(path)
    if path.suffix.lower() == ".zip":
        try:
            with zipfile.ZipFile(path) as archive:
                inner = [n for n in archive.namelist() if Path(n).name == member]
                if not inner:
                    raise ConfigError(f"{name}: no {member} inside")
                with archive.open(inner[0]) as fh:
                    text = fh.read().decode("utf-8-sig")
        except (OSError, zipfile.BadZipFile) as exc:
            raise ConfigError(f"{name}: cannot read UJIIndoorLoc: {exc}") from None
        name = f"{name}:{member}"
    else:
        name, text = _read_text(path)
    header = _header(name, text)
    aps = [c for c in header if c.startswith("WAP")]
    need = ["LONGITUDE", "LATITUDE", "FLOOR", "BUILDINGID", "TIMESTAMP"]
    missing = [c for c in need if c not in header]
    if missing or not aps:
        raise ConfigError(f"{name}: not UJIIndoorLoc (missing {missing or 'WAP columns'})")
    frame = _parse(name, io.StringIO(text), {})
    columns = {"x": "LONGITUDE", "y": "LATITUDE", "floor": "FLOOR", "building": "BUILDINGID"}
    return _fingerprints(name, frame, aps, UJI_NOT_HEARD, {**columns, "t": "TIMESTAMP"})


def read_wifine(source: str | os.PathLike[str]) -> Fingerprints:
    """WiFine walks: one CSV (``train_4_26.csv``) or a folder of them (``wifine/val``); each
    file is one walk (``trajectory`` = its name), ``floor`` its floorID (0, 1, 2 = floors 4, 5,
    6), ``t`` its timestamp; -100 means not heard."""
    path = Path(source)
    files = sorted(path.glob("*.csv")) if path.is_dir() else [path]
    if not files:
        raise ConfigError(f"{path}: no WiFine CSV files in this folder")
    parts = []
    for file in files:
        name, text = _read_text(file)
        header = _header(name, text)
        need = ["x", "y", "floorID", "timestamp"]
        missing = [c for c in need if c not in header]
        if missing:
            raise ConfigError(f"{name}: not a WiFine walk (missing {missing})")
        aps = [c for c in header if c.isdigit()]
        frame = _parse(name, io.StringIO(text), {})
        columns = {"x": "x", "y": "y", "floor": "floorID", "t": "timestamp"}
        walk = _fingerprints(name, frame, aps, WIFINE_NOT_HEARD, columns)
        parts.append(replace(walk, trajectory=np.full(len(walk), file.stem)))
    return concatenate(parts, name=str(path))


def write_wifine_maps(
    layouts: str | os.PathLike[str], folder: str | os.PathLike[str]
) -> dict[int, Path]:
    """A ROS map YAML per WiFine floor in ``folder``, each naming its layout image in
    ``layouts`` (``Floor_{4,5,6}_10cm.png``) by absolute path; keyed by floorID."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    maps = {}
    for floor_id, floor in WIFINE_FLOORS.items():
        image = (Path(layouts) / f"Floor_{floor}_10cm.png").resolve()
        maps[floor_id] = folder / f"wifine_floor_{floor}.yaml"
        maps[floor_id].write_text(WIFINE_MAP_YAML.format(image=image), encoding="utf-8")
    return maps


def concatenate(parts: list[Fingerprints], name: str) -> Fingerprints:
    """Scans of several files over the same access points, in order."""
    first = parts[0]
    for p in parts[1:]:
        if p.access_points != first.access_points:
            raise ConfigError(f"{p.name}: its access points differ from {first.name}'s")

    def joined(key: str):
        values = [getattr(p, key) for p in parts]
        return None if any(v is None for v in values) else np.concatenate(values)

    return Fingerprints(
        np.concatenate([p.positions for p in parts]),
        np.concatenate([p.rssi_dbm for p in parts]),
        first.access_points,
        floor=joined("floor"),
        building=joined("building"),
        trajectory=joined("trajectory"),
        t=joined("t"),
        name=name,
    )


# ----------------------------------------------------------------------------------- helpers
def _read_text(source: Source) -> tuple[str, str]:
    if hasattr(source, "read"):
        name = str(getattr(source, "name", "<file>"))
        data = source.read()
        text = data.decode("utf-8-sig") if isinstance(data, bytes) else data
        return name, text.removeprefix("\ufeff")
    name = str(source)
    try:
        return name, Path(source).read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{name}: cannot read: {exc}") from None


def _header(name: str, text: str) -> list[str]:
    first = next(csv.reader(io.StringIO(text)), None)
    header = [c.strip() for c in first] if first else []
    if not any(header):
        raise ConfigError(f"{name}: empty file (no header row)")
    repeated = sorted({c for c in header if header.count(c) > 1})
    if repeated:
        raise ConfigError(f"{name}: column name(s) repeated in the header: {repeated[:5]}")
    return header


def _parse(name: str, buffer: io.StringIO, dtype: dict[str, Any]):
    import pandas as pd

    try:
        frame = pd.read_csv(buffer, dtype=dtype, skipinitialspace=True)
    except (pd.errors.ParserError, ValueError) as exc:
        raise ConfigError(f"{name}: malformed CSV: {str(exc).splitlines()[0]}") from None
    frame.columns = [str(c).strip() for c in frame.columns]
    if frame.empty:
        raise ConfigError(f"{name}: no data rows")
    return frame


def _numeric(name: str, frame, column: str) -> np.ndarray:
    """A column as float64; the first cell that is not a number named by line and column."""
    import pandas as pd

    values = frame[column]
    if values.dtype.kind in "fiub":
        return values.to_numpy(np.float64)
    numbers = pd.to_numeric(values, errors="coerce")
    bad = numbers.isna() & values.notna() & (values.astype(str).str.strip() != "")
    if bad.any():
        row = int(np.flatnonzero(bad.to_numpy())[0])
        raise ConfigError(
            f"{name}: line {row + 2}, column {column!r}: not a number: {values.iloc[row]!r}"
        )
    return numbers.to_numpy(np.float64)


def _fingerprints(
    name: str, frame, aps: list[str], not_heard: float, columns: dict[str, str]
) -> Fingerprints:
    """Build from a parsed frame; ``columns`` maps our fields to the file's column names."""
    rssi = np.column_stack([_numeric(name, frame, c) for c in aps])
    rssi[rssi == not_heard] = np.nan
    xy = np.column_stack([_numeric(name, frame, columns[k]) for k in ("x", "y")])
    missing = ~np.isfinite(xy)
    if missing.any():
        row, col = np.argwhere(missing)[0]
        raise ConfigError(
            f"{name}: line {row + 2}, column {columns['xy'[col]]!r}: missing or not finite"
        )
    extra: dict[str, np.ndarray] = {}
    for key in ("floor", "building", "t"):
        if key in columns:
            values = _numeric(name, frame, columns[key])
            bad = ~np.isfinite(values)
            if key != "t":
                bad |= values != np.round(values)
            if bad.any():
                row = int(np.flatnonzero(bad)[0])
                what = "an integer" if key != "t" else "a number"
                raise ConfigError(f"{name}: line {row + 2}, column {columns[key]!r}: not {what}")
            extra[key] = values
    if "trajectory" in columns:
        labels = frame[columns["trajectory"]].fillna("").astype(str).str.strip().to_numpy()
        extra["trajectory"] = labels
    return Fingerprints(xy, rssi, tuple(aps), name=name, **extra)

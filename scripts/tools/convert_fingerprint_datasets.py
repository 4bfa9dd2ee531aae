"""Convert public WiFi fingerprint datasets to the package's generic CSV (issue 38's
generalisation check: the default method, defaults unchanged, on datasets it was not tuned on).

    python scripts/tools/convert_fingerprint_datasets.py [--sod DIR] [--feng DIR]
        [--out /work/external_datasets/converted]

Each dataset keeps its authors' own train/test split: ``OUT/<name>/train.csv`` and
``OUT/<name>/test.csv``, written with :meth:`sfw_gym.datasets.Fingerprints.to_csv` (``x``, ``y`` in
metres, then ``floor``/``building`` where the data has them, then one column per access point in
dBm; not heard = an empty cell) and read back with :func:`sfw_gym.datasets.read_csv` as a check.
The raw datasets are not in this repository; bring them in from their public repositories and
point ``--sod``/``--feng`` at the checked-out folders.

Datasets
--------

``sod`` / ``sod_<building>`` / ``sod_ap30``: **SODIndoorLoc** (supplementary open dataset for WiFi
indoor localisation), github ``renwudao24/SODIndoorLoc``; J. Bi, Y. Wang, B. Yu et al.,
"Supplementary open dataset for WiFi indoor localization based on received signal strength",
*Satellite Navigation* 3, 25 (2022). Licence: the repository has **no licence file**; the
README publishes the data with a citation request ("Jingxue Bi. Supplementary Open Dataset for WiFi
Fingerprint-based Indoor Localization"), and the paper (open access, CC BY 4.0) points to it.
Three buildings in three cities (CETC331 floors 1-3, HCXY floor 4, SYL floor 4), so access points
never repeat across buildings: their columns are named ``<building>_MACnnn`` here.
Columns ``MAC001 ... MACn`` (dBm, -104..0, ``100`` = not heard), then ``ECoord, NCoord`` (east,
north in metres, a local frame per building), ``FloorID``, ``BuildingID`` (1 CETC331, 2 HCXY,
3 SYL), ``SceneID, UserID, PhoneID, SampleTimes``. The authors' split: reference points
(``Training_*``) and separate test points with 10 scans each (``Testing_*``).

- ``sod``: the three buildings together, all detected MACs: ``Training_CETC331`` (955 reference
  points, one scan each) + ``Training_HCXY_All_Avg`` (379) + ``Training_SYL_All_Avg`` (296; each
  row the mean of 30 scans) -> ``Testing_CETC331`` + ``Testing_HCXY_All`` + ``Testing_SYL_All``
  (840 + 860 + 1020 scans). ``sod_<building>``: one building of it alone.
- ``sod_ap30``: HCXY and SYL with only the pre-installed access points and all 30 raw scans per
  reference point: ``Training_{HCXY,SYL}_AP_30`` (11,370 + 8,880) -> ``Testing_{HCXY,SYL}_AP``.
  (``Training_*_All_30`` are not in the stored snapshot.)

Found while converting: ``Training_SYL_All_Avg.csv``'s ``BuildingID`` column holds 3, 4, ..., 298
(a row counter), so the building is taken from the folder, not the column, everywhere.

``feng_<scene>``: **WiFi RSS & RTT dataset with different LOS conditions**, github
``Fx386483710/WiFi_RSS_RTT_Dataset_for_Model_Selection``; X. Feng, K. A. Nguyen, Z. Luo, "A WiFi
RSS-RTT indoor positioning system using dynamic model switching algorithm", *IEEE Journal of
Indoor and Seamless Positioning and Navigation* (2024); data: Zenodo, doi 10.5281/zenodo.11558792.
Licence: the repository's ``LICENSE`` is **MIT**. Three single-floor scenes, each its own set of
4-5 access points: ``lecture_theatre`` (entirely line of sight), ``office`` (entirely non line of
sight), ``corridor`` (mixed); 60 scans per reference point; the authors' split into
``database_<scene>_train.csv`` and ``database_<scene>_test.csv`` (disjoint points). Columns ``X,
Y`` (grid indices of the 0.6 m x 0.6 m survey grid, so metres = 0.6 x index: the corridor's 0..56
spans its stated 35 m), ``AP1..AP5 RTT(mm)`` (not used here), ``AP1..AP5 RSS(dBm)`` (``-200`` =
not heard), ``LOS APs``. Only the RSS columns are kept, named ``AP<k>``.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import pandas as pd

from sfw_gym.datasets import Fingerprints, read_csv

SOD_NOT_HEARD = 100
SOD_BUILDINGS = {"CETC331": 1, "HCXY": 2, "SYL": 3}
#: (train file, test file) per building, all detected MACs.
SOD_ALL = {
    "CETC331": ("Training_CETC331.csv", "Testing_CETC331.csv"),
    "HCXY": ("Training_HCXY_All_Avg.csv", "Testing_HCXY_All.csv"),
    "SYL": ("Training_SYL_All_Avg.csv", "Testing_SYL_All.csv"),
}
SOD_AP30 = {
    "HCXY": ("Training_HCXY_AP_30.csv", "Testing_HCXY_AP.csv"),
    "SYL": ("Training_SYL_AP_30.csv", "Testing_SYL_AP.csv"),
}
FENG_SCENES = ("lecture_theatre", "office", "corridor")
FENG_NOT_HEARD = -200.0
FENG_GRID_M = 0.6


def read_sod(path: Path, building: str) -> Fingerprints:
    """One SODIndoorLoc sheet: its MAC columns (100 -> not heard), ECoord/NCoord in metres,
    FloorID, and the building from its folder."""
    frame = pd.read_csv(path)
    macs = [c for c in frame.columns if c.startswith("MAC")]
    rssi = frame[macs].to_numpy(np.float64)
    rssi[rssi == SOD_NOT_HEARD] = np.nan
    return Fingerprints(
        positions=frame[["ECoord", "NCoord"]].to_numpy(np.float64),
        rssi_dbm=rssi,
        access_points=tuple(f"{building}_{m}" for m in macs),
        floor=frame["FloorID"].to_numpy(np.int64),
        building=np.full(len(frame), SOD_BUILDINGS[building], np.int64),
        name=str(path),
    )


def join(parts: list[Fingerprints], name: str) -> Fingerprints:
    """Scans of buildings with disjoint access points, over the union of their columns."""
    aps = tuple(dict.fromkeys(ap for p in parts for ap in p.access_points))
    aligned = [p.aligned_to(aps) for p in parts]
    return Fingerprints(
        positions=np.concatenate([p.positions for p in aligned]),
        rssi_dbm=np.concatenate([p.rssi_dbm for p in aligned]),
        access_points=aps,
        floor=np.concatenate([p.floor for p in aligned]),
        building=np.concatenate([p.building for p in aligned]),
        name=name,
    )


def read_feng(path: Path) -> Fingerprints:
    """One Feng et al. scene file: the RSS columns only (-200 -> not heard), X/Y grid indices
    times 0.6 m."""
    frame = pd.read_csv(path)
    columns = [c for c in frame.columns if c.endswith("RSS(dBm)")]
    rssi = frame[columns].to_numpy(np.float64)
    rssi[rssi <= FENG_NOT_HEARD] = np.nan
    return Fingerprints(
        positions=frame[["X", "Y"]].to_numpy(np.float64) * FENG_GRID_M,
        rssi_dbm=rssi,
        access_points=tuple(c.split()[0] for c in columns),
        name=str(path),
    )


def write(out: Path, name: str, train: Fingerprints, test: Fingerprints) -> None:
    folder = out / name
    folder.mkdir(parents=True, exist_ok=True)
    for split, fp in (("train", train), ("test", test)):
        path = fp.to_csv(folder / f"{split}.csv")
        back = read_csv(path)
        assert back.access_points == fp.access_points and len(back) == len(fp), path
        assert np.array_equal(np.isnan(back.rssi_dbm), np.isnan(fp.rssi_dbm)), path
        assert np.allclose(back.positions, fp.positions), path
    print(
        f"{name}: train {len(train)} scans, test {len(test)}, "
        f"{train.n_access_points} access points -> {folder}"
    )


def convert_sod(root: Path, out: Path) -> None:
    parts = {
        b: (read_sod(root / b / tr, b), read_sod(root / b / te, b))
        for b, (tr, te) in SOD_ALL.items()
    }
    for b, (train, test) in parts.items():
        write(out, f"sod_{b.lower()}", train, test)
    write(
        out,
        "sod",
        join([tr for tr, _ in parts.values()], "sod train"),
        join([te for _, te in parts.values()], "sod test"),
    )
    ap30 = [
        (read_sod(root / b / tr, b), read_sod(root / b / te, b)) for b, (tr, te) in SOD_AP30.items()
    ]
    write(
        out,
        "sod_ap30",
        join([tr for tr, _ in ap30], "sod_ap30 train"),
        join([te for _, te in ap30], "sod_ap30 test"),
    )


def convert_feng(root: Path, out: Path) -> None:
    for scene in FENG_SCENES:
        train = read_feng(root / "data" / f"database_{scene}_train.csv")
        test = read_feng(root / "data" / f"database_{scene}_test.csv")
        write(out, f"feng_{scene}", train, test)


def main() -> None:
    ext = Path("/work/external_datasets")
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sod", type=Path, default=ext / "renwudao24+SODIndoorLoc")
    parser.add_argument(
        "--feng", type=Path, default=ext / "Fx386483710+WiFi_RSS_RTT_Dataset_for_Model_Selection"
    )
    parser.add_argument("--out", type=Path, default=ext / "converted")
    args = parser.parse_args()
    if args.sod.is_dir():
        convert_sod(args.sod, args.out)
    else:
        print(f"skipped SODIndoorLoc: no folder {args.sod}")
    if args.feng.is_dir():
        convert_feng(args.feng, args.out)
    else:
        print(f"skipped Feng et al.: no folder {args.feng}")


if __name__ == "__main__":
    main()

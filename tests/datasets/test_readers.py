"""The fingerprint readers on small files written in each format, their one-line errors, and the
generic CSV's round trip."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.datasets import (
    WIFINE_FLOORS,
    Fingerprints,
    read_csv,
    read_ujiindoorloc,
    read_wifine,
    write_wifine_maps,
)
from tests.conftest import DATASETS_DIR

UJI_HEADER = (
    "WAP001,WAP002,WAP003,LONGITUDE,LATITUDE,FLOOR,BUILDINGID,SPACEID,RELATIVEPOSITION,"
    "USERID,PHONEID,TIMESTAMP"
)


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


def test_generic_csv_reads_positions_labels_and_not_heard(tmp_path: Path) -> None:
    path = write(
        tmp_path / "a.csv",
        "x,y,floor,trajectory,t,ap1,ap2\n1.5,2,0,walk A,0.5,-60,100\n3,4,1,walk B,1.5,,-71.5\n",
    )
    fp = read_csv(path)
    assert fp.positions.tolist() == [[1.5, 2.0], [3.0, 4.0]]
    assert fp.access_points == ("ap1", "ap2")
    assert fp.floor.tolist() == [0, 1] and fp.building is None
    assert fp.trajectory.tolist() == ["walk A", "walk B"]
    assert fp.t.tolist() == [0.5, 1.5]
    # 100 and the empty cell are "not heard" (NaN), kept apart from any reading
    assert fp.heard.tolist() == [[True, False], [False, True]]
    assert fp.rssi_dbm[1, 1] == -71.5


def test_not_heard_value_is_configurable_and_a_file_object_works(tmp_path: Path) -> None:
    fp = read_csv(io.StringIO("x,y,ap\n0,0,-100\n1,1,-50\n"), not_heard=-100)
    assert fp.heard[:, 0].tolist() == [False, True]
    with open(write(tmp_path / "b.csv", "x,y,ap\n0,0,-100\n"), "rb") as fh:
        assert read_csv(fh).rssi_dbm[0, 0] == -100  # the default 100 leaves -100 a reading


def test_generic_csv_round_trip(tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    rssi = rng.uniform(-95, -30, (6, 3)).round(2)
    rssi[rng.uniform(size=rssi.shape) < 0.4] = np.nan
    original = Fingerprints(
        rng.uniform(0, 50, (6, 2)),
        rssi,
        ("aa:bb", "cc:dd", "ee"),
        floor=[0, 0, 1, 1, 2, 2],
        building=[3, 3, 3, 4, 4, 4],
        trajectory=["w1", "w1", "w2", "w2", "w3", "w3"],
        t=np.arange(6) * 5.0,
    )
    back = read_csv(original.to_csv(tmp_path / "round.csv"))
    np.testing.assert_allclose(back.positions, original.positions, rtol=1e-9)
    np.testing.assert_array_equal(back.heard, original.heard)
    np.testing.assert_allclose(back.rssi_dbm[back.heard], original.rssi_dbm[original.heard])
    assert back.access_points == original.access_points
    for key in ("floor", "building", "trajectory", "t"):
        np.testing.assert_array_equal(getattr(back, key), getattr(original, key))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "empty file"),
        ("x,y,ap1\n", "no data rows"),
        ("y,ap1\n1,-50\n", "no 'x' and 'y' columns"),
        ("x,y,floor\n1,2,0\n", "no access point columns"),
        ("x,y,ap1,ap1\n1,2,-50,-60\n", "repeated in the header: ['ap1']"),
        ("x,y,ap1\n1,2,-50\n3,4,strong\n", "line 3, column 'ap1': not a number: 'strong'"),
        ("x,y,ap1\n1,2,-50\n,4,-60\n", "line 3, column 'x': missing or not finite"),
        ("x,y,floor,ap1\n1,2,1.5,-50\n", "line 2, column 'floor': not an integer"),
    ],
)
def test_malformed_generic_csv_is_one_line_naming_file_and_place(
    tmp_path: Path, text: str, message: str
) -> None:
    path = write(tmp_path / "bad.csv", text)
    with pytest.raises(ConfigError) as err:
        read_csv(path)
    assert message in str(err.value) and str(path) in str(err.value)
    assert "\n" not in str(err.value)


def test_missing_file_is_a_config_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read"):
        read_csv(tmp_path / "none.csv")


def uji_rows() -> str:
    return (
        f"{UJI_HEADER}\n"
        "-70,100,100,-7600.5,4864900.25,2,1,110,2,11,13,1371713733\n"
        "100,-45,-99,-7610,4864910,0,2,101,1,2,23,1371713740\n"
    )


def test_ujiindoorloc_from_its_zip_a_folder_and_a_csv(tmp_path: Path) -> None:
    with zipfile.ZipFile(tmp_path / "UJIIndoorLoc.zip", "w") as archive:
        archive.writestr("UJIIndoorLoc/trainingData.csv", uji_rows())
        archive.writestr("UJIIndoorLoc/validationData.csv", uji_rows())
    from_zip = read_ujiindoorloc(tmp_path / "UJIIndoorLoc.zip")
    from_folder = read_ujiindoorloc(tmp_path, "validation")
    from_csv = read_ujiindoorloc(write(tmp_path / "validationData.csv", uji_rows()))
    for fp in (from_zip, from_folder, from_csv):
        assert fp.access_points == ("WAP001", "WAP002", "WAP003")
        assert fp.positions.tolist() == [[-7600.5, 4864900.25], [-7610.0, 4864910.0]]
        assert fp.floor.tolist() == [2, 0] and fp.building.tolist() == [1, 2]
        assert fp.heard.tolist() == [[True, False, False], [False, True, True]]
        assert fp.t.tolist() == [1371713733, 1371713740]


def test_ujiindoorloc_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="split must be one of"):
        read_ujiindoorloc(tmp_path, "test")
    with pytest.raises(ConfigError, match=r"not UJIIndoorLoc \(missing \['LONGITUDE'"):
        read_ujiindoorloc(write(tmp_path / "trainingData.csv", "WAP001,X\n1,2\n"))
    with zipfile.ZipFile(tmp_path / "other.zip", "w") as archive:
        archive.writestr("readme.txt", "hello")
    with pytest.raises(ConfigError, match=r"no trainingData\.csv inside"):
        read_ujiindoorloc(tmp_path / "other.zip")


def wifine_walk(path: Path, floor: int, t0: float, xs: list[float]) -> Path:
    lines = ["0,1,2,num_visible_APs,timestamp,x,y,z,floorID"]
    for k, x in enumerate(xs):
        lines.append(f"-100,{-50 - k},-100,1,{t0 + 5 * k},{x},2.5,1.4,{floor}")
    return write(path, "\n".join(lines) + "\n")


def test_wifine_walks_from_a_folder(tmp_path: Path) -> None:
    wifine_walk(tmp_path / "train_4_1.csv", 0, 0.0, [1.0, 2.0])
    wifine_walk(tmp_path / "train_5_2.csv", 1, 100.0, [5.0, 6.0, 7.0])
    fp = read_wifine(tmp_path)
    assert len(fp) == 5 and fp.access_points == ("0", "1", "2")
    assert fp.trajectory.tolist() == ["train_4_1"] * 2 + ["train_5_2"] * 3
    assert fp.floor.tolist() == [0, 0, 1, 1, 1]
    assert fp.heard[:, 1].all() and not fp.heard[:, [0, 2]].any()  # -100: not heard
    assert [label for label, _ in fp.walks()] == ["train_4_1", "train_5_2"]
    one = read_wifine(tmp_path / "train_4_1.csv")
    assert one.positions[:, 0].tolist() == [1.0, 2.0]


def test_wifine_errors(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="no WiFine CSV files"):
        read_wifine(tmp_path)
    with pytest.raises(ConfigError, match=r"not a WiFine walk \(missing \['floorID'"):
        read_wifine(write(tmp_path / "w.csv", "0,x,y,timestamp\n-100,1,2,0\n"))


def test_walks_are_in_time_order_and_split_where_the_floor_changes() -> None:
    fp = Fingerprints(
        np.arange(12.0).reshape(6, 2),
        np.full((6, 1), -60.0),
        ("ap",),
        floor=[1, 1, 0, 0, 2, 2],
        trajectory=["a", "b", "a", "a", "b", "b"],
        t=[30.0, 5.0, 10.0, 20.0, 1.0, 2.0],
    )
    walks = {label: rows.tolist() for label, rows in fp.walks()}
    # walk a: t 10, 20 on floor 0, then t 30 on floor 1; walk b: t 1, 2 on floor 2, t 5 on 1
    assert walks == {"a#0": [2, 3], "a#1": [0], "b#0": [4, 5], "b#1": [1]}
    with pytest.raises(ConfigError, match="no trajectory column"):
        next(Fingerprints(np.zeros((1, 2)), np.zeros((1, 1)), ("ap",)).walks())


def test_aligned_to_another_sets_access_points() -> None:
    fp = Fingerprints(np.zeros((1, 2)), [[-50.0, -60.0]], ("a", "b"))
    aligned = fp.aligned_to(("b", "c"))
    assert aligned.access_points == ("b", "c")
    assert aligned.rssi_dbm[0, 0] == -60.0 and np.isnan(aligned.rssi_dbm[0, 1])


@pytest.mark.slow
@pytest.mark.skipif(not (DATASETS_DIR / "ujiindoorloc").is_dir(), reason="../shared absent")
def test_the_real_ujiindoorloc_and_wifine_load() -> None:
    uji = read_ujiindoorloc(DATASETS_DIR / "ujiindoorloc" / "UJIIndoorLoc.zip")
    assert len(uji) == 19_937 and uji.n_access_points == 520
    assert set(uji.building.tolist()) == {0, 1, 2} and set(uji.floor.tolist()) == {0, 1, 2, 3, 4}
    val = read_wifine(DATASETS_DIR / "wifine" / "val")
    assert val.n_access_points == 436 and len(set(val.trajectory.tolist())) == 85


def test_wifine_map_yamls_name_each_layout_in_the_documented_frame(tmp_path: Path) -> None:
    import yaml

    maps = write_wifine_maps(Path("layouts"), tmp_path / "maps")
    assert sorted(maps) == sorted(WIFINE_FLOORS) == [0, 1, 2]
    spec = yaml.safe_load(maps[1].read_text())
    assert spec["image"] == str(Path("layouts").resolve() / "Floor_5_10cm.png")
    assert spec["resolution"] == 0.1 and spec["origin"] == [0.0, 0.0, 0.0]
    assert spec["negate"] == 0 and spec["free_thresh"] < spec["occupied_thresh"]

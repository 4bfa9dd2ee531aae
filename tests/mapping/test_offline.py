"""Offline mapping of an RSSI log: CSV parsing, mapping a synthetic two-room log, the CLI."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest

from sfw_gym.cli import main
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import SparseInverseKVisibility, belief_classes
from sfw_gym.mapping.offline import map_log, read_rssi_log, select_router_columns, write_map

# -- a synthetic two-room log (plain numpy) ------------------------------------------------------
W, H, WALL_X, DOOR_Y = 6.0, 4.0, 3.0, 3.0  # metres; the wall x = 3, 0 <= y <= 3, door above
WALL = (WALL_X, 0.0, WALL_X, DOOR_Y)
ROUTER_M = (1.0, 1.5)
PX = 0.05  # metres per pixel: the log is in pixels
K0_DBM = 20.0 - 40.2  # RSSI at 1 m without walls
WALL_DB = 15.0
RADIUS = 0.17


def crossings(points: np.ndarray, router, wall) -> np.ndarray:
    """1 where the segment point -> router properly crosses the wall segment, else 0."""

    def orient(ax, ay, bx, by, cx, cy):
        return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)

    px, py = points[:, 0], points[:, 1]
    (rx, ry), (x0, y0, x1, y1) = router, wall
    d1, d2 = orient(x0, y0, x1, y1, px, py), orient(x0, y0, x1, y1, rx, ry)
    d3, d4 = orient(px, py, rx, ry, x0, y0), orient(px, py, rx, ry, x1, y1)
    return ((d1 * d2 < 0) & (d3 * d4 < 0)).astype(np.int64)


def rssi_at(points: np.ndarray, rng, offset_db=0.0) -> np.ndarray:
    d = np.maximum(np.hypot(*(points - np.asarray(ROUTER_M)).T), 0.1)
    level = K0_DBM + offset_db - 20.0 * np.log10(d) - WALL_DB * crossings(points, ROUTER_M, WALL)
    return np.round(level + rng.normal(0.0, 2.0, len(points)))


def survey() -> np.ndarray:
    """Lawnmower through the left room, the door, then the right room (metres, 5 cm steps)."""
    c = RADIUS + 0.05
    ys = np.arange(c, H - c + 1e-9, 0.3)

    def mow(x0, x1, rows):
        return [p for i, y in enumerate(rows) for p in ([(x0, y), (x1, y)][:: 1 - 2 * (i % 2)])]

    left = mow(c, WALL_X - 0.05 - c, ys)
    door = [(WALL_X - 0.05 - c, 3.5), (WALL_X + 0.05 + c, 3.5)]
    right = mow(WALL_X + 0.05 + c, W - c, ys[::-1])
    out = []
    for a, b in itertools.pairwise([*left, *door, *right]):
        n = max(1, math.ceil(math.dist(a, b) / 0.05))
        out.append(np.asarray(a) + np.arange(n)[:, None] / n * (np.asarray(b) - np.asarray(a)))
    return np.concatenate(out)


@pytest.fixture(scope="module")
def two_room_log(tmp_path_factory):
    """The log as the SfW experiments write it: pixels, 2 bands, BOM, trailing commas, gaps."""
    rng = np.random.default_rng(0)
    traj = survey()
    r24, r5 = rssi_at(traj, rng), rssi_at(traj, rng, offset_db=-7.0)
    blank24 = rng.random(len(traj)) < 0.01  # "not heard" on 2.4 GHz
    no_pos = {17, 400, 901}  # rows whose position is missing
    lines = ["x_pixel,y_pixel,router1_2.4,router1_5,"]
    for i, ((x, y), a, b) in enumerate(zip(traj / PX, r24, r5, strict=True)):
        xs, ys = ("", "") if i in no_pos else (f"{x:.3f}", f" {y:.3f} ")
        if i == 400:
            xs = "nan"
        lines.append(f"{xs},{ys},{'' if blank24[i] else int(a)},{int(b)},")
        if i == 50:
            lines.append("")  # a blank line
    path = tmp_path_factory.mktemp("log") / "two_rooms.csv"
    path.write_bytes(b"\xef\xbb\xbf" + "\n".join(lines).encode() + b"\n")
    keep = np.array([i not in no_pos for i in range(len(traj))])
    r24 = np.where(blank24, -100.0, r24)
    return {"path": path, "traj": traj[keep], "r24": r24[keep], "r5": r5[keep], "n_skip": 3}


@pytest.fixture(scope="module")
def mapped(two_room_log):
    router_px = np.asarray(ROUTER_M) / PX
    return map_log(two_room_log["path"], [router_px], scale_m_per_unit=PX, resolution_m=0.05)


# -- mapping ---------------------------------------------------------------------------------------
def test_log_parsed_with_bom_trailing_comma_and_gaps(two_room_log, mapped):
    log = mapped.log
    assert log.position_names == ("x_pixel", "y_pixel")
    assert log.rssi_names == ("router1_2.4", "router1_5")
    assert log.n_skipped == two_room_log["n_skip"] == 3
    assert log.n_samples == len(two_room_log["traj"])
    np.testing.assert_allclose(log.positions * PX, two_room_log["traj"], atol=1e-4)
    np.testing.assert_array_equal(log.rssi_dbm[:, 0], two_room_log["r24"])
    np.testing.assert_array_equal(log.rssi_dbm[:, 1], two_room_log["r5"])
    assert mapped.columns == ("max(router1_2.4, router1_5)",)  # the authors' choice
    assert mapped.log.line_numbers[0] == 2


def test_map_equals_the_mapper_run_directly(mapped, two_room_log):
    """The default: the log forward, then reversed, through one mapper."""
    direct = SparseInverseKVisibility(mapped.grid, mapped.routers_m, mapped.mapper.config)
    strongest = np.maximum(two_room_log["r24"], two_room_log["r5"])
    samples = list(zip(mapped.log.positions * PX, strongest, strict=True))
    for p, r in [*samples, *samples[::-1]]:
        direct.update(p, np.array([r]))
    np.testing.assert_array_equal(mapped.mapper.occupancy_u8, direct.occupancy_u8)
    np.testing.assert_allclose(mapped.routers_m, [ROUTER_M])
    lo = np.vstack([two_room_log["traj"], [ROUTER_M]]).min(axis=0)
    np.testing.assert_allclose(mapped.grid.origin_xy, lo - 1.0, atol=1e-3)  # 1 m margin


def test_wall_found_and_visited_cells_free(mapped, two_room_log):
    grid, occ = mapped.grid, mapped.mapper.occupancy_u8
    free, wall, _ = belief_classes(occ)
    xs, ys = grid.cell_centres()
    near_wall = (np.abs(xs - WALL_X) <= 0.05 + 2 * grid.resolution_m) & (ys <= DOOR_Y + 0.1)
    assert wall[near_wall].sum() >= 0.6 * DOOR_Y / grid.resolution_m  # a wall, not a dot
    assert wall[near_wall].sum() >= 0.8 * wall.sum()  # and hardly any elsewhere
    rc = grid.world_to_cell(two_room_log["traj"])
    assert free[rc[:, 0], rc[:, 1]].mean() >= 0.95
    for room_x in (1.5, 4.5):  # both interiors largely free
        room = (np.abs(xs - room_x) < 1.0) & (ys > 0.5) & (ys < 2.5)
        assert free[room].mean() >= 0.7


def test_one_band_or_named_columns_on_request(two_room_log):
    router = [np.asarray(ROUTER_M) / PX]
    path = two_room_log["path"]
    res = map_log(path, router, scale_m_per_unit=PX, rssi_column="5", progress=True)
    assert res.columns == ("router1_5",)
    assert res.mapper.n_updates == 2 * len(two_room_log["traj"])  # two passes
    assert map_log(path, router, scale_m_per_unit=PX, rssi_column="router1_2.4").columns == (
        "router1_2.4",
    )
    with pytest.raises(ConfigError, match=r"--rssi-column 'rssi': no column \['rssi'\]; give"):
        map_log(path, router, scale_m_per_unit=PX, rssi_column="rssi")


def test_write_map_png_npy_json(mapped, tmp_path):
    paths = write_map(mapped, tmp_path / "out" / "map.png", y_down=True)
    assert paths["png"].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    occ = np.load(paths["npy"])
    assert occ.dtype == np.uint8 and occ.shape == mapped.grid.shape
    np.testing.assert_array_equal(occ, mapped.mapper.occupancy_u8)
    meta = json.loads(paths["json"].read_text())
    assert meta["shape"] == list(mapped.grid.shape)
    assert meta["rssi_columns"] == ["max(router1_2.4, router1_5)"]
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "map.json",
        "map.npy",
        "map.png",
    ]


# -- parsing edge cases ----------------------------------------------------------------------------
def write(tmp_path: Path, text: str, name="log.csv") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def test_parse_edge_cases(tmp_path):
    text = (
        "\ufeff x , y ,r1,r2,\n"
        "\n"
        "1, 2, -40 , -60,\n"
        '3,4,,"-70"\n'  # empty RSSI, no trailing comma, quoted cell
        ",5,-50,-50,\n"  # no x: skipped
        "NaN,6,-50,-50,\n"  # NaN x: skipped
        "7,8,NA,-100,\n"
        "   \n"
    )
    log = read_rssi_log(write(tmp_path, text))
    assert log.position_names == ("x", "y") and log.rssi_names == ("r1", "r2")
    np.testing.assert_array_equal(log.positions, [[1, 2], [3, 4], [7, 8]])
    np.testing.assert_array_equal(log.rssi_dbm, [[-40, -60], [-100, -70], [-100, -100]])
    assert log.skipped_lines == (5, 6)
    np.testing.assert_array_equal(log.line_numbers, [3, 4, 7])


def test_headerless_file(tmp_path):
    log = read_rssi_log(write(tmp_path, "0,0,-40\n1,0,-45\n"))
    assert log.rssi_names == ("column3",) and log.n_samples == 2


def test_column_selection(tmp_path):
    hdr = "x,y,router1_2.4,router1_5,router2_2.4,router2_5\n0,0,-1,-2,-3,-4\n"
    log = read_rssi_log(write(tmp_path, hdr))
    assert select_router_columns(log, 2) == [0, 2]
    assert select_router_columns(log, 2, "5") == [1, 3]
    assert select_router_columns(log, 4) == [0, 1, 2, 3]
    grouped = read_rssi_log(write(tmp_path, "x,y,a_2.4GHz,b_2.4GHz,a_5GHz,b_5GHz\n0,0,1,2,3,4\n"))
    assert select_router_columns(grouped, 2, "5") == [2, 3]
    untagged = read_rssi_log(write(tmp_path, "x,y,a,b,c,d\n0,0,1,2,3,4\n"))
    assert select_router_columns(untagged, 2, "5") == [1, 3]  # interleaved, as the SfW layout
    with pytest.raises(ConfigError, match=r"3 router positions given, but the file has 4 RSSI"):
        select_router_columns(log, 3)
    only5 = read_rssi_log(write(tmp_path, "x,y,r1_5,r2_5\n0,0,1,2\n"))
    with pytest.raises(ConfigError, match=r"--band 2\.4"):
        select_router_columns(only5, 2, "2.4")


@pytest.mark.parametrize(
    ("text", "problem"),
    [
        ("", r"log\.csv: empty file"),
        ("x,y,r1\n\n", r"log\.csv: no data rows"),
        ("x,y\n1,2\n", r"log\.csv:1: need at least 3 columns"),
        ("x,y,r1\n1,2,-40\n3,4,-4O\n", r"log\.csv:3: column 'r1': not a number: '-4O'"),
        ("x,y,r1\n1,2,-40\n3,4,-40,-50\n", r"log\.csv:3: expected 3 cells .* got 4"),
        ("x,y,r1\n1,2\n", r"log\.csv:2: expected 3 cells .* got 2"),
        ("x,y,r1\n1,inf,-40\n", r"log\.csv:2: column 'y': infinite"),
        ("x,y,r1\n,,-40\n", r"log\.csv: no row has a position"),
    ],
)
def test_bad_input_names_file_and_line(tmp_path, text, problem):
    with pytest.raises(ConfigError, match=problem):
        read_rssi_log(write(tmp_path, text))


def test_bad_files_and_arguments(tmp_path):
    with pytest.raises(ConfigError, match=r"nope\.csv: no such file"):
        read_rssi_log(tmp_path / "nope.csv")
    latin1 = tmp_path / "latin1.csv"
    latin1.write_bytes("x,y,r\xe9\n0,0,-40\n".encode("latin-1"))
    with pytest.raises(ConfigError, match=r"latin1\.csv: not UTF-8"):
        read_rssi_log(latin1)
    log = write(tmp_path, "x,y,r1\n0,0,-40\n600,400,-70\n")  # pixels, --scale forgotten
    with pytest.raises(ConfigError, match=r"12040 x 8040 cells .* is --scale"):
        map_log(log, [[10, 10]], resolution_m=0.05)
    with pytest.raises(ConfigError, match="scale_m_per_unit"):
        map_log(log, [[10, 10]], scale_m_per_unit=0.0)
    res = map_log(log, [[10, 10]], scale_m_per_unit=0.01)
    with pytest.raises(ConfigError, match=r"--out must be a \.png"):
        write_map(res, tmp_path / "map.jpg")


@pytest.fixture(scope="module")
def sfw_two_router_log(tmp_path_factory):
    """A log in the SfW paper's public 2-router layout, written here: a BOM, the header
    ``x_pixel,y_pixel,router1_2.4,router1_5,router2_2.4,router2_5,`` (trailing comma) and a 7th,
    unnamed value per row, the strongest of the four; positions in canvas pixels."""
    rng = np.random.default_rng(1)
    traj = survey()
    second = (5.0, 1.0)
    r1 = [rssi_at(traj, rng), rssi_at(traj, rng, offset_db=-7.0)]
    d2 = np.maximum(np.hypot(*(traj - np.asarray(second)).T), 0.1)
    r2 = [
        np.round(K0_DBM + off - 20 * np.log10(d2) + rng.normal(0, 2, len(traj))) for off in (0, -7)
    ]
    cells = np.column_stack([traj / SFW_PX_M, r1[0], r1[1], r2[0], r2[1]])
    strongest = cells[:, 2:].max(axis=1)
    lines = ["x_pixel,y_pixel,router1_2.4,router1_5,router2_2.4,router2_5,"]
    lines += [
        f"{x:.1f},{y:.1f},{a:.0f},{b:.0f},{c:.0f},{d:.0f},{m:.0f}"
        for (x, y, a, b, c, d), m in zip(cells, strongest, strict=True)
    ]
    path = tmp_path_factory.mktemp("sfw") / "sfw_2routers.csv"
    path.write_bytes(b"\xef\xbb\xbf" + "\r\n".join(lines).encode() + b"\r\n")
    routers_px = np.array([ROUTER_M, second]) / SFW_PX_M
    return {"path": path, "routers_px": routers_px, "strongest": strongest, "n": len(traj)}


SFW_PX_M = 0.0115  # metres per canvas pixel in the SfW buildings


def test_the_sfw_two_router_layout_reads_as_it_is(sfw_two_router_log):
    log = read_rssi_log(sfw_two_router_log["path"])
    assert log.rssi_names == ("router1_2.4", "router1_5", "router2_2.4", "router2_5")
    assert log.n_samples == sfw_two_router_log["n"]
    np.testing.assert_array_equal(log.strongest_dbm, sfw_two_router_log["strongest"])
    res = map_log(log, sfw_two_router_log["routers_px"], scale_m_per_unit=SFW_PX_M)
    # each router's strongest band; the strongest router's is the authors' 7th column
    assert res.columns == ("max(router1_2.4, router1_5)", "max(router2_2.4, router2_5)")
    per_router = np.column_stack([log.rssi_dbm[:, [0, 1]].max(1), log.rssi_dbm[:, [2, 3]].max(1)])
    np.testing.assert_array_equal(per_router.max(axis=1), log.strongest_dbm)


def test_cli_maps_the_sfw_two_router_layout(sfw_two_router_log, tmp_path, capsys):
    routers = ";".join(f"{x:.1f},{y:.1f}" for x, y in sfw_two_router_log["routers_px"])
    argv = ["map", str(sfw_two_router_log["path"]), "--routers", routers]
    argv += [
        "--px-per-m",
        str(1 / SFW_PX_M),
        "--rssi-column",
        "max",
        "--out",
        str(tmp_path / "m.png"),
    ]
    assert main(argv) == 0
    assert "max(router1_2.4, router1_5), max(router2_2.4, router2_5)" in capsys.readouterr().out
    assert main([*argv[:-4], "--out", str(tmp_path / "d.png")]) == 0  # max is the default
    np.testing.assert_array_equal(np.load(tmp_path / "m.npy"), np.load(tmp_path / "d.npy"))
    one = read_rssi_log(write(tmp_path, "x_pixel,y_pixel,rssi\n10,10,-40\n12,10,-41\n"))
    assert one.rssi_names == ("rssi",) and one.strongest_dbm is None


def test_an_unnamed_last_column_that_is_no_maximum_is_a_column(tmp_path):
    log = read_rssi_log(write(tmp_path, "x,y,r1,\n0,0,-40,-70\n1,0,-45,-20\n"))
    assert log.rssi_names == ("r1", "column4") and log.strongest_dbm is None
    np.testing.assert_array_equal(log.rssi_dbm, [[-40, -70], [-45, -20]])


def test_a_long_log_streams_in_chunks(tmp_path, monkeypatch):
    from sfw_gym.mapping import offline

    monkeypatch.setattr(offline, "_CHUNK_ROWS", 7)
    rows = "".join(f"{i},{i % 3},{-40 - i % 11}\n" for i in range(50))
    log = read_rssi_log(write(tmp_path, "x,y,r\n" + rows + ",,-40\n"))
    assert log.n_samples == 50 and log.skipped_lines == (52,)
    np.testing.assert_array_equal(log.positions[:, 0], np.arange(50))
    np.testing.assert_array_equal(log.line_numbers, np.arange(2, 52))
    np.testing.assert_array_equal(log.rssi_dbm[:, 0], -40 - np.arange(50) % 11)


# -- the CLI ---------------------------------------------------------------------------------------
def test_cli_map_end_to_end(two_room_log, tmp_path, capsys):
    router = f"{ROUTER_M[0] / PX},{ROUTER_M[1] / PX}"
    out = tmp_path / "m.png"
    argv = ["map", str(two_room_log["path"]), "--routers", router, "--scale", str(PX)]
    assert main([*argv, "--resolution", "0.1", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"{len(two_room_log['traj'])} samples, 3 rows skipped" in printed
    assert "µs per sample" in printed and "router1_2.4" in printed and str(out) in printed
    occ = np.load(out.with_suffix(".npy"))
    assert occ.dtype == np.uint8
    assert occ.shape == tuple(json.loads(out.with_suffix(".json").read_text())["shape"])
    pts = np.vstack([two_room_log["traj"], [ROUTER_M]])
    size = pts.max(axis=0) - pts.min(axis=0) + 2.0  # + 1 m margin on each side
    assert np.abs(np.array(occ.shape[::-1]) - size / 0.1).max() <= 1.0


def test_cli_map_errors_exit_2(two_room_log, tmp_path, capsys):
    log = str(two_room_log["path"])
    assert main(["map", log, "--routers", "2", "--out", str(tmp_path / "a.png")]) == 2
    assert "sfw-gym map: error: --routers" in capsys.readouterr().err
    assert main(["map", log, "--routers", "1,1;2,2;3,3", "--out", str(tmp_path / "b.png")]) == 2
    assert "3 router positions given, but the file has 2 RSSI columns" in capsys.readouterr().err
    assert main(["map", str(tmp_path / "missing.csv"), "--routers", "1,1"]) == 2
    assert "missing.csv: no such file" in capsys.readouterr().err
    assert not list(tmp_path.glob("*.png"))

"""Recorded logs (``sfw-gym record``): the SfW layouts, the truth beside them, their scores; the
two mapping methods and the two-pass option of ``map_log`` on them."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.cli import main
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation.logs import read_log_meta, record_log, score_map
from sfw_gym.mapping import GridSpec, SparseInverseKVisibility, belief_classes
from sfw_gym.mapping.offline import map_log, read_rssi_log, router_column_groups
from sfw_gym.mapping.reference import sfw_reference_map
from sfw_gym.world import generate_floorplan


@pytest.fixture(scope="module")
def plan():
    return generate_floorplan(2)


@pytest.fixture(scope="module")
def two_router_log(plan, tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "walk.csv"
    record_log(plan, path, routers=2, seed=4, missed_fraction=0.1)
    return path


def test_a_two_router_log_has_the_sfw_layout_and_its_truth(two_router_log):
    log = read_rssi_log(two_router_log)
    assert log.position_names == ("x_pixel", "y_pixel")
    assert log.rssi_names == ("router1_2.4", "router1_5", "router2_2.4", "router2_5")
    assert two_router_log.read_text().splitlines()[0].endswith("router2_5,")  # unnamed 7th
    assert log.strongest_dbm is not None
    np.testing.assert_array_equal(log.strongest_dbm, log.rssi_dbm.max(axis=1))
    missed = (log.rssi_dbm == -100).mean()
    assert 0.07 < missed < 0.2  # missed readings (10 %), and a few below the sensitivity
    meta = read_log_meta(two_router_log)
    assert meta["samples"] == log.n_samples > 500
    # every sample stands on a free cell of the truth, in the log's own (pixel, y-down) frame
    grid, truth = meta["truth_grid"], meta["truth_u8"]
    xy = log.positions * meta["pixel_m"]
    rc = np.floor((xy[:, ::-1] - np.asarray(grid.origin_xy)[::-1]) / grid.resolution_m)
    assert (truth[rc[:, 0].astype(int), rc[:, 1].astype(int)] == 255).all()


def test_each_routers_columns_are_its_own(two_router_log):
    """Per-router attribution: beside router r, router r's columns are the strong ones."""
    log = read_rssi_log(two_router_log)
    meta = read_log_meta(two_router_log)
    routers = np.asarray(meta["routers_px"])
    groups = router_column_groups(log, 2)
    assert groups == [[0, 1], [2, 3]]
    for r, cols in enumerate(groups):
        near = np.linalg.norm(log.positions - routers[r], axis=1) < 1.0 / meta["pixel_m"]
        other = groups[1 - r]
        assert near.sum() > 5
        assert np.median(log.rssi_dbm[near][:, cols].max(axis=1)) > np.median(
            log.rssi_dbm[near][:, other].max(axis=1)
        )


def test_a_one_router_log_has_one_rssi_column(plan, tmp_path):
    path = tmp_path / "one.csv"
    record_log(plan, path, routers=1, seed=1, trajectory="survey")
    assert path.read_text().splitlines()[0] == "x_pixel,y_pixel,rssi"
    log = read_rssi_log(path)
    assert log.rssi_names == ("rssi",) and log.strongest_dbm is None


def test_the_same_seed_records_the_same_log(plan, tmp_path):
    a, b = (record_log(plan, tmp_path / f"{n}.csv", seed=3)["csv"] for n in "ab")
    assert a.read_text() == b.read_text()
    c = record_log(plan, tmp_path / "c.csv", seed=5)["csv"]
    assert c.read_text() != a.read_text()


def test_score_map_reads_the_map_on_the_truths_grid():
    truth = np.full((4, 6), 255, np.uint8)
    truth[:, 3] = 0
    truth_grid = GridSpec((0.0, 0.0), 0.5, truth.shape)
    # the same map on a grid one cell larger on every side: a perfect score
    est = np.full((6, 8), 127, np.uint8)
    est[1:5, 1:7] = truth
    scores = score_map(est, GridSpec((-0.5, -0.5), 0.5, est.shape), truth, truth_grid)
    assert scores["free_iou"] == 1.0 and scores["wall_precision"] == 1.0
    # a map that covers only the truth's left half: the right half reads as unknown
    half = GridSpec((0.0, 0.0), 0.5, (4, 3))
    scores = score_map(truth[:, :3], half, truth, truth_grid)
    assert scores["free_iou"] == pytest.approx(12 / 20)


def test_the_reference_method_and_two_passes_through_map_log(two_router_log):
    meta = read_log_meta(two_router_log)
    kw = {"scale_m_per_unit": meta["pixel_m"]}
    ours = map_log(two_router_log, meta["routers_px"], passes=1, **kw)
    twice = map_log(two_router_log, meta["routers_px"], **kw)  # the default: two passes
    n = ours.log.n_samples
    assert ours.mapper.config.router_policy == "all"  # the offline default
    assert ours.mapper.n_updates == n and twice.mapper.n_updates == 2 * n
    assert len(twice.update_us) == 2 * n
    # two passes = the same mapper fed the log forward, then reversed
    groups = router_column_groups(ours.log, 2)
    rssi = np.column_stack([ours.log.rssi_dbm[:, g].max(axis=1) for g in groups])
    direct = SparseInverseKVisibility(ours.grid, ours.routers_m, ours.mapper.config)
    for i in [*range(n), *reversed(range(n))]:
        direct.update(ours.positions_m[i], rssi[i])
    np.testing.assert_array_equal(twice.occupancy_u8, direct.occupancy_u8)
    assert not np.array_equal(twice.occupancy_u8, ours.occupancy_u8)
    ref = map_log(two_router_log, meta["routers_px"], method="sfw-reference", **kw)
    assert ref.mapper is None
    np.testing.assert_array_equal(
        ref.occupancy_u8, sfw_reference_map(ours.grid, ours.routers_m, ours.positions_m, rssi)
    )
    with pytest.raises(ConfigError, match="method must be one of"):
        map_log(two_router_log, meta["routers_px"], method="sfw", **kw)
    with pytest.raises(ConfigError, match="passes must be 1 or 2"):
        map_log(two_router_log, meta["routers_px"], passes=3, **kw)


def test_record_then_map_and_score_from_the_command_line(tmp_path, capsys):
    log = tmp_path / "rec.csv"
    assert main(["record", str(log), "--seed", "2", "--routers", "1"]) == 0
    out = capsys.readouterr().out
    command = out.strip().splitlines()[-1].split("map and score it: sfw-gym ")[1]
    import shlex

    args = [*shlex.split(command), "--out", str(tmp_path / "m.png")]
    assert main(args) == 0
    scores = capsys.readouterr().out.strip().splitlines()[-1]
    assert scores.startswith("against the recorded truth: paper_iou")
    free = belief_classes(np.load(tmp_path / "m.npy"))[0]
    assert free.sum() > 100
    with pytest.raises(SystemExit):
        main(["map", str(log), "--routers", "1,1", "--method", "nope"])

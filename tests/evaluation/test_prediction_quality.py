"""Map prediction's data and judge (issue 46): snapshots collected on the native vector env,
resumed, loaded; the quality figures on cases computed by hand."""

from __future__ import annotations

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation.prediction import (
    SnapshotEpisode,
    collect_snapshots,
    load_snapshots,
    predict_snapshots,
    prediction_quality,
)
from sfw_gym.navigation.prediction import (
    FREE,
    OUTSIDE,
    UNKNOWN,
    WALL,
    NearestKnownPredictor,
    PredictedMap,
)


def test_snapshots_are_taken_at_the_steps_asked_and_resume(tmp_path):
    episodes = [
        SnapshotEpisode("frontier", 3, (5, 12)),
        SnapshotEpisode("random", 4, (7,)),
        SnapshotEpisode("frontier", 5, (2, 4, 6)),
    ]
    files = collect_snapshots(episodes, tmp_path, env_id="SfW-ExploreSmall-v0", num_envs=2)
    assert [f.name for f in files] == [
        "frontier_gen_3.npz",
        "random_gen_4.npz",
        "frontier_gen_5.npz",
    ]
    snaps = [load_snapshots(f) for f in files]
    assert [s.steps.tolist() for s in snaps] == [[5, 12], [7], [2, 4, 6]]
    first = snaps[0]
    assert first.codes.shape[1:] == first.truth.shape == first.proximity.shape
    assert first.agent == "frontier" and first.seed == 3
    assert set(np.unique(first.truth)) <= {FREE, WALL, OUTSIDE}
    # the belief grows: fewer unknown cells later
    unknown = ((first.codes & 3) == UNKNOWN).sum(axis=(1, 2))
    assert unknown[1] < unknown[0]
    # the same episode again gives the same snapshot (seeded), and a finished file is kept
    mtime = files[0].stat().st_mtime_ns
    again = collect_snapshots(episodes[:1], tmp_path, env_id="SfW-ExploreSmall-v0")
    assert again[0].stat().st_mtime_ns == mtime
    other = collect_snapshots(episodes[:1], tmp_path / "b", env_id="SfW-ExploreSmall-v0")
    np.testing.assert_array_equal(load_snapshots(other[0]).codes, first.codes)
    assert len(predict_snapshots(NearestKnownPredictor(), first)) == 2


def test_a_file_that_is_not_a_snapshot_is_named(tmp_path):
    bad = tmp_path / "x.npz"
    np.savez(bad, codes=np.zeros((1, 2, 2)))
    with pytest.raises(ConfigError, match=r"x\.npz"):
        load_snapshots(bad)


def test_quality_on_cases_computed_by_hand():
    codes = np.array([[FREE, UNKNOWN, UNKNOWN, UNKNOWN, UNKNOWN, UNKNOWN]], np.uint8)
    truth = np.array([[FREE, FREE, FREE, WALL, OUTSIDE, WALL]], np.uint8)
    zero = np.zeros((1, 6), np.float32)
    p_free = np.array([[1.0, 0.9, 0.2, 0.1, 0.1, 0.3]], np.float32)
    p_wall = np.array([[0.0, 0.05, 0.7, 0.8, 0.1, 0.6]], np.float32)
    # calls on the unknown cells: free, wall, wall, outside, wall
    q = prediction_quality([PredictedMap(p_free, p_wall, zero)], [codes], [truth])
    assert q["free_iou"] == pytest.approx(1 / 2)  # free calls {1}, truly free {1, 2}
    assert q["wall_f1"] == pytest.approx(2 * 2 / (3 + 2))  # walls called {2, 3, 5}, true {3, 5}
    # p_free ranks the free cells (0.9, 0.2) above the others (0.1, 0.1, 0.3) in 5 of 6 pairs
    assert q["free_auroc"] == pytest.approx(5 / 6)
    assert q["wall_auroc"] == pytest.approx(5 / 6)  # walls (0.8, 0.6) vs 0.05, 0.7, 0.1
    perfect = PredictedMap(
        (truth == FREE).astype(np.float32), (truth == WALL).astype(np.float32), zero
    )
    q = prediction_quality([perfect], [codes], [truth])
    assert q == pytest.approx(
        {"free_iou": 1.0, "wall_f1": 1.0, "free_auroc": 1.0, "wall_auroc": 1.0}
    )


def test_an_episode_s_curve_records_the_entropy_beside_coverage_and_path():
    from sfw_gym.evaluation.rollout import EpisodeRecord, EpisodeSpec

    def info(coverage, path, entropy):
        return {
            "coverage": coverage,
            "map_iou": 0.9,
            "path_length_m": path,
            "entropy_bits": entropy,
        }

    spec = EpisodeSpec(agent="frontier", episode=0, seed=0, curve_every=2)
    record = EpisodeRecord(spec, info(0.0, 0.0, 100.0), 0.0)
    record.step(info(0.1, 0.2, 95.0), False)
    record.step(info(0.2, 0.4, 90.0), False)
    record.step(info(0.3, 0.5, 88.0), True)
    assert record.curve == [
        (0, 0.0, 0.9, 0.0, 100.0),
        (2, 0.2, 0.9, 0.4, 90.0),
        (3, 0.3, 0.9, 0.5, 88.0),
    ]

"""The SfW authors' method (the baseline of every mapping table), on cases computed by hand."""

import numpy as np
import pytest

from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import GridSpec
from sfw_gym.mapping.reference import sfw_reference_map

CORRIDOR = GridSpec((0.0, 0.0), 1.0, (3, 10))  # a 1 m-cell corridor, the router in cell (1, 0)


def test_a_corridor_walked_out_and_back_by_hand():
    # three samples along the corridor's middle row: k = 0, 0 (-30, -35 dBm > -41) and 1 (-50)
    pos = [[3.5, 1.5], [5.5, 1.5], [7.5, 1.5]]
    out = sfw_reference_map(CORRIDOR, [[0.5, 1.5]], pos, [[-30.0], [-35.0], [-50.0]])
    # forward: +15 on cols 0-3, robot cell 255; +15 on cols 0-5, rule 4 frees cols 3-5 (+15)
    # again; -15 on cols 0-7 (k = 1). Reversed: -15 on 0-7; +15 on 0-5 (no k-1 partner);
    # +15 on 0-3 and rule 4 (+15) on 3-5. Robot cells are 255 after each visit.
    expected = [157, 157, 157, 255, 157, 255, 97, 255, 127, 127]
    assert out[1].tolist() == expected
    assert (out[[0, 2]] == 127).all()  # off the rays: untouched


def test_each_sample_goes_to_its_strongest_router_only():
    routers = [[0.5, 1.5], [9.5, 1.5]]
    # at col 3 the first router is the stronger (k = 0 on its ray), the second is ignored
    out = sfw_reference_map(CORRIDOR, routers, [[3.5, 1.5]], [[-30.0, -70.0]])
    assert out[1].tolist() == [157, 157, 157, 255, 127, 127, 127, 127, 127, 127]
    # the same sample, the second router the stronger: its ray (cols 3-9), k = 2 below -56 dBm
    out = sfw_reference_map(CORRIDOR, routers, [[3.5, 1.5]], [[-90.0, -60.0]])
    assert out[1].tolist() == [127, 127, 127, 255, 97, 97, 97, 97, 97, 97]
    # nobody heard: only nothing changes (not even the robot's cell)
    out = sfw_reference_map(CORRIDOR, routers, [[3.5, 1.5]], [[-100.0, -100.0]])
    assert (out == 127).all()


def test_bad_input_is_refused_with_the_problem_named():
    with pytest.raises(ConfigError, match=r"a position at \[30\.0, 1\.5\] lies outside the map"):
        sfw_reference_map(CORRIDOR, [[0.5, 1.5]], [[3.5, 1.5], [30.0, 1.5]], [[-30.0], [-30.0]])
    with pytest.raises(ConfigError, match=r"a router at \[0\.5, -1\.0\] lies outside the map"):
        sfw_reference_map(CORRIDOR, [[0.5, 1.5], [0.5, -1.0]], [[3.5, 1.5]], [[-30.0, -40.0]])
    with pytest.raises(ConfigError, match=r"descending, got \(-60\.0, -50\.0\)"):
        sfw_reference_map(
            CORRIDOR, [[0.5, 1.5]], [[3.5, 1.5]], [[-30.0]], thresholds_dbm=(-60.0, -50.0)
        )
    with pytest.raises(ConfigError, match=r"rssi_dbm \(N, R=1\)"):
        sfw_reference_map(CORRIDOR, [[0.5, 1.5]], [[3.5, 1.5]], [[-30.0, -40.0]])
    with pytest.raises(ConfigError, match="finite"):
        sfw_reference_map(CORRIDOR, [[0.5, 1.5]], [[3.5, 1.5]], [[np.nan]])


def test_a_reading_at_the_second_threshold_is_k_2_like_one_below_it():
    """k = 1 only above -56 dBm (rule 2): at -56 dBm a sample pairs with a k = 2 sample on its
    ray (rule 4) exactly as at -57 dBm, and not as at -55 dBm (k = 1)."""
    pos = [[3.5, 1.5], [7.5, 1.5]]

    def mapped(first_dbm: float) -> np.ndarray:
        return sfw_reference_map(CORRIDOR, [[0.5, 1.5]], pos, [[first_dbm], [-70.0]])

    assert np.array_equal(mapped(-56.0), mapped(-57.0))
    assert not np.array_equal(mapped(-56.0), mapped(-55.0))


def test_the_line_rule_walks_bresenham_s_cells_from_end_to_end():
    """One cell per step along the longer axis, both ends included, each within half a cell
    of the ideal segment across it (what makes a Bresenham line)."""
    from sfw_gym.mapping.reference import _add_line

    rng = np.random.default_rng(0)
    for _ in range(200):
        r0, c0, r1, c1 = (int(v) for v in rng.integers(0, 20, 4))
        img = np.zeros((20, 20), np.int64)
        _add_line(img, r0, c0, r1, c1, 1)
        cells = np.argwhere(img)
        assert len(cells) == max(abs(r1 - r0), abs(c1 - c0)) + 1
        assert img[r0, c0] == img[r1, c1] == 1
        if abs(c1 - c0) >= abs(r1 - r0) and c1 != c0:  # x is the longer axis
            ideal = r0 + (cells[:, 1] - c0) * (r1 - r0) / (c1 - c0)
            assert np.all(np.abs(cells[:, 0] - ideal) <= 0.5)
        elif r1 != r0:
            ideal = c0 + (cells[:, 0] - r0) * (c1 - c0) / (r1 - r0)
            assert np.all(np.abs(cells[:, 1] - ideal) <= 0.5)

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
    with pytest.raises(ConfigError, match="outside the map's grid"):
        sfw_reference_map(CORRIDOR, [[0.5, 1.5]], [[30.0, 1.5]], [[-30.0]])
    with pytest.raises(ConfigError, match=r"rssi_dbm \(N, R=1\)"):
        sfw_reference_map(CORRIDOR, [[0.5, 1.5]], [[3.5, 1.5]], [[-30.0, -40.0]])
    with pytest.raises(ConfigError, match="finite"):
        sfw_reference_map(CORRIDOR, [[0.5, 1.5]], [[3.5, 1.5]], [[np.nan]])

"""``sfw-gym slam``: Radio SLAM on a recorded log, and one-line errors for a bad one."""

from __future__ import annotations

import re

import numpy as np
import pytest

from sfw_gym.cli import main
from sfw_gym.slam.offline import read_slam_log, write_slam_log


def test_a_recorded_drifting_run_is_corrected_and_its_outputs_written(tmp_path, capsys):
    log = tmp_path / "run.csv"
    assert main(["slam", str(log), "--record", "2000005", "--steps", "1500"]) == 0
    out = capsys.readouterr().out
    odometry, slam = map(
        float, re.search(r"odometry ([\d.]+) m, Radio SLAM ([\d.]+) m", out).groups()
    )
    assert slam < 0.8 * odometry
    folder = tmp_path / "run_slam"
    trajectory = np.loadtxt(folder / "trajectory.csv", delimiter=",", skiprows=1)
    assert trajectory.shape == (1501, 4)
    with np.load(folder / "fingerprint_map.npz") as fmap:
        assert fmap["positions"].shape == (1501, 2) and fmap["fingerprints_dbm"].shape == (1501, 16)
        np.testing.assert_allclose(fmap["positions"], trajectory[:, 1:3], atol=1e-5)
    assert (folder / "slam.png").stat().st_size > 10_000
    # the odometry weights given on the command line are the ones used
    loose = tmp_path / "loose"
    assert (
        main(
            [
                "slam",
                str(log),
                "--odometry-sigma",
                "0.2",
                "--heading-sigma",
                "0.2",
                "--out",
                str(loose),
            ]
        )
        == 0
    )
    assert not np.array_equal(
        np.loadtxt(loose / "trajectory.csv", delimiter=",", skiprows=1), trajectory
    )
    recorded = read_slam_log(log)
    assert np.isnan(recorded.fingerprints).any()  # not heard stays not heard
    assert recorded.truth is not None and recorded.odometry.shape == (1501, 3)


def test_a_log_round_trips_through_its_writer(tmp_path):
    rng = np.random.default_rng(0)
    prints = rng.uniform(-90, -30, (5, 3))
    prints[1, 2] = np.nan
    path = write_slam_log(tmp_path / "x.csv", np.arange(5.0), rng.normal(size=(5, 3)), prints)
    log = read_slam_log(path)
    assert log.access_points == ("ap0", "ap1", "ap2") and log.truth is None
    np.testing.assert_allclose(log.fingerprints, prints, rtol=1e-5)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("time,x,y\n1,2,3\n", r"columns \['odom_x', 'odom_y', 'odom_theta'\] missing"),
        ("time,odom_x,odom_y,odom_theta\n0,0,0,0\n1,1,0,0\n", "no access-point columns"),
        ("time,odom_x,odom_y,odom_theta,a\n0,0,0,0,-50\n1,1,0\n", r"bad\.csv:3: 3 values"),
        (
            "time,odom_x,odom_y,odom_theta,a\n0,0,0,0,-50\n1,x,0,0,-50\n",
            r"bad\.csv:3: odom_x is not",
        ),
        ("time,odom_x,odom_y,odom_theta,a\n0,0,0,0,-50\n1,nan,0,0,-50\n", r"bad\.csv:3: time, odo"),
        ("time,odom_x,odom_y,odom_theta,a\n0,0,0,0,-50\n", "1 data rows"),
        ("", "empty log"),
    ],
)
def test_a_bad_log_is_one_line_naming_the_file_and_line(tmp_path, capsys, text, message):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    assert main(["slam", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and re.search(message, err), err

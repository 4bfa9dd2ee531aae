"""``sfw-gym fingerprints evaluate`` and ``convert`` end to end on small CSVs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from sfw_gym.cli import main
from sfw_gym.cli.fingerprints import parse_floorplan_option
from sfw_gym.datasets import Fingerprints, read_csv
from sfw_gym.evaluation.fingerprints import majority_key
from sfw_gym.world.floorplan import floorplan_from_polygon
from tests.conftest import two_rooms_polygon
from tests.localization.test_fingerprinting import AP_NAMES, radio, survey


@pytest.fixture(scope="module")
def files(tmp_path_factory) -> dict[str, Path]:
    """A survey (two buildings, two floors) and two test walks with trajectories and times."""
    root = tmp_path_factory.mktemp("fp")
    survey(noise_db=3.0).to_csv(root / "train.csv")
    rng = np.random.default_rng(5)
    xy = np.column_stack([np.arange(2.0, 18.0, 0.8), np.full(20, 3.0)])
    walks = [(xy, 0, "w1"), (xy[::-1] + np.array([0.0, 5.0]), 1, "w2")]
    test = Fingerprints(
        np.concatenate([w[0] for w in walks]),
        np.concatenate([radio(w[0], w[1], 0, 3.0, rng) for w in walks]),
        AP_NAMES,
        floor=np.repeat([0, 1], 20),
        building=np.zeros(40, int),
        trajectory=np.repeat(["w1", "w2"], 20),
        t=np.tile(np.arange(20) * 5.0, 2)[::-1],  # rows given in reverse time order
    )
    test.to_csv(root / "test.csv")
    return {"train": root / "train.csv", "test": root / "test.csv", "root": root}


def test_evaluate_writes_metrics_and_predictions(files, capsys) -> None:
    out = files["root"] / "out"
    argv = ["fingerprints", "evaluate", "--train", str(files["train"]), "--test"]
    assert main([*argv, str(files["test"]), "--out", str(out), "--method", "w3nn"]) == 0
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["method"] == "w3nn" and metrics["n_test"] == 40
    for key in ("mean_error_m", "median_error_m", "p75_error_m", "p95_error_m", "fit_s"):
        assert metrics[key] >= 0
    assert metrics["floor_hit_rate"] == 1.0 and metrics["building_hit_rate"] == 1.0
    assert metrics["query_ms_per_scan"] > 0
    rows = pd.read_csv(out / "predictions.csv")
    assert len(rows) == 40 and {"x", "y", "x_true", "error_m", "floor", "trajectory"} <= set(rows)
    assert rows["error_m"].mean() == pytest.approx(metrics["mean_error_m"], abs=1e-3)
    assert "w3nn: 40 scans, mean error" in capsys.readouterr().out


def _track(files, out: Path) -> pd.DataFrame:
    argv = ["fingerprints", "evaluate", "--train", str(files["train"]), "--test"]
    argv += [str(files["test"]), "--track", "--particles", "500", "--out", str(out)]
    assert main(argv) == 0
    return pd.read_csv(out / "predictions.csv")


def test_track_orders_each_walk_by_time_and_reports_per_scan_beside(files) -> None:
    out = files["root"] / "tracked"
    rows = _track(files, out)
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["tracked_walks"] == 2 and metrics["sensor_model"] == "kernel"
    assert metrics["odometry"].startswith("synthetic")
    assert metrics["per_scan_mean_error_m"] > 0 and not metrics["with_floorplan"]
    assert {"per_scan_x", "per_scan_error_m"} <= set(rows)
    # the tracked walk is better than its scans alone once it has settled
    late = rows.groupby("trajectory").apply(lambda g: g.sort_values("t").iloc[5:])
    assert late["error_m"].mean() < late["per_scan_error_m"].mean()


@pytest.mark.slow
def test_tracking_is_seeded_the_same_figures_again(files) -> None:
    first, again = _track(files, files["root"] / "first"), _track(files, files["root"] / "again")
    pd.testing.assert_frame_equal(first, again)


def test_track_with_a_floorplan(files, tmp_path: Path) -> None:
    plan = floorplan_from_polygon(two_rooms_polygon())
    plan_path = plan.save(tmp_path / "plan.json")
    argv = ["fingerprints", "evaluate", "--train", str(files["train"]), "--test"]
    argv += [str(files["test"]), "--out", str(tmp_path / "o"), "--track", "--particles", "300"]
    assert main([*argv, "--floorplan", f"0={plan_path}", "--wall-weight", "0.1"]) == 0
    metrics = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert metrics["with_floorplan"] and metrics["wall_weight"] == 0.1


def test_floorplan_option_takes_a_path_or_floor_and_path() -> None:
    assert parse_floorplan_option("plans/f.yaml") == (None, "plans/f.yaml")
    assert parse_floorplan_option("2=f.yaml") == (2, "f.yaml")
    assert parse_floorplan_option("c:=x") == (None, "c:=x")


def test_evaluate_bad_options_are_one_line(files, tmp_path, capsys) -> None:
    argv = ["fingerprints", "evaluate", "--train", str(files["train"]), "--test"]
    argv += [str(files["test"]), "--out", str(tmp_path / "o")]
    with pytest.raises(SystemExit) as exc:
        main([*argv, "--method", "svm"])
    assert exc.value.code == 2 and "invalid choice: 'svm'" in capsys.readouterr().err
    assert main([*argv, "--floorplan", "plan.json"]) == 2
    assert "--floorplan: only used with --track" in capsys.readouterr().err


def test_a_malformed_csv_names_the_file_and_line(files, tmp_path, capsys) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("x,y,ap0\n1,2,-50\n3,4,loud\n")
    argv = ["fingerprints", "evaluate", "--train", str(bad), "--test", str(files["test"])]
    assert main([*argv, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("line 3, column 'ap0': not a number: 'loud'") and str(bad) in err
    assert len(err.splitlines()) == 1


def test_convert_writes_the_generic_csv(tmp_path, capsys) -> None:
    walk = tmp_path / "train_4_1.csv"
    walk.write_text("0,1,num_visible_APs,timestamp,x,y,z,floorID\n-100,-61,1,0,1.5,2,1.4,0\n")
    out = tmp_path / "walk.csv"
    assert main(["fingerprints", "convert", "--format", "wifine", str(walk), str(out)]) == 0
    back = read_csv(out)
    assert back.trajectory.tolist() == ["train_4_1"] and back.rssi_dbm[0, 1] == -61
    assert np.isnan(back.rssi_dbm[0, 0])
    assert "1 scans, 2 access points" in capsys.readouterr().out


def test_a_walk_is_tracked_on_the_floor_most_of_its_scans_were_placed_on() -> None:
    assert majority_key([1, 1, 1, 1], [0, 2, 2, 1]) == 1002
    assert majority_key([0, 2, 2], [3, 3, 3]) == 2003

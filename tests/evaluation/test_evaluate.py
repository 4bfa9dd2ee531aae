"""The evaluate runner: same seeds for every agent, resumable checkpoint, atomic outputs, stats."""

from __future__ import annotations

import csv
import json
import math

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401
from sfw_gym import evaluation as ev
from sfw_gym.agents import Agent
from sfw_gym.cli import main
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation import runner

SMALL = "SfW-ExploreSmall-v0"
#: Short episodes keep the suite fast.
TINY = {"env_id": SMALL, "env_kwargs": {"max_steps": 40}, "workers": 1, "progress": False}


def test_tiny_run_writes_table_curves_and_trajectories(tmp_path):
    result = ev.evaluate(["frontier", "random"], 2, seed=5, out=tmp_path, **TINY)
    recs = result["records"]
    assert len(recs) == 4
    # Same floorplan and seed for every agent in an episode.
    for i in range(2):
        pair = [r for r in recs if r["episode"] == i]
        assert {r["seed"] for r in pair} == {5 + i}
        assert len({r["floorplan"] for r in pair}) == 1
    for name in (
        "results.csv",
        "results.md",
        "coverage_vs_steps.png",
        "iou_vs_path.png",
        "episodes.jsonl",
        "config.json",
    ):
        assert (tmp_path / name).stat().st_size > 0, name
    assert len(list((tmp_path / "trajectories").glob("*.png"))) == 2
    assert len(list((tmp_path / "episodes").glob("*.npz"))) == 4
    assert not list(tmp_path.rglob("*.tmp")), "temp files left behind"
    rows = list(csv.DictReader((tmp_path / "results.csv").open()))
    assert [r["agent"] for r in rows] == ["frontier", "random"]
    assert float(rows[0]["coverage_mean"]) > 0
    md = (tmp_path / "results.md").read_text()
    assert "| frontier | 2 |" in md and "±" in md
    paired = (tmp_path / "paired.md").read_text()
    assert "| random − frontier | coverage | 2 |" in paired
    ev.evaluate(["frontier"], 2, seed=5, out=tmp_path, **TINY)  # one agent: nothing to pair
    assert not (tmp_path / "paired.md").exists()
    rec = recs[0]
    for key in (
        "coverage",
        "map_iou",
        "k_accuracy",
        "path_length_m",
        "collisions",
        "steps_to_coverage_50",
        "steps_to_coverage_90",
        "zone_band_unknown",
        "stop_reason",
        "curve",
    ):
        assert key in rec, key
    assert rec["steps"] == 40 and rec["stop_reason"] in (
        "max_steps",
        "no_frontiers",
        "all_blacklisted",
    )
    assert rec["terminated"] is False  # 40 steps do not reach the coverage target
    # the map's entropy fell by the bits gained; per metre driven, what the reward pays for
    assert rec["info_gain_total_bits"] > 0
    gain = rec["info_gain_total_bits"] / rec["path_length_m"]
    assert rec["info_gain_per_m"] == pytest.approx(gain)


def test_menu_choosing_agents_report_through_one_decision_log(tmp_path):
    kwargs = {**TINY, "env_kwargs": {"max_steps": 150}}
    result = ev.evaluate(["frontier", "greedy", "random"], 1, seed=5, out=tmp_path, **kwargs)
    by_agent = {r["agent"]: r for r in result["records"]}
    computed = {"frontier": "heading_change_rad", "greedy": "expected_gain_bits"}
    for name, feature in computed.items():
        log = np.load(tmp_path / "episodes" / f"{name}_0000.npz")
        steps, names = log["decision_step"], list(log["decision_feature_names"])
        assert by_agent[name]["decisions"] == len(steps) > 0, name
        assert np.all(np.diff(steps) > 0) and steps[-1] < 150
        features = log["decision_features"]
        assert features.shape == (len(steps), len(names))
        assert np.isfinite(features[:, names.index("path_cost_m")]).all()
        assert np.isfinite(features[:, names.index(feature)]).all()
        rc, shape = log["decision_target_rc"], log["belief"].shape
        assert ((rc >= 0) & (rc < shape)).all()
    assert by_agent["random"]["decisions"] == 0


class StraightAgent(Agent):
    """An agent of one's own, named by its entry point (not registered)."""

    name = "straight"

    def _act(self, view, obs):
        return 1.0, 0.0


@pytest.mark.episode
def test_an_agent_of_ones_own_runs_in_the_workers_by_its_entry_point(tmp_path):
    entry = f"{__name__}:StraightAgent"
    result = ev.evaluate(["random", entry], 2, seed=5, out=tmp_path, **{**TINY, "workers": 2})
    assert sorted({r["agent"] for r in result["records"]}) == sorted(["random", entry])
    for odd in (":", "x:", ":Agent", ".rel:Agent"):  # one clean line each
        with pytest.raises(ConfigError, match="agent"):
            ev.evaluate([odd], 1, out=tmp_path / "z", **TINY)
    with pytest.raises(ConfigError, match="has no 'Nope'"):
        ev.evaluate([f"{__name__}:Nope"], 1, out=tmp_path / "x", **TINY)
    with pytest.raises(ConfigError, match="is not an sfw_gym Agent subclass"):
        ev.evaluate([f"{__name__}:TINY"], 1, out=tmp_path / "y", **TINY)


def test_interrupted_run_resumes_without_redoing_episodes(tmp_path, monkeypatch):
    real = ev.run_episode
    calls: list[str] = []

    def flaky(spec):
        if len(calls) == 2:
            raise KeyboardInterrupt  # the user hits Ctrl-C during the third episode
        calls.append(spec.key)
        return real(spec)

    monkeypatch.setattr(runner, "run_episode", flaky)
    with pytest.raises(KeyboardInterrupt):
        ev.evaluate(["frontier", "random"], 2, seed=0, out=tmp_path, **TINY)
    done = ev.load_checkpoint(tmp_path / ev.CHECKPOINT)
    assert [r["key"] for r in done] == calls
    # A torn last line (a kill mid-append) is ignored, and the appends after it stay readable.
    with (tmp_path / ev.CHECKPOINT).open("a") as fh:
        fh.write('{"key": "trunc')
    rerun: list[str] = []

    def counting(spec):
        rerun.append(spec.key)
        return real(spec)

    monkeypatch.setattr(runner, "run_episode", counting)
    result = ev.evaluate(["frontier", "random"], 2, seed=0, out=tmp_path, **TINY)
    assert len(rerun) == 2 and not set(rerun) & set(calls)
    assert len(result["records"]) == 4
    lines = (tmp_path / ev.CHECKPOINT).read_text().splitlines()
    assert sorted(json.loads(line)["key"] for line in lines) == sorted(
        r["key"] for r in result["records"]
    )
    # Asking for more episodes later runs only the new ones.
    rerun.clear()
    ev.evaluate(["frontier", "random"], 3, seed=0, out=tmp_path, **TINY)
    assert len(rerun) == 2 and all("|2|" in k for k in rerun)


@pytest.mark.episode
def test_parallel_workers_match_the_serial_run(tmp_path):
    serial = ev.evaluate(["random"], 2, seed=1, out=tmp_path / "a", **TINY)
    parallel = ev.evaluate(["random"], 2, seed=1, out=tmp_path / "b", **{**TINY, "workers": 2})
    key = lambda r: r["episode"]  # noqa: E731
    for a, b in zip(
        sorted(serial["records"], key=key), sorted(parallel["records"], key=key), strict=True
    ):
        assert a["coverage"] == b["coverage"] and a["curve"] == b["curve"]


def test_floorplan_folder_cycles_and_gif(tmp_path):
    from sfw_gym.world.generator import generate_floorplan

    plans = tmp_path / "plans"
    for s in (1, 2):
        generate_floorplan(s, area_m2=45.0).save(plans / f"plan{s}.json")
    result = ev.evaluate(
        ["random"], 3, seed=0, out=tmp_path / "out", floorplans=plans, gif_episodes=1, **TINY
    )
    files = [r["floorplan_file"] for r in sorted(result["records"], key=lambda r: r["episode"])]
    assert [f.rsplit("/", 1)[-1] for f in files] == ["plan1.json", "plan2.json", "plan1.json"]
    gif = tmp_path / "out" / "gifs" / "random_0000.gif"
    assert gif.stat().st_size > 0
    from PIL import Image

    with Image.open(gif) as frames:
        assert frames.n_frames > 1
        assert frames.info["loop"] == 0  # played over and over, not once
    assert [p.name for p in gif.parent.iterdir()] == ["random_0000.gif"]  # gif_episodes=1


def test_bad_arguments_are_clear_errors(tmp_path):
    with pytest.raises(ConfigError, match="unknown agent"):
        ev.evaluate(["frontier", "nope"], 1, out=tmp_path, **TINY)
    with pytest.raises(ConfigError, match="episodes"):
        ev.evaluate(["frontier"], 0, out=tmp_path, **TINY)
    with pytest.raises(ConfigError, match=r"no floorplan files there"):
        ev.evaluate(["frontier"], 1, out=tmp_path, floorplans=tmp_path, **TINY)
    with pytest.raises(ConfigError, match="potential_scale"):
        ev.evaluate(
            ["frontier"],
            1,
            out=tmp_path,
            agent_params={"frontier": {"potential_scale": -1}},
            **TINY,
        )


def test_cli_evaluate(tmp_path, capsys):
    args = ["evaluate", "--agents", "random,frontier", "--episodes", "1", "--env", SMALL]
    args += ["--out", str(tmp_path), "--no-progress", "--env-kwargs", '{"max_steps": 20}']
    assert main([*args, "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    assert "| random | 1 |" in printed
    assert "paired on the same plans and seeds:\n| agent − reference" in printed
    assert "| frontier − random | coverage | 1 |" in printed
    assert main(["evaluate", "--agents", "bogus", "--out", str(tmp_path)]) == 2
    assert "unknown agent" in capsys.readouterr().err
    assert (
        main(["evaluate", "--agents", "random", "--env-kwargs", "[1]", "--out", str(tmp_path)]) == 2
    )


def test_mean_ci95_and_summary():
    mean, half, n = ev.mean_ci95([1.0, 2.0, 3.0, 4.0])
    assert (mean, n) == (2.5, 4)
    assert half == pytest.approx(3.182446 * np.std([1, 2, 3, 4], ddof=1) / 2, rel=1e-5)
    assert math.isnan(ev.mean_ci95([7.0])[1]) and ev.mean_ci95([])[2] == 0
    # the same interval column by column (the curves' bands)
    from sfw_gym.evaluation.stats import ci95_half_width

    cols = ci95_half_width(np.array([[1.0, 10.0], [2.0, 10.0], [3.0, 10.0], [4.0, 10.0]]))
    np.testing.assert_allclose(cols, [half, 0.0])
    recs = [
        {"agent": "a", "coverage": 0.95, "steps_to_coverage_90": 100, "stop_reason": "x"},
        {"agent": "a", "coverage": 0.5, "steps_to_coverage_90": -1, "stop_reason": "y"},
    ]
    row = ev.summarize(recs, ["a"])[0]
    assert row["steps_to_coverage_90_mean"] == 100 and row["steps_to_coverage_90_n"] == 1
    assert row["episodes_coverage_ge_90"] == 1 and row["stop_reasons"] == "x:1;y:1"
    assert "(1/2)" in ev.results_markdown([row])


def test_paired_differences_pair_episodes_not_agents_means():
    recs = [
        {"agent": "f", "episode": 0, "coverage": 0.5, "info_gain_per_m": 20.0},
        {"agent": "f", "episode": 1, "coverage": 0.9, "info_gain_per_m": 30.0},
        {"agent": "g", "episode": 1, "coverage": 0.8, "info_gain_per_m": 33.0},
        {"agent": "g", "episode": 0, "coverage": 0.6, "info_gain_per_m": None},
        {"agent": "g", "episode": 2, "coverage": 1.0, "info_gain_per_m": 99.0},  # unpaired
    ]
    (row,) = ev.paired_differences(recs, ["f", "g"], reference="f")
    assert (row["agent"], row["reference"], row["pairs"]) == ("g", "f", 2)
    by_metric = {d.metric: d for d in row["differences"]}
    cov, gain = by_metric["coverage"], by_metric["info_gain_per_m"]
    # differences +0.1 and -0.1 (agent − reference, episode by episode)
    assert (cov.n, cov.mean_a, cov.mean_b) == (2, pytest.approx(0.7), pytest.approx(0.7))
    assert cov.mean == pytest.approx(0.0)
    assert cov.low == pytest.approx(-0.1) and cov.high == pytest.approx(0.1)  # the bootstrap's
    assert (gain.n, gain.mean) == (1, pytest.approx(3.0))  # the pair with a None is left out
    table = ev.paired_markdown([row])
    assert "| g − f | coverage | 2 | 0.700 | 0.700 | +0.000 [-0.100, +0.100] |  |" in table
    assert "| g − f | info gain [bits/m] | 1 | 30.0 | 33.0 | +3.0 |  |" in table  # no interval


def test_the_paired_comparison_is_a_seeded_bootstrap_of_the_mean_difference():
    """The interval derived without scipy's bootstrap: on 400 pairs the percentile bootstrap of
    the mean difference agrees with the t interval computed by hand (mean ± t · s / √n, the
    bootstrap's resampling error and its √((n−1)/n) narrowing well inside 15 % of s / √n); it
    is paired (the sides' own spread, 100 times the differences', does not widen it); all-equal
    differences give the zero-width interval at their value; and on a sample whose bootstrap
    distribution is a binomial's, the interval is that binomial's quantiles."""
    from scipy import stats

    rng = np.random.default_rng(3)
    n = 400
    a = rng.normal(0.6, 1.0, n)
    b = a + rng.normal(0.05, 0.01, n)
    b[4] = np.nan  # a pair with a missing side is left out
    d = ev.compare_paired(a, b, metric="coverage")
    keep = np.isfinite(b)
    diff = b[keep] - a[keep]
    m = n - 1
    se = diff.std(ddof=1) / np.sqrt(m)
    t = stats.t.ppf(0.975, m - 1)
    assert d.n == m and d.mean == pytest.approx(diff.mean())
    assert d.low == pytest.approx(diff.mean() - t * se, abs=0.15 * se)
    assert d.high == pytest.approx(diff.mean() + t * se, abs=0.15 * se)
    assert d.high - d.low < 0.01  # paired: unpaired, the sides' spread would make it ~0.2
    same = ev.compare_paired([0.5, 1.0, 2.0], [0.75, 1.25, 2.25])
    assert (same.mean, same.low, same.high) == pytest.approx((0.25, 0.25, 0.25))
    # 18 differences of 0 and 2 of 10: a resample's mean is 10 K / 20, K ~ Binomial(20, 0.1),
    # whose 2.5 % and 97.5 % quantiles are K = 0 (P(0) = 0.12) and K = 5 (P(K <= 4) = 0.957,
    # P(K <= 5) = 0.989): the percentile interval is [0, 2.5] exactly, not the t interval's
    # symmetric 1.0 ± 1.44 (nor the "basic" bootstrap's [-0.5, 2.0])
    skewed = ev.compare_paired(np.zeros(20), [0.0] * 18 + [10.0] * 2)
    k = stats.binom(20, 0.1)
    assert k.cdf(0) > 0.025 and k.cdf(4) < 0.975 < k.cdf(5)
    assert (skewed.mean, skewed.low, skewed.high) == (1.0, 0.0, 2.5)
    assert ev.compare_paired(a, b) == ev.compare_paired(a, b)  # the same numbers every run
    assert d.low > 0 and d.resolved(+1) == "better" and d.resolved(-1) == "worse"
    assert d.resolved(0) == "higher"
    assert d.text("{:+.3f}") == f"{d.mean:+.3f} [{d.low:+.3f}, {d.high:+.3f}]"
    assert ev.compare_paired([1.0, 2.0], [2.0, 1.0]).resolved(+1) == ""  # holds zero
    assert ev.compare_paired([None], [1.0]).n == 0
    with pytest.raises(ValueError, match="2 values against 1"):
        ev.compare_paired([1.0, 2.0], [1.0])


def test_the_paired_ratio_of_means_resamples_the_pairs_together():
    rng = np.random.default_rng(5)
    a = rng.uniform(20.0, 30.0, 40)
    b = 1.1 * a * rng.normal(1.0, 0.02, 40)  # 10 % more, pair by pair
    d = ev.compare_paired(a, b, ratio=True)
    assert d.ratio and d.n == 40 and d.mean == pytest.approx(b.mean() / a.mean())
    # the pairs resampled together: about as tight as the pair-by-pair spread (a resampling of
    # the two sides apart would be some ten times wider, from the spread of a itself)
    idx = np.random.default_rng(1).integers(0, 40, (4000, 40))
    lo, hi = np.percentile(b[idx].mean(1) / a[idx].mean(1), [2.5, 97.5])
    assert d.low == pytest.approx(lo, abs=2e-3) and d.high == pytest.approx(hi, abs=2e-3)
    assert d.low > 1.0 and d.resolved(+1) == "better" and d.text("{:.3f}").startswith("1.1")
    same = ev.compare_paired(a, a, ratio=True)
    assert (same.mean, same.low, same.high, same.resolved(+1)) == (1.0, 1.0, 1.0, "")
    # two pairs already give an interval (the resamples: 12/10, 21/20 and the ratio of both)
    two = ev.compare_paired([10.0, 20.0], [12.0, 21.0], ratio=True)
    assert (two.low, two.mean, two.high) == pytest.approx((1.05, 1.1, 1.2))
    assert ev.compare_paired([None], [1.0], ratio=True).ratio  # a ratio, even without pairs


def test_one_metric_table_formats_every_table():
    from sfw_gym.evaluation import benchmark as bm
    from sfw_gym.evaluation.metric_table import METRICS

    protocol = bm.load_protocol("benchmark-v1")
    assert set(protocol["metrics"]) <= set(METRICS)  # the benchmark's metrics are the table's
    gain = METRICS["info_gain_per_m"]
    row = ev.summarize(
        [
            {"agent": "a", "info_gain_per_m": 24.25, "stop_reason": "x"},
            {"agent": "a", "info_gain_per_m": 24.75, "stop_reason": "x"},
        ],
        ["a"],
    )[0]
    evaluate_cell = ev.results_markdown([row]).splitlines()[2].split(" | ")[7]
    assert evaluate_cell.startswith(gain.format(24.5) + " ± ")  # "24.5 ± 3.2"
    stats_entry = {"mean": 24.5, "ci_low": 24.0, "ci_high": 25.0}
    assert bm.format_interval(stats_entry, "info_gain_per_m") == "24.5 [24.0, 25.0]"
    assert gain.format_signed(-0.25) == "-0.2" and gain.label in ev.results_markdown([row])


def test_zone_band_metric_counts_unknown_cells_near_the_true_zone_border():
    env = gym.make(SMALL)
    env.reset(seed=0, options={"routers": 2})
    m = ev.zone_band_unknown(env)
    assert m["zone_band_cells"] > 0
    assert 0.9 * m["zone_band_cells"] < m["zone_band_unknown"] <= m["zone_band_cells"]  # 1 update
    assert json.dumps(m)


class _Radio:
    """Two routers; the left one is the strongest left of x = 3 m."""

    routers = ((0.5, 0.5), (5.5, 0.5))

    def mean_rssi(self, xy):
        left = xy[:, 0] < 3.0
        return np.stack([np.where(left, -40.0, -60.0), np.where(left, -60.0, -40.0)], 1)


class _Grid:
    resolution_m = 1.0

    def cell_centres(self):
        return np.meshgrid(np.arange(6) + 0.5, [0.5])


def test_the_zone_band_metric_counts_unknown_free_cells_within_the_band_of_a_zone_border():
    from sfw_gym import metrics

    truth = np.full((1, 6), 255, np.uint8)  # one row of free cells, zones 0 0 0 | 1 1 1
    belief = np.full((1, 6), 127, np.uint8)
    belief[0, 1] = 255  # mapped free: not unknown
    m = metrics.zone_band_unknown(truth, belief, _Grid(), _Radio(), band_m=1.0)
    # border cells 2 and 3; the band: cells within 1 m of them, 1 to 4; cell 1 is known
    assert m == {"zone_band_cells": 4, "zone_band_unknown": 3, "zone_band_unknown_frac": 0.75}
    one = type("OneRouter", (), {"routers": [(0.5, 0.5)]})()
    assert metrics.zone_band_unknown(truth, belief, _Grid(), one)["zone_band_cells"] == 0

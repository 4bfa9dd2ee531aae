"""``scripts/studies/ppo_diagnosis.py``: the reward's ranking of known behaviours, the variance
decomposition, the horizon and VecNormalize's scale, checked against what they mean."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "studies" / "ppo_diagnosis.py"


def _script():
    spec = importlib.util.spec_from_file_location("ppo_diagnosis", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_two_way_shares_match_a_hand_computed_example():
    d = _script()
    # rows: policies, columns: plans. Grand mean 3, row means 1.5 / 4.5, column means 2 / 4:
    # SS total 14 = plans 2·(1 + 1) + policies 2·(2.25 + 2.25) + residual 4 · 0.5².
    shares = d.two_way_shares(np.array([[1.0, 2.0], [3.0, 6.0]]))
    assert shares == pytest.approx({"plans": 4 / 14, "policies": 9 / 14, "residual": 1 / 14})
    rng = np.random.default_rng(0)
    shares = d.two_way_shares(rng.normal(size=(4, 6)))
    assert sum(shares.values()) == pytest.approx(1.0)
    # an additive table (policy effect + plan effect) has no residual
    additive = np.add.outer([0.0, 1.0, 5.0], [2.0, -1.0, 0.5, 3.0])
    assert d.two_way_shares(additive)["residual"] == pytest.approx(0.0, abs=1e-12)


def test_signal_to_noise_of_a_paired_difference():
    d = _script()
    a = np.array([1.0, 3.0, 5.0])  # std 2 across plans
    s = d.signal_to_noise(a, a + 1.0)  # +1 on every plan: a constant difference
    assert s["mean_difference"] == pytest.approx(1.0)
    assert s["plan_std"] == pytest.approx(2.0)
    assert s["snr_unpaired"] == pytest.approx(0.5)
    assert math.isnan(s["snr_paired"])  # no spread in the differences
    assert s["episodes_needed"] == pytest.approx(16.0)  # (2 / 0.5)²


def test_horizon_returns_to_go_and_vecnormalize_scale():
    d = _script()
    assert d.effective_horizon(0.99) == pytest.approx(100.0)
    assert d.effective_horizon(0.98) == pytest.approx(50.0)
    r = np.array([1.0, 0.0, 2.0])
    assert d.returns_to_go(r, 0.5) == pytest.approx([1.5, 1.0, 2.0])
    assert d.returns_to_go(r, 1.0) == pytest.approx([3.0, 2.0, 2.0])
    # R_t = 0.5 R_{t-1} + r_t: 1, 0.5, 2.25, then a new episode: 4
    values = np.array([1.0, 0.5, 2.25, 4.0])
    assert d.vecnormalize_scale([r, np.array([4.0])], 0.5) == pytest.approx(
        math.sqrt(values.var() + 1e-8)
    )
    assert d.entropy_ratio(np.full(64, 1 / 64)) == pytest.approx(1.0)
    assert d.entropy_ratio(np.eye(64)[3]) == pytest.approx(0.0)


@pytest.mark.episode
def test_ranking_on_small_plans_pairs_the_plans_and_splits_the_return():
    d = _script()
    runs = d.ranking("SfW-ExploreSmall-v0", ("frontier", "spin", "wall-follow"), episodes=2)
    frontier, spin = runs["frontier"], runs["spin"]
    assert [e["floorplan"] for e in frontier] == [e["floorplan"] for e in spin]  # paired plans
    for f, s in zip(frontier, spin, strict=True):
        assert s["coverage"] < f["coverage"]  # turning in place maps little
        assert s["bumps"] == 0
    for e in frontier + spin + runs["wall-follow"]:
        assert e["return"] == pytest.approx(e["bits_part"] - e["fine_part"], abs=1e-9)
        assert e["fine_part"] == pytest.approx(0.1 * e["bumps"])
        assert e["steps"] <= 300
    assert len(frontier[0]["rewards"]) == frontier[0]["steps"]  # traced: the per-step rewards
    assert "rewards" not in spin[0]
    table = d.ranking_table("SfW-ExploreSmall-v0", runs)
    assert table.count("\n| ") == 4  # header + 3 behaviours
    rows = {line.split("|")[1].strip(): line.split("|") for line in table.splitlines()[4:]}
    assert sorted(int(r[-3]) for r in rows.values()) == [1, 2, 3]  # by return
    assert int(rows["frontier"][-2]) < int(rows["spinning in place"][-2])  # by coverage

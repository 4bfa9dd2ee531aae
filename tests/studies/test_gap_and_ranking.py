"""``scripts/studies/gap_decomposition.py`` and ``ranking_study.py`` (issue 51): their bins
partition what they count, the bits by source sum to the episode's, the correlations are
correlations."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

STUDIES = Path(__file__).resolve().parents[2] / "scripts" / "studies"


def _script(name: str):
    spec = importlib.util.spec_from_file_location(name, STUDIES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    spec.loader.exec_module(module)
    return module


@pytest.mark.episode
def test_the_gap_bins_partition_the_unknown_free_cells_and_the_sources_the_bits():
    g = _script("gap_decomposition")
    row = g.run("frontier", 1_000_000, 200)
    bins, left = row["bins"], row["left_unknown"]
    assert 0 < left <= row["free_cells"]
    walls = [v for k, v in bins.items() if k.startswith("wall ")]
    assert sum(walls) == left
    assert bins["in sight"] + bins["out of sight"] == left
    assert bins["room entered"] + bins["room never entered"] + bins["in no room"] == left
    assert bins["room entered"] > 0 and bins["room never entered"] > 0  # 200 steps: some rooms
    assert sum(row["sources"].values()) == pytest.approx(row["bits"], rel=1e-9)


@pytest.mark.episode
def test_the_ranking_probe_scores_the_top_candidates_against_their_true_bits():
    r = _script("ranking_study")
    env = gym.make("SfW-Explore-v0", max_steps=150)
    obs, _ = env.reset(seed=1_000_000)
    agent = r.Probe(env, every=2)
    agent.reset(env, seed=1_000_000)
    for _ in range(150):
        obs, *_ = env.step(agent.act(obs))
    assert agent.rows
    for row in agent.rows:
        assert row["truth_max"] == max(row["truth"])
        for m in r.MODELS:
            assert np.isnan(row[m]) or -1.0 <= row[m] <= 1.0
            assert 0.0 <= row["regret"][m] <= row["truth_max"] - min(row["truth"]) + 1e-12
    # the dry run's total ranks well: its choice loses less than a candidate of average truth
    model = "dry run, predicted walls: total"
    lost = np.mean([row["regret"][model] for row in agent.rows])
    average = np.mean([row["truth_max"] - np.mean(row["truth"]) for row in agent.rows])
    assert lost < average

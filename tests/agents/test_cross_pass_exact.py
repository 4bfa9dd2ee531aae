"""Cross-pass made faster with the same choices (issue 39): band clusters filled from the cells
within the trigger, and a bounded first path search."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from scipy import ndimage

from sfw_gym.agents.cross_pass import CrossPassAgent


def clusters_by_labelling(targets, cost, trigger_m):
    """The computation ``_clusters_within_trigger`` replaced: label the map, sort by best cost."""
    labels, n = ndimage.label(targets, structure=np.ones((3, 3), bool))
    best = ndimage.minimum(np.where(labels > 0, cost, np.inf), labels, np.arange(1, n + 1))
    return [np.nonzero(labels == i + 1) for i in np.argsort(best) if best[i] <= trigger_m]


@pytest.mark.parametrize("ties", [False, True])
def test_clusters_within_the_trigger_equal_a_whole_map_labelling(ties):
    rng = np.random.default_rng(int(ties))
    agent = CrossPassAgent(pass_trigger_m=5.0)
    for _ in range(200):
        shape = tuple(int(v) for v in rng.integers(1, 40, 2))
        targets = rng.random(shape) < rng.uniform(0.05, 0.6)
        cost = rng.uniform(0.0, 10.0, shape)
        if ties:
            cost = np.round(cost * 2.0) / 2.0  # equally near clusters
        got = agent._clusters_within_trigger(targets, cost)
        expected = clusters_by_labelling(targets, cost, 5.0)
        assert len(got) == len(expected)
        for (rows, cols), (rows_0, cols_0) in zip(got, expected, strict=True):
            np.testing.assert_array_equal(rows, rows_0)
            np.testing.assert_array_equal(cols, cols_0)


class UnboundedCrossPass(CrossPassAgent):
    """Cross-pass searching every plan's paths over the whole map."""

    _bounded_search = False


@pytest.mark.parametrize("seed", [0, 1])
def test_a_bounded_first_search_makes_the_same_choices_as_a_full_one(seed):
    """Kept only when no band cell lies within the trigger (and the frontier choice is proven):
    the default bound, and one short of the trigger (always the whole map), act as unbounded."""
    runs = []
    for agent in (UnboundedCrossPass(), CrossPassAgent(), CrossPassAgent(search_radius_m=2.0)):
        env = gym.make("SfW-Explore-v0", max_steps=400)
        obs, _ = env.reset(seed=seed)
        agent.reset(env, seed=seed)
        actions = []
        for _ in range(400):
            action = agent.act(obs)
            actions.append(action)
            obs, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                break
        runs.append((np.array(actions), agent.n_full_searches, agent.n_plans))
    (unbounded, _, _), (bounded, full_searches, plans), (short, _, _) = runs
    assert 0 < full_searches < plans  # both ways of choosing happened
    assert np.array_equal(bounded, unbounded)
    assert np.array_equal(short, unbounded)

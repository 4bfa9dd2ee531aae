"""The agent benchmarks of ``sfw-gym bench --agents`` run and report what they promise."""

from __future__ import annotations

import sfw_gym  # noqa: F401  (registers the envs)
from sfw_gym.bench import run_candidate_bench, synthetic_view, time_agent_episode


def test_agent_episodes_run_their_whole_budget():
    for agent in ("random", "frontier"):
        seconds, steps = time_agent_episode(agent, "SfW-ExploreSmall-v0", seed=0, max_steps=60)
        assert steps == 60 and seconds > 0


def test_synthetic_views_are_half_explored_squares():
    view = synthetic_view(64)
    assert view.belief_u8.shape == (64, 64)
    known = (view.belief_u8 != 127).mean()
    assert 0.2 < known < 0.9
    assert view.belief_u8[view.cell] == 255  # the robot stands on free space


def test_candidate_bench_reports_both_ways_of_asking():
    lines = run_candidate_bench(sizes=(32,), calls=2)
    assert len(lines) == 3 and "candidate_goals(view)" in lines[1] and "GoalFinder" in lines[2]

"""The region oracle: look-ahead on a copy of the true env, never on the real one."""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registers the envs)
from sfw_gym.agents import make_agent
from sfw_gym.agents.oracles import ORACLE_PREFIX, OracleAgent
from sfw_gym.agents.region_oracle import RegionOracle
from sfw_gym.agents.regions import RegionAgent
from sfw_gym.core.errors import ConfigError

SMALL = "SfW-ExploreSmall-v0"
#: Small budgets: 10-step decisions, 3 candidates, 2 decisions of look-ahead.
FAST = {"regions": {"decision_steps": 10}, "candidates": 3, "horizon_decisions": 2}


class Recording(RegionOracle):
    """The oracle, recording its choice at each decision."""

    def _on_reset(self, view: Any) -> None:
        super()._on_reset(view)
        self.choices: list[int] = []
        self.scores: list[dict[int, float]] = []

    def choose(self, view: Any, obs: Any, menu: Any, extra: Any) -> int:
        choice = super().choose(view, obs, menu, extra)
        self.choices.append(choice)
        self.scores.append(dict(self.last_scores))
        return choice


class Scripted(RegionAgent):
    """The region teacher, except that its first decisions take the given choices."""

    def __init__(self, choices: list[int], **params: Any) -> None:
        super().__init__(**params)
        self.script = list(choices)

    def choose(self, view: Any, obs: Any, menu: Any, extra: Any) -> int:
        if self.script:
            return self.script.pop(0)
        return super().choose(view, obs, menu, extra)


def run(agent: Any, seed: int, steps: int) -> tuple[list[np.ndarray], gym.Env]:
    env = gym.make(SMALL)
    obs, _ = env.reset(seed=seed)
    agent.reset(env, seed=0)
    actions = []
    for _ in range(steps):
        actions.append(np.asarray(agent.act(obs)).copy())
        obs, *_ = env.step(actions[-1])
    return actions, env


def test_it_is_a_registered_privileged_oracle():
    assert issubclass(RegionOracle, OracleAgent) and RegionOracle.privileged
    agent = make_agent("oracle-regions")
    assert isinstance(agent, RegionOracle) and agent.name.startswith(ORACLE_PREFIX)


def test_the_look_ahead_leaves_the_real_env_and_the_agent_alone():
    """The real env and the oracle's own steering after its decisions are those of the region
    teacher replaying the same choices: the simulations stepped copies only."""
    oracle = Recording(**FAST)
    actions, env = run(oracle, seed=2, steps=60)
    assert oracle.simulated_steps > 0 and len(oracle.choices) == 6
    replay = Scripted(oracle.choices, regions=FAST["regions"])
    replayed, env2 = run(replay, seed=2, steps=60)
    for a, b in zip(actions, replayed, strict=True):
        np.testing.assert_array_equal(a, b)
    u, u2 = env.unwrapped, env2.unwrapped
    assert u.steps == u2.steps == 60
    np.testing.assert_array_equal(u.robot_view().log_odds, u2.robot_view().log_odds)
    assert u.ground_truth().pose == u2.ground_truth().pose
    assert oracle.steering.remaining == replay.steering.remaining
    assert oracle.steering.micro_decisions == replay.steering.micro_decisions
    # ... and the oracle does not only replay the teacher: some decision chose another region
    teacher, _ = run(Scripted([], regions=FAST["regions"]), seed=2, steps=60)
    assert any((a != b).any() for a, b in zip(actions, teacher, strict=True))


def test_same_seeds_give_the_same_actions():
    first, _ = run(RegionOracle(**FAST), seed=2, steps=40)
    second, _ = run(RegionOracle(**FAST), seed=2, steps=40)
    for a, b in zip(first, second, strict=True):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("score", ["bits", "bits_per_metre", "coverage"])
def test_its_choice_is_the_best_of_the_simulations_each_rescored_on_a_fresh_env(score):
    """Each simulated candidate's score equals a fresh env driven by the teacher forced to that
    candidate for the first decision (then its own for the horizon); the oracle takes the best."""
    oracle = Recording(**FAST, score=score)
    run(oracle, seed=2, steps=1)
    scores = oracle.scores[0]
    assert len(scores) == 3 and len(set(scores.values())) > 1
    steps = FAST["horizon_decisions"] * FAST["regions"]["decision_steps"]
    for i, expected in scores.items():
        env = gym.make(SMALL)
        obs, info0 = env.reset(seed=2)
        forced = Scripted([i], regions=FAST["regions"])
        forced.reset(env, seed=0)
        for _ in range(steps):
            obs, _, _, _, info = env.step(forced.act(obs))
        bits = info0["entropy_bits"] - info["entropy_bits"]
        metres = info["path_length_m"] - info0["path_length_m"] + oracle.settings.distance_offset_m
        got = {
            "bits": bits,
            "bits_per_metre": bits / metres,
            "coverage": info["coverage"] - info0["coverage"],
        }[score]
        assert got == pytest.approx(expected, rel=1e-12, abs=1e-12), i
    assert scores[oracle.choices[0]] == max(scores.values())


def test_one_candidate_or_no_time_is_the_region_teacher():
    teacher, _ = run(make_agent("region-teacher", regions=FAST["regions"]), seed=2, steps=60)
    for params in ({"candidates": 1}, {"time_limit_s": 1e-9}):
        oracle = Recording(**{**FAST, **params})
        actions, _ = run(oracle, seed=2, steps=60)
        for a, b in zip(teacher, actions, strict=True):
            np.testing.assert_array_equal(a, b)
        assert all(len(s) <= (1 if "time_limit_s" in params else 0) for s in oracle.scores)


@pytest.mark.parametrize(
    ("params", "key"),
    [
        ({"candidates": 0}, "candidates"),
        ({"horizon_decisions": 0}, "horizon_decisions"),
        ({"horizon_decisions": 1.5}, "horizon_decisions"),
        ({"score": "metres"}, "score"),
        ({"distance_offset_m": -1.0}, "distance_offset_m"),
        ({"time_limit_s": 0.0}, "time_limit_s"),
        ({"teacher": "oracle"}, "teacher"),
        ({"regions": {"decision_steps": 0}}, "decision_steps"),
    ],
)
def test_bad_settings_raise_a_config_error_naming_them(params, key):
    with pytest.raises(ConfigError, match=key):
        make_agent("oracle-regions", **params)


def test_reset_needs_the_env_itself():
    env = gym.make(SMALL)
    env.reset(seed=0)
    with pytest.raises(ConfigError, match="oracle"):
        RegionOracle().reset(info={"robot_view": env.unwrapped.robot_view()}, seed=0)
    with pytest.raises(ConfigError, match="oracle"):
        RegionOracle().reset(None, seed=0)

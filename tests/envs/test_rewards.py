"""Reward bookkeeping: what the learner is paid, step by step and summed over wrapper steps, and
when an episode ends."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registers the envs)
from sfw_gym.agents import FrontierAgent
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.waypoint import WaypointWrapper

SMALL = "SfW-ExploreSmall-v0"


class RecordSteps(gym.Wrapper):
    """Keeps every inner step's reward and end flags."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        self.rewards: list[float] = []
        self.ends: list[tuple[bool, bool]] = []

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.rewards.append(reward)
        self.ends.append((terminated, truncated))
        return obs, reward, terminated, truncated, info


@pytest.mark.parametrize("env_id", ["SfW-Explore-v0", "SfW-ExploreDiscrete-v0"])
def test_reward_is_the_entropy_decrease_in_bits_minus_the_collision_penalty(env_id):
    env = gym.make(env_id, reward_scale=0.01, collision_penalty=0.1)
    _, info = env.reset(seed=5)
    env.action_space.seed(5)
    entropy, collisions, bumps, gained = info["entropy_bits"], 0, 0, 0.0
    for _ in range(400):
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        bumped = info["collisions"] - collisions
        gain = entropy - info["entropy_bits"]
        assert bumped in (0, 1)
        assert info["info_gain_bits"] == pytest.approx(gain, abs=1e-6)
        assert reward == pytest.approx(0.01 * gain - 0.1 * bumped, abs=1e-8)
        entropy, collisions = info["entropy_bits"], info["collisions"]
        bumps += bumped
        gained += gain
        if terminated or truncated:
            break
    assert bumps > 0 and gained > 100  # both terms were exercised


def test_reward_scale_and_penalty_scale_the_two_terms():
    def rewards(**kwargs):
        env = gym.make("SfW-Explore-v0", **kwargs)
        env.reset(seed=5)
        env.action_space.seed(5)
        return np.array([env.step(env.action_space.sample())[1] for _ in range(400)])

    base = rewards(reward_scale=0.01, collision_penalty=0.0)
    np.testing.assert_allclose(rewards(reward_scale=0.03, collision_penalty=0.0), 3 * base)
    penalised = rewards(reward_scale=0.01, collision_penalty=0.5)
    assert np.all(np.isclose(penalised - base, 0.0) | np.isclose(penalised - base, -0.5))
    assert np.isclose(penalised - base, -0.5).any()


@pytest.mark.parametrize("env_id", ["SfW-Explore-v0", "SfW-ExploreDiscrete-v0"])
def test_waypoint_reward_is_the_sum_of_the_env_steps_it_covers(env_id):
    inner = RecordSteps(gym.make(env_id, max_steps=400))
    env = WaypointWrapper(inner, grid_cells=4, max_steps_per_waypoint=40)
    env.reset(seed=7)
    env.action_space.seed(7)
    total, n_multi = 0.0, 0
    while True:
        before = len(inner.rewards)
        _, reward, terminated, truncated, info = env.step(env.action_space.sample())
        covered = inner.rewards[before:]
        assert info["waypoint_steps"] == len(covered)
        assert reward == pytest.approx(sum(covered), abs=1e-9)
        assert (terminated, truncated) == inner.ends[-1]
        total += reward
        n_multi += len(covered) > 1 and len({round(r, 9) for r in covered}) > 1
        if terminated or truncated:
            break
    assert n_multi >= 3  # waypoints whose steps paid different rewards
    assert total == pytest.approx(sum(inner.rewards), abs=1e-6)


def test_terminated_at_the_first_step_that_reaches_the_coverage_target():
    env = gym.make(SMALL, coverage_target=0.2, max_steps=2000)
    obs, info = env.reset(seed=1)
    agent = FrontierAgent()
    agent.reset(env, seed=1)
    coverage = [info["coverage"]]
    while True:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        coverage.append(info["coverage"])
        if terminated or truncated:
            break
    assert terminated and not truncated
    assert coverage[-1] >= 0.2 and max(coverage[:-1]) < 0.2
    assert info["summary"]["coverage"] == coverage[-1]
    assert 0 <= info["summary"]["map_mse"] <= 1
    assert info["steps_to_coverage_50"] == info["steps_to_coverage_90"] == -1  # not reached


def test_truncates_at_max_steps():
    env = gym.make("SfW-ExploreSmall-v0", max_steps=7, coverage_target=1.0)
    env.reset(seed=0)
    for i in range(7):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        assert truncated == (i == 6) and not terminated
    assert info["summary"]["steps"] == 7


def test_step_budget_scales_with_the_plan_area():
    env = gym.make("SfW-ExploreSmall-v0", steps_per_m2=0.2, coverage_target=1.0)
    _, info = env.reset(seed=0)
    area = env.unwrapped.scene.floorplan.area_m2
    budget = info["max_steps"]
    assert budget == math.ceil(0.2 * area) and 2 <= budget < 300
    steps = 0
    while True:
        steps += 1
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:
            break
    assert truncated and steps == budget == info["summary"]["steps"]
    capped = gym.make("SfW-ExploreSmall-v0", steps_per_m2=1000.0, max_steps=50)
    assert capped.reset(seed=0)[1]["max_steps"] == 50  # max_steps caps the scaled budget
    full = gym.make("SfW-ExploreFull-v0")
    _, info = full.reset(seed=1)
    assert info["max_steps"] == math.ceil(60 * full.unwrapped.scene.floorplan.area_m2)
    for bad in (-1.0, float("nan"), "60"):
        with pytest.raises(ConfigError, match="steps_per_m2"):
            gym.make("SfW-Explore-v0", steps_per_m2=bad)


@pytest.mark.slow
def test_steps_to_coverage_are_the_first_steps_at_each_level():
    """Once reached, ``steps_to_coverage_50`` / ``_90`` are the first steps whose coverage was at
    least 0.5 / 0.9, read off the episode's own coverage series (and stay once set)."""
    env = gym.make(SMALL, max_steps=2000)  # seed 3: 0.9 at about step 1,300
    obs, info = env.reset(seed=3)
    agent = FrontierAgent()
    agent.reset(env, seed=3)
    coverage, infos = [info["coverage"]], []
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        coverage.append(info["coverage"])
        infos.append(info)
        done = terminated or truncated
    for level, key in ((0.5, "steps_to_coverage_50"), (0.9, "steps_to_coverage_90")):
        reached = [t for t, c in enumerate(coverage) if c >= level]
        assert reached, f"the episode never reached {level}: pick a longer one"
        assert info[key] == reached[0]
        after, before = infos[reached[0] - 1 :], infos[: reached[0] - 1]
        assert all(i[key] == reached[0] for i in after) and all(i[key] == -1 for i in before)


def test_each_discrete_action_moves_the_robot_as_its_wheel_command_says():
    """0 drives max_linear_speed x control_period along the heading, 1 and 2 turn in place by
    +/- max_angular_speed x control_period (the defaults: 0.1 m, 0.3 rad), away from walls."""
    env = gym.make("SfW-ExploreDiscrete-v0")
    env.reset(seed=0)
    robot = env.unwrapped.scene.robot
    step_m, turn_rad = 0.5 * 0.2, 1.5 * 0.2
    for action, (dist, dturn) in ((1, (0, turn_rad)), (2, (0, -turn_rad)), (0, (step_m, 0))):
        x0, y0, t0 = robot.pose
        env.step(action)
        x1, y1, t1 = robot.pose
        assert not robot.bumped
        assert math.hypot(x1 - x0, y1 - y0) == pytest.approx(dist, abs=1e-9)
        assert math.remainder(t1 - t0 - dturn, math.tau) == pytest.approx(0.0, abs=1e-9)
        if dist:
            assert math.atan2(y1 - y0, x1 - x0) == pytest.approx(t0, abs=1e-6)  # along the heading


def test_the_state_vector_is_scaled_rssi_heard_flags_bump_position_heading_and_known():
    """Per router (RSSI + 100) / 80 and a heard flag, then the bump, x and y as fractions of the
    grid's extent, sin and cos of the heading, the known fraction: worked out from the env's
    own readings, pose and grid."""
    env = gym.make(SMALL, radio={"sensitivity_dbm": -35.0})  # some readings unheard
    env.reset(seed=5)
    u = env.unwrapped
    seen = set()
    for t in range(40):
        obs, *_ = env.step(np.array([0.7, 0.4 if t % 10 < 5 else -0.4]))
        rssi = u.rssi_history.view[-1].astype(float)
        x, y, theta = u.pose_estimate
        (x0, y0), (rows, cols), res = u.grid.origin_xy, u.grid.shape, u.grid.resolution_m
        heard = rssi > -100
        n = len(rssi)  # SMALL: as many slots as routers
        expected = [
            *np.where(heard, np.clip((rssi + 100) / 80, 0, 1), 0.0),
            *heard.astype(float),
            float(u.scene.robot.bumped),
            (x - x0) / (cols * res),
            (y - y0) / (rows * res),
            math.sin(theta),
            math.cos(theta),
            u.tracker.known_fraction,
        ]
        np.testing.assert_allclose(obs["state"], np.float32(expected), atol=1e-6)
        assert obs["state"].shape == (2 * n + 6,)
        seen.update(heard.tolist())
    assert seen == {True, False}

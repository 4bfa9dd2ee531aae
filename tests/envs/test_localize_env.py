"""SfW-Localize-v0: WiFi Monte-Carlo localisation on a surveyed plan, from an unknown start."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents import FrontierAgent
from sfw_gym.core.errors import ConfigError


def drive(env, seed: int, steps: int):
    obs, info = env.reset(seed=seed)
    agent = FrontierAgent()
    agent.reset(env.unwrapped, seed=seed)
    infos, rewards = [info], []
    for _ in range(steps):
        obs, reward, _, _, info = env.step(agent.act(obs))
        infos.append(info)
        rewards.append(reward)
    return obs, infos, rewards


def test_the_robot_finds_itself_from_an_unknown_start():
    env = gym.make("SfW-Localize-v0")
    obs, infos, rewards = drive(env, 2_000_000, 120)
    errors = [i["loc_error_m"] for i in infos]
    assert np.mean(errors[10:]) < 1.5  # measured 0.7 m
    assert env.observation_space.contains(obs) and obs["belief"].shape == (5,)
    # the reward is the fall of the error bound (the particles' spread): it telescopes
    assert sum(rewards) == pytest.approx(infos[0]["loc_spread_m"] - infos[-1]["loc_spread_m"])


@pytest.mark.episode
def test_a_kidnapped_robot_is_lost_then_found_and_its_odometry_saw_nothing():
    env = gym.make("SfW-Localize-v0", localize={"kidnap_step": 60})
    _, infos, _ = drive(env, 2_000_000, 100)
    at = next(k for k, i in enumerate(infos) if i["kidnapped"])
    assert at == 60
    jump = np.hypot(*(infos[at]["true_pose"][:2] - infos[at - 1]["true_pose"][:2]))
    odometry_step = np.hypot(*(infos[at]["odometry_pose"][:2] - infos[at - 1]["odometry_pose"][:2]))
    assert jump > 2.0 and odometry_step < 0.2  # carried away; the wheels felt one step at most
    assert infos[at]["loc_error_m"] > 2.0  # lost
    assert min(i["loc_error_m"] for i in infos[at + 1 : at + 31]) < 1.0  # found again


def test_bad_settings_are_named():
    with pytest.raises(ConfigError, match="localize"):
        gym.make("SfW-Localize-v0", localize={"particle": 10})
    with pytest.raises(ConfigError, match="n_background_aps"):
        gym.make("SfW-Localize-v0", n_background_aps=0)

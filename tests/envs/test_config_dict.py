"""Every registered id's ``config_dict()`` is its whole configuration: JSON-serialisable, and
the env built from it alone is the same env (same configuration, same rollout), so
``gym.make(env_id, **config_dict())`` is too."""

from __future__ import annotations

import json

import gymnasium as gym
import pytest

import sfw_gym  # noqa: F401  (registers the ids)
from sfw_gym.envs import ENV_IDS
from tests.envs.test_behaviour_digest import episode_digest

STEPS = 30


@pytest.mark.parametrize("env_id", sorted(ENV_IDS))
def test_config_dict_round_trips_through_gym_make(env_id):
    env = gym.make(env_id)
    cfg = json.loads(json.dumps(env.unwrapped.config_dict()))  # as a log file would hold it
    again = type(env.unwrapped)(**cfg)  # from the dict alone, not the registered kwargs
    assert again.unwrapped.config_dict() == cfg
    assert episode_digest(again, seed=3, steps=STEPS) == episode_digest(env, seed=3, steps=STEPS)


def test_config_dict_holds_every_subsystem_of_the_lidar_env():
    cfg = gym.make("SfW-ExploreLidar-v0").unwrapped.config_dict()
    assert {"radio", "robot", "mapper", "slam", "lidar", "generator", "floorplan"} <= set(cfg)
    assert cfg["pose_source"] == "radio_lidar" and cfg["lidar"]["beams"] > 0
    assert gym.make("SfW-Explore-v0").unwrapped.config_dict()["lidar"] is None

"""Every registered id's ``config_dict()`` is its whole configuration: JSON-serialisable, and
the env built from it alone is the same env (same configuration, same rollout), so
``gym.make(env_id, **config_dict())`` is too."""

from __future__ import annotations

import inspect
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


#: A valid non-default value for every keyword of the explore env (a new keyword must be added).
NON_DEFAULT = {
    "action_type": "discrete",
    "floorplan": 7,
    "generator": {"area_m2": 45.0},
    "n_routers": 3,
    "radio_preset": "thick",
    "radio_band": "5",
    "radio": {"tx_power_dbm": 18.0},
    "robot": {"radius_m": 0.2},
    "mapper": {"max_k": 4},
    "resolution_m": 0.2,
    "map_px": 40,
    "crop_px": 40,
    "coverage_target": 0.9,
    "collision_penalty": 0.2,
    "reward_scale": 0.02,
    "max_steps": 100,
    "steps_per_m2": 10.0,
    "n_background_aps": 4,
    "pose_source": "true",
    "slam": {"sigma_db": 5.0},
    "lidar": {"beams": 90},
}


@pytest.mark.parametrize("key", sorted(NON_DEFAULT))
def test_every_keyword_shows_in_the_config_and_survives_the_round_trip(key):
    from sfw_gym.envs.explore import SfWExploreEnv

    params = set(inspect.signature(SfWExploreEnv).parameters)
    assert params - {"render_mode", "render_size", "unknown"} == set(NON_DEFAULT)
    default = SfWExploreEnv().config_dict()
    cfg = json.loads(json.dumps(SfWExploreEnv(**{key: NON_DEFAULT[key]}).config_dict()))
    changed = {k for k in cfg if cfg[k] != default[k]}
    assert key in changed
    assert SfWExploreEnv(**cfg).config_dict() == cfg

"""Access points beyond the mapping routers: the robot hears their fingerprint (issue 15)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents import FrontierAgent
from sfw_gym.core.errors import ConfigError
from sfw_gym.slam import kernel_similarity

SMALL = "SfW-ExploreSmall-v0"


def test_the_default_env_has_no_fingerprint():
    env = gym.make(SMALL)
    obs, info = env.reset(seed=0)
    assert "fingerprint" not in obs and "fingerprint" not in info
    with pytest.raises(ConfigError, match="n_background_aps"):
        gym.make(SMALL, n_background_aps=-1)


def test_background_aps_are_heard_as_a_fingerprint_that_changes_with_place():
    env = gym.make(SMALL, n_background_aps=12)
    obs, info = env.reset(seed=3)
    assert env.observation_space.contains(obs)
    scene = env.unwrapped.scene
    aps = scene.background.routers
    inside = scene.floorplan.is_free(aps)
    assert 0 < inside.sum() < len(aps)  # some in the building, some next door
    fp = info["fingerprint"]
    assert fp.shape == (12,)
    np.testing.assert_array_equal(~np.isnan(fp), obs["fingerprint_heard"].astype(bool))
    # the same seed, the same access points and readings
    again = gym.make(SMALL, n_background_aps=12)
    _, info2 = again.reset(seed=3)
    np.testing.assert_array_equal(np.nan_to_num(info2["fingerprint"]), np.nan_to_num(fp))
    # fingerprints taken close together are more alike than ones taken far apart
    agent = FrontierAgent()
    agent.reset(env, seed=3)
    poses, prints = [], []
    for _ in range(250):
        _, _, _, _, info = env.step(agent.act(obs))
        poses.append(info["true_pose"][:2])
        prints.append(info["fingerprint"])
    poses, prints = np.array(poses), np.array(prints)
    d = np.linalg.norm(poses[:, None] - poses[None], axis=2)
    sim = kernel_similarity(prints[:, None], prints[None])
    near, far = sim[(d > 0) & (d < 0.5)], sim[d > 3.0]
    assert len(near) > 50 and len(far) > 50
    assert near.mean() > far.mean() + 0.1

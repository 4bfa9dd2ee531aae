"""The candidate-goal explorer as an agent on the explore env acts as in its training env."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.core.errors import ConfigError
from tests.envs.test_goals import SMALL

sb3_contrib = pytest.importorskip("sb3_contrib")
torch = pytest.importorskip("torch")
from sfw_gym.rl.agent import PPOAgent  # noqa: E402
from sfw_gym.rl.goal_policy import GoalsPolicy  # noqa: E402


@pytest.fixture(scope="module")
def model_dir(tmp_path_factory):
    folder = tmp_path_factory.mktemp("goals")
    env = gym.make("SfW-ExploreGoals-v0", **SMALL)
    sb3_contrib.MaskablePPO(GoalsPolicy, env, n_steps=16, batch_size=16, seed=3).save(
        folder / "model.zip"
    )
    return folder


def test_the_agent_drives_the_explore_env_as_the_goals_env_does(model_dir):
    model = sb3_contrib.MaskablePPO.load(model_dir / "model.zip")
    env = gym.make("SfW-ExploreGoals-v0", **SMALL)
    obs, _ = env.reset(seed=4)
    for _ in range(12):
        action, _ = model.predict(
            obs, action_masks=env.unwrapped.action_masks(), deterministic=True
        )
        obs, _, terminated, truncated, info = env.step(int(action))
        assert not (terminated or truncated)
    steps, pose = env.unwrapped.explore.steps, info["true_pose"]
    agent = PPOAgent(model_dir)
    explore = gym.make("SfW-Explore-v0", **SMALL)
    obs, _ = explore.reset(seed=4)
    agent.reset(explore, seed=0)
    for _ in range(steps):
        obs, _, _, _, info = explore.step(agent.act(obs))
    assert agent.n_decisions == 12
    np.testing.assert_array_equal(info["true_pose"], pose)
    # every valid choice is logged, with its menu's features (all of them computed)
    assert 0 < len(agent.decisions) <= 12
    assert agent.decisions[-1].target_rc == agent.driver.target
    assert all(np.isfinite(d.features).all() for d in agent.decisions)


def test_a_missing_model_is_named(tmp_path):
    with pytest.raises(ConfigError, match=r"no model found .*; train one with `sfw-gym train"):
        PPOAgent(tmp_path)
    with pytest.raises(ConfigError, match=r"other\.zip not found; train one with `sfw-gym train"):
        PPOAgent(tmp_path / "other.zip")


def test_the_agent_runs_torch_on_one_thread_unless_told_otherwise(model_dir):
    torch.set_num_threads(2)
    PPOAgent(model_dir, num_threads=None)
    assert torch.get_num_threads() == 2
    PPOAgent(model_dir)  # a small network: more threads only contend with the envs
    assert torch.get_num_threads() == 1


def test_a_policy_trained_without_masks_chooses_among_all_candidates(model_dir, tmp_path):
    (tmp_path / "config.yml").write_text("hyperparameters:\n  use_masking: false\n")
    (tmp_path / "model.zip").write_bytes((model_dir / "model.zip").read_bytes())
    masks = []
    agent = PPOAgent(tmp_path)
    agent._choose = lambda obs, mask: masks.append(mask) or 0
    explore = gym.make("SfW-Explore-v0", **SMALL)
    obs, _ = explore.reset(seed=4)
    agent.reset(explore, seed=0)
    for _ in range(20):
        obs, *_ = explore.step(agent.act(obs))
    assert masks and all(m.all() for m in masks)
    assert PPOAgent(model_dir).use_masking

"""PPOAgent: a policy trained with waypoints acts through the agents' interface as in training."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import yaml

import sfw_gym  # noqa: F401
from sfw_gym.agents import PPOAgent
from sfw_gym.envs.waypoint import WaypointWrapper
from sfw_gym.errors import ConfigError
from sfw_gym.training import train_ppo, wrapper_specs

SMALL = "SfW-ExploreSmall-v0"
WAYPOINTS = {"grid_cells": 4, "max_steps_per_waypoint": 20}


@pytest.fixture(scope="module")
def waypoint_model(tmp_path_factory):
    """A tiny waypoint policy trained by train_ppo from an rl-zoo YAML with env_wrapper."""
    root = tmp_path_factory.mktemp("ppo")
    hyper = root / "ppo.yml"
    block = {
        "policy": "MultiInputPolicy",
        "n_envs": 1,
        "env_wrapper": [{"sfw_gym.envs.waypoint.WaypointWrapper": WAYPOINTS}],
        "n_steps": 32,
        "batch_size": 32,
        "n_epochs": 1,
        "policy_kwargs": "dict(net_arch=dict(pi=[16], vf=[16]))",
    }
    hyper.write_text(yaml.safe_dump({SMALL: block}))
    out = root / "run"
    train_ppo(SMALL, 64, out, hyperparams_path=hyper, env_kwargs={"max_steps": 120},
              eval_every=10**9, progress_bar=False)  # fmt: skip
    return out


def test_agent_drives_the_raw_env_exactly_as_the_wrapper_did_in_training(waypoint_model):
    agent = PPOAgent(model_dir=waypoint_model, deterministic=True)
    assert agent.waypoints == WAYPOINTS

    wrapped = WaypointWrapper(gym.make(SMALL, max_steps=120), **WAYPOINTS)
    obs, _ = wrapped.reset(seed=3)
    goals = []
    while True:
        action, _ = agent.model.predict(obs, deterministic=True)
        goals.append(tuple(wrapped.goal_xy(int(action))))
        obs, _, terminated, truncated, info = wrapped.step(int(action))
        if terminated or truncated:
            break
    expected = np.array(wrapped.unwrapped.trajectory)

    env = gym.make(SMALL, max_steps=120)
    obs, _ = env.reset(seed=3)
    agent.reset(env, seed=0)
    while True:
        obs, _, terminated, truncated, info2 = env.step(agent.act(obs))
        if terminated or truncated:
            break
    np.testing.assert_allclose(np.array(env.unwrapped.trajectory), expected)
    assert agent.goals == [pytest.approx(g) for g in goals]
    assert info2["coverage"] == info["coverage"]


def test_sampled_waypoints_are_reproducible_from_the_agent_seed(waypoint_model):
    def goals(seed):
        agent = PPOAgent(model_dir=waypoint_model)
        env = gym.make(SMALL, max_steps=60)
        obs, _ = env.reset(seed=3)
        agent.reset(env, seed=seed)
        for _ in range(60):
            obs, *_ = env.step(agent.act(obs))
        return agent.goals

    assert goals(1) == goals(1) and len(goals(1)) >= 2


def test_a_policy_on_raw_continuous_actions_drives_directly(tmp_path):
    train_ppo(SMALL, 32, tmp_path, n_envs=1, env_kwargs={"max_steps": 40}, eval_every=10**9,
              progress_bar=False)  # fmt: skip
    agent = PPOAgent(model_dir=tmp_path)
    assert agent.waypoints is None
    env = gym.make(SMALL, max_steps=40)
    obs, _ = env.reset(seed=0)
    agent.reset(env, seed=0)
    for _ in range(5):
        action = agent.act(obs)
        assert env.action_space.contains(action)
        obs, *_ = env.step(action)
    discrete = gym.make("SfW-ExploreDiscrete-v0")
    discrete.reset(seed=0)
    with pytest.raises(ConfigError, match="action types"):
        agent.reset(discrete)


def test_an_env_with_other_observations_is_refused(waypoint_model):
    agent = PPOAgent(model_dir=waypoint_model)  # trained on SMALL's 36 x 36 images
    env = gym.make("SfW-Explore-v0")
    obs, _ = env.reset(seed=0)
    agent.reset(env)
    with pytest.raises(ConfigError, match="map_px"):
        agent.act(obs)


def test_missing_model_is_a_clear_error(tmp_path):
    with pytest.raises(ConfigError, match=r"model\.zip not found"):
        PPOAgent(model_dir=tmp_path)


def test_env_wrapper_entries_in_rl_zoo_forms():
    name = "sfw_gym.envs.waypoint.WaypointWrapper"
    assert wrapper_specs(None) == []
    assert wrapper_specs(name) == [(name, {})]
    specs = wrapper_specs([{name: {"grid_cells": 4}}, name])
    assert specs == [(name, {"grid_cells": 4}), (name, {})]
    with pytest.raises(ConfigError, match="env_wrapper"):
        wrapper_specs([{"a": 1, "b": 2}])
    with pytest.raises(ConfigError, match="env_wrapper"):
        wrapper_specs(3)


def test_waypoint_policy_scores_every_block_with_one_network():
    import torch

    from sfw_gym.agents.waypoint_policy import WaypointPolicy

    env = WaypointWrapper(gym.make(SMALL), grid_cells=3)
    policy = WaypointPolicy(env.observation_space, env.action_space, lambda _: 1e-3)
    obs, _ = env.reset(seed=0)
    batch = {k: torch.as_tensor(v)[None] for k, v in obs.items()}
    logits = policy.get_distribution(batch).distribution.logits[0]
    perm = torch.randperm(9)
    batch["blocks"] = batch["blocks"][:, perm]
    permuted = policy.get_distribution(batch).distribution.logits[0]
    # a block's logit depends on its own features only (softmax logits are shift-free)
    torch.testing.assert_close(permuted - permuted.mean(), (logits - logits.mean())[perm])

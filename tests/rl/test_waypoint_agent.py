"""WaypointPPOAgent: a waypoint policy acts through the agents' interface as in training."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import yaml

import sfw_gym  # noqa: F401
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.waypoint import WaypointWrapper
from sfw_gym.rl import WaypointPPOAgent
from sfw_gym.rl.training import train_ppo, wrapper_specs

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
    train_ppo(
        SMALL,
        64,
        out,
        hyperparams_path=hyper,
        env_kwargs={"max_steps": 120},
        eval_every=10**9,
        progress_bar=False,
    )
    return out


def test_agent_drives_the_raw_env_exactly_as_the_wrapper_did_in_training(waypoint_model):
    agent = WaypointPPOAgent(path=waypoint_model, deterministic=True)
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
        agent = WaypointPPOAgent(path=waypoint_model, deterministic=False)
        env = gym.make(SMALL, max_steps=60)
        obs, _ = env.reset(seed=3)
        agent.reset(env, seed=seed)
        for _ in range(60):
            obs, *_ = env.step(agent.act(obs))
        return agent.goals

    assert goals(1) == goals(1) and len(goals(1)) >= 2


@pytest.fixture(scope="module")
def continuous_model(tmp_path_factory):
    """A tiny policy on the env's own continuous actions."""
    out = tmp_path_factory.mktemp("ppo_continuous")
    train_ppo(
        SMALL, 32, out, n_envs=1, env_kwargs={"max_steps": 40}, eval_every=10**9, progress_bar=False
    )
    return out


def test_a_policy_on_raw_continuous_actions_drives_directly(continuous_model):
    agent = WaypointPPOAgent(path=continuous_model)
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


def run_ppo(agent: WaypointPPOAgent, env_id: str, steps: int, agent_seed: int) -> list:
    """The agent's actions over ``steps`` steps of ``env_id`` (env seed 3)."""
    env = gym.make(env_id)
    obs, _ = env.reset(seed=3)
    agent.reset(env, seed=agent_seed)
    actions = []
    for _ in range(steps):
        actions.append(np.asarray(agent.act(obs)).tolist())
        obs, *_ = env.step(actions[-1])
    return actions


def test_deterministic_shipped_policy_takes_the_most_likely_waypoint_whatever_the_agent_seed():
    import torch

    from sfw_gym.navigation import block_features, waypoint_goal_xy

    agent = WaypointPPOAgent(deterministic=True)  # the shipped waypoint policy
    env = gym.make("SfW-Explore-v0")
    obs, _ = env.reset(seed=3)
    agent.reset(env, seed=0)
    agent.act(obs)
    view = env.unwrapped.robot_view()
    blocks = block_features(view.belief_u8, view.grid, view.odometry_pose, 8)
    policy = agent.model.policy
    with torch.no_grad():
        tensor, _ = policy.obs_to_tensor({**obs, "blocks": blocks})
        probs = policy.get_distribution(tensor).distribution.probs[0].numpy()
    assert probs.max() < 0.5  # far from one-hot: a sampled waypoint would differ from the mode
    np.testing.assert_allclose(agent.goals[0], waypoint_goal_xy(view.grid, 8, probs.argmax()))
    assert run_ppo(agent, "SfW-Explore-v0", 150, 0) == run_ppo(agent, "SfW-Explore-v0", 150, 1)


def test_sampling_shipped_policy_repeats_itself_for_one_agent_seed_only():
    agent = WaypointPPOAgent(deterministic=False)
    first = run_ppo(agent, "SfW-Explore-v0", 150, 0)
    assert run_ppo(agent, "SfW-Explore-v0", 150, 0) == first
    assert run_ppo(agent, "SfW-Explore-v0", 150, 1) != first


def test_deterministic_continuous_policy_acts_with_its_mean_action(continuous_model):
    agent = WaypointPPOAgent(path=continuous_model, deterministic=True)
    env = gym.make(SMALL)
    obs, _ = env.reset(seed=0)
    agent.reset(env, seed=0)
    for _ in range(10):
        action = agent.act(obs)
        expected, _ = agent.model.predict(obs, deterministic=True)
        np.testing.assert_allclose(action, np.clip(expected, -1, 1), atol=1e-6)
        obs, *_ = env.step(action)
    assert run_ppo(agent, SMALL, 20, 0) == run_ppo(agent, SMALL, 20, 1)


def test_an_env_with_other_observations_is_refused(waypoint_model):
    agent = WaypointPPOAgent(path=waypoint_model)  # trained on SMALL's 36 x 36 images
    env = gym.make("SfW-Explore-v0")
    obs, _ = env.reset(seed=0)
    agent.reset(env)
    with pytest.raises(ConfigError, match="map_px") as error:
        agent.act(obs)
    message = str(error.value)
    assert str(waypoint_model) in message  # which policy
    assert "'map': (3, 36, 36)" in message and "'map': (3, 64, 64)" in message  # trained vs got
    assert agent.settings.path == str(waypoint_model)
    with pytest.raises(ConfigError, match=r"WaypointPPOAgent\.act\(obs\) needs the env's \(Dict\)"):
        agent.act(None)


def test_missing_model_is_a_clear_error(tmp_path):
    with pytest.raises(ConfigError, match=r"config\.yml not found; train one"):
        WaypointPPOAgent(path=tmp_path)
    (tmp_path / "config.yml").write_text("env_id: SfW-Explore-v0\n")
    with pytest.raises(ConfigError, match=r"no model found \(looked for SfW-Explore-v0\.zip"):
        WaypointPPOAgent(path=tmp_path)
    with pytest.raises(ConfigError, match=r"other\.zip not found; train one"):
        WaypointPPOAgent(path=tmp_path / "other.zip")


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

    from sfw_gym.rl.policy import WaypointPolicy

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


@pytest.mark.parametrize("env_id", ["SfW-ExploreDrift-v0", "SfW-ExploreLidar-v0"])
def test_the_shipped_policy_acts_on_envs_with_more_observations(env_id):
    """Extra observation keys (the drift env's fingerprint, the LiDAR) are not the policy's:
    it acts on its own keys, as the benchmark protocol's drift env needs."""
    actions = run_ppo(WaypointPPOAgent(), env_id, 80, 0)
    assert len(actions) == 80 and np.isfinite(actions).all()

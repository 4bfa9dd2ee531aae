"""The candidate-goal policy: masked pointer logits, a critic apart, behaviour cloning."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registration)
from tests.envs.test_goals import SMALL, explore_lite

torch = pytest.importorskip("torch")
sb3_contrib = pytest.importorskip("sb3_contrib")
from sfw_gym.rl.goal_policy import (  # noqa: E402
    Demonstrations,
    GoalsPolicy,
    HeadGradientNorms,
    behaviour_clone,
)


def model_on(env):
    return sb3_contrib.MaskablePPO(GoalsPolicy, env, n_steps=16, batch_size=16, seed=0)


def as_batch(observations):
    return {k: torch.as_tensor(np.stack([o[k] for o in observations])) for k in observations[0]}


def teacher_decisions(seeds):
    observations, actions, masks = [], [], []
    for seed in seeds:
        env = gym.make("SfW-ExploreGoals-v0", **SMALL)
        obs, _ = env.reset(seed=seed)
        done = False
        while not done:
            action = explore_lite(env)
            observations.append(obs)
            actions.append(action)
            masks.append(env.unwrapped.action_masks())
            obs, _, terminated, truncated, _ = env.step(action)
            done = terminated or truncated
    return observations, np.array(actions), np.array(masks)


def test_masked_candidates_get_no_probability():
    env = gym.make("SfW-ExploreGoals-v0", **SMALL, goals={"max_candidates": 64})
    obs, _ = env.reset(seed=0)
    mask = env.unwrapped.action_masks()
    assert not mask.all()
    policy = model_on(env).policy
    dist = policy.get_distribution(as_batch([obs]), action_masks=mask[None])
    probs = dist.distribution.probs[0].detach().numpy()
    assert np.all(probs[~mask] == 0.0) and probs[mask].sum() == pytest.approx(1.0)


def test_the_value_loss_does_not_reach_the_actor():
    env = gym.make("SfW-ExploreGoals-v0", **SMALL)
    obs, _ = env.reset(seed=0)
    policy = model_on(env).policy
    policy.predict_values(as_batch([obs])).sum().backward()
    heads = policy.heads
    assert all(p.grad is None for p in [*heads.scorer.parameters(), *heads.score.parameters()])
    assert any(p.grad is not None and p.grad.abs().sum() > 0 for p in heads.critic.parameters())


def test_each_heads_gradient_norm_is_logged_after_every_update():
    model = model_on(gym.make("SfW-ExploreGoals-v0", **SMALL))
    callback = HeadGradientNorms()
    model.learn(48, callback=callback)  # three rollouts of 16: two updates before the third
    assert len(callback.history) == 2
    for norms in callback.history:
        assert set(norms) == {"actor", "critic"} and min(norms.values()) > 0


@pytest.mark.episode
def test_behaviour_cloning_learns_the_teachers_choices():
    observations, actions, masks = teacher_decisions(range(4))
    held_out, actions_out, masks_out = teacher_decisions([10])
    policy = model_on(gym.make("SfW-ExploreGoals-v0", **SMALL)).policy
    losses = behaviour_clone(policy, Demonstrations(observations, actions, masks), epochs=30)
    assert losses[-1] < 0.5 * losses[0]
    with torch.no_grad():
        logits = policy.heads.forward_actor(policy.extract_features(as_batch(held_out)))
    chosen = logits.masked_fill(~torch.as_tensor(masks_out), -1e8).argmax(1).numpy()
    assert np.mean(chosen == actions_out) >= 0.8


def test_dagger_labels_the_learners_states_with_the_teachers_choices():
    from sfw_gym.rl import goal_policy

    policy = model_on(gym.make("SfW-ExploreGoals-v0", **SMALL)).policy  # untrained
    _, taught, _ = goal_policy.teacher_decisions("SfW-ExploreGoals-v0", SMALL, [3])
    np.testing.assert_array_equal(taught, teacher_decisions([3])[1])
    observations, labels, _ = goal_policy.teacher_decisions(
        "SfW-ExploreGoals-v0", SMALL, [3], learner=policy
    )
    env = gym.make("SfW-ExploreGoals-v0", **SMALL)  # replay: the learner drives
    obs, _ = env.reset(seed=3)
    taken = []
    for recorded, label in zip(observations, labels, strict=True):
        np.testing.assert_array_equal(obs["candidates"], recorded["candidates"])
        assert label == explore_lite(env)
        action, _ = policy.predict(
            obs, deterministic=True, action_masks=env.unwrapped.action_masks()
        )
        taken.append(int(action))
        obs, *_ = env.step(int(action))
    assert np.mean(np.array(taken) != labels) > 0.2  # other states than the teacher's own


def test_the_shared_trunk_ablation_lets_the_value_loss_reach_the_actors_layer():
    env = gym.make("SfW-ExploreGoals-v0", **SMALL)
    obs, _ = env.reset(seed=0)
    model = sb3_contrib.MaskablePPO(
        GoalsPolicy, env, n_steps=16, batch_size=16, seed=0, policy_kwargs={"shared_trunk": True}
    )
    policy = model.policy
    policy.predict_values(as_batch([obs])).sum().backward()
    heads = policy.heads
    assert any(p.grad is not None and p.grad.abs().sum() > 0 for p in heads.scorer.parameters())
    assert all(p.grad is None for p in heads.score.parameters())
    groups = policy.parameter_groups()
    assert {id(p) for p in heads.scorer.parameters()} <= {id(p) for p in groups["critic"]}

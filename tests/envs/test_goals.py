"""SfW-ExploreGoals-v0: masks, the reward's bookkeeping and ranking, bad input."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents.frontier import explore_lite_choice
from sfw_gym.core.errors import ConfigError

#: SfW-ExploreSmall-v0's plans and grid, for quick episodes.
SMALL = dict(generator={"area_m2": 45.0}, resolution_m=0.2, map_px=36, crop_px=36, max_steps=300)


def make(**kwargs):
    return gym.make("SfW-ExploreGoals-v0", **{**SMALL, **kwargs})


def explore_lite(env) -> int:
    """The frontier agent's choice on the menu (any valid goal when no frontier is reachable)."""
    choice = explore_lite_choice(env.unwrapped.menu)
    return int(np.argmax(env.unwrapped.action_masks())) if choice is None else choice


def random_choice(env, rng) -> int:
    return int(rng.choice(np.flatnonzero(env.unwrapped.action_masks())))


def episode_return(seed: int, policy) -> tuple[float, float]:
    env = make()
    env.reset(seed=seed)
    rng = np.random.default_rng(seed)
    total, done = 0.0, False
    while not done:
        _, reward, terminated, truncated, info = env.step(policy(env, rng))
        total += reward
        done = terminated or truncated
    return total, info["coverage"]


def test_masks_are_the_reachable_candidates():
    env = make()
    obs, _ = env.reset(seed=0)
    menu = env.unwrapped.menu
    mask = env.unwrapped.action_masks()
    assert mask.shape == (env.action_space.n,) and mask.any()
    assert np.array_equal(mask, obs["candidate_mask"].astype(bool))
    assert np.array_equal(mask[: len(menu)], menu.valid) and not mask[len(menu) :].any()
    assert np.all(obs["candidates"][len(menu) :] == 0.0)


def test_a_masked_action_turns_in_place_for_one_step():
    env = make(goals={"max_candidates": 64})  # more slots than candidates: the last is empty
    env.reset(seed=0)
    assert not env.unwrapped.action_masks()[-1]
    _, _, _, _, info = env.step(63)
    assert info["invalid_action"] and info["decision_steps"] == 1 and info["decision_m"] == 0.0


def test_the_robot_drives_towards_the_chosen_goal():
    env = make()
    env.reset(seed=1)
    u = env.unwrapped
    far = np.where(u.menu.valid, u.menu.feature("path_cost_m"), -1.0)
    i = int(np.argmax(far))  # the farthest reachable goal
    goal_xy = u.robot_view().grid.cell_to_world(u.menu.goal_rc[i])
    before = np.linalg.norm(u.robot_view().xy - goal_xy)
    _, _, _, _, info = env.step(i)
    assert info["decision_m"] > 0.1  # it drove (until the goal, a resolved target or a bump)
    assert np.linalg.norm(u.robot_view().xy - goal_xy) < before - 0.5 * info["decision_m"]


def test_reward_is_the_bits_gained_minus_the_costs_of_the_decision():
    env = make()
    env.reset(seed=2)
    cfg = env.unwrapped.config
    rng = np.random.default_rng(0)
    for _ in range(15):
        before = env.unwrapped.explore.mapper.entropy_bits
        _, reward, terminated, truncated, info = env.step(random_choice(env, rng))
        bits = (
            (before - info["entropy_bits"])
            - cfg.cost_per_m_bits * info["decision_m"]
            - cfg.cost_per_step_bits * info["decision_steps"]
            + cfg.goal_bonus_bits * terminated
        )
        assert reward == pytest.approx(bits / cfg.reward_scale_bits, abs=1e-9)
        if terminated or truncated:
            break


def test_reward_ranks_frontier_choices_above_random_ones():
    """A known-good policy (explore_lite's choice on the menu) earns more than random valid
    choices, seed by seed, and covers more."""
    for seed in range(3):
        good, good_cov = episode_return(seed, lambda env, rng: explore_lite(env))
        bad, bad_cov = episode_return(seed, random_choice)
        assert good > bad and good_cov > bad_cov


@pytest.mark.parametrize("action", [-1, 16, 1.5, np.array([1, 2])])
def test_bad_actions_name_the_valid_range(action):
    env = make()
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"goal action must be an integer in \[0, 16\)"):
        env.step(action)


def test_unknown_goal_settings_name_the_nearest_key():
    with pytest.raises(ConfigError, match="did you mean 'max_candidates'"):
        make(goals={"max_candidate": 8})


def test_maskable_ppo_never_picks_a_masked_goal():
    sb3_contrib = pytest.importorskip("sb3_contrib")
    env = make(max_steps=60)
    model = sb3_contrib.MaskablePPO("MultiInputPolicy", env, n_steps=16, batch_size=16, seed=0)
    model.learn(32)
    obs, _ = env.reset(seed=5)
    for _ in range(10):
        mask = env.unwrapped.action_masks()
        action, _ = model.predict(obs, action_masks=mask, deterministic=False)
        assert mask[int(action)]
        obs, _, terminated, truncated, _ = env.step(int(action))
        if terminated or truncated:
            obs, _ = env.reset()

"""SB3 on the native vector env: the adapter gives what DummyVecEnv of single envs gives."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registers the ids)

SMALL = "SfW-ExploreSmall-v0"


def test_the_adapter_gives_dummy_vec_envs_steps_resets_and_terminal_observations():
    from stable_baselines3.common.vec_env import DummyVecEnv

    from sfw_gym.rl.vec_env import SB3VecEnv

    # a budget per m² of each plan: the sub-envs' episodes end at different steps
    n, kwargs = 3, {"steps_per_m2": 1.0, "max_steps": 300}
    ours = SB3VecEnv(gym.make_vec(SMALL, num_envs=n, **kwargs))
    theirs = DummyVecEnv([lambda: gym.make(SMALL, **kwargs)] * n)
    for venv in (ours, theirs):
        venv.seed(7)
    a, b = ours.reset(), theirs.reset()
    rng = np.random.default_rng(0)
    dones, partial = 0, 0
    for _ in range(150):
        for key in b:
            np.testing.assert_array_equal(a[key], b[key])
        actions = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        ours.step_async(actions)
        theirs.step_async(actions)
        a, ra, da, ia = ours.step_wait()
        b, rb, db, ib = theirs.step_wait()
        np.testing.assert_array_equal(ra, rb)
        np.testing.assert_array_equal(da, db)
        partial += 0 < db.sum() < n
        for x, y, rx, ry in zip(ia, ib, ours.reset_infos, theirs.reset_infos, strict=True):
            assert x["coverage"] == y["coverage"] and x["floorplan"] == y["floorplan"]
            assert x["TimeLimit.truncated"] == y["TimeLimit.truncated"]
            assert rx.get("floorplan") == ry.get("floorplan")
            if "terminal_observation" in y:
                dones += 1
                for key in y["terminal_observation"]:
                    np.testing.assert_array_equal(
                        x["terminal_observation"][key], y["terminal_observation"][key]
                    )
    assert dones >= n and partial  # resets were compared, some of one sub-env alone


def test_each_sub_env_is_reset_with_its_own_options():
    from stable_baselines3.common.vec_env import DummyVecEnv

    from sfw_gym.rl.vec_env import SB3VecEnv

    ours = SB3VecEnv(gym.make_vec(SMALL, num_envs=3))
    theirs = DummyVecEnv([lambda: gym.make(SMALL)] * 3)
    for venv in (ours, theirs):
        venv.seed(2)
        venv.set_options([{"routers": 1}, {}, {"routers": 1}])
    a, b = ours.reset(), theirs.reset()
    for key in b:
        np.testing.assert_array_equal(a[key], b[key])
    heard = a["state"][:, 3]  # the second router's heard flag: no second router with one
    assert heard[0] == heard[2] == 0.0


@pytest.mark.episode
def test_ppo_learns_on_the_adapter():
    from stable_baselines3 import PPO

    from sfw_gym.rl.vec_env import SB3VecEnv

    venv = SB3VecEnv(gym.make_vec(SMALL, num_envs=4, max_steps=40))
    model = PPO("MultiInputPolicy", venv, n_steps=16, batch_size=32, n_epochs=1, seed=0)
    model.learn(128)
    assert model.num_timesteps == 128


def test_the_action_repeat_holds_each_action_and_sums_the_rewards():
    """ActionRepeat(env, 4).step equals four steps of the bare env with that action (reward
    summed, last observation); an episode's end cuts the repeat short."""
    from sfw_gym.envs.action_repeat import ActionRepeat

    wrapped, bare = ActionRepeat(gym.make(SMALL, max_steps=10), 4), gym.make(SMALL, max_steps=10)
    wrapped.reset(seed=3)
    bare.reset(seed=3)
    rng = np.random.default_rng(1)
    for expected_steps in (4, 4, 2):  # 10 steps: the last decision gets 2
        action = rng.uniform(-1, 1, 2).astype(np.float32)
        obs, reward, terminated, truncated, info = wrapped.step(action)
        total = 0.0
        for _ in range(expected_steps):
            bare_obs, r, bare_term, bare_trunc, _ = bare.step(action)
            total += r
        assert reward == pytest.approx(total, abs=1e-12)
        np.testing.assert_array_equal(obs["state"], bare_obs["state"])
        assert (terminated, truncated) == (bare_term, bare_trunc)
    assert truncated and info["max_steps"] == 10


def test_the_native_action_repeat_gives_what_the_wrapper_gives_per_env():
    from stable_baselines3.common.vec_env import DummyVecEnv

    from sfw_gym.envs.action_repeat import ActionRepeat
    from sfw_gym.rl.vec_env import SB3VecEnv

    n, kwargs = 2, {"max_steps": 40}  # a multiple of the repeat: episodes end on a decision
    ours = SB3VecEnv(gym.make_vec(SMALL, num_envs=n, **kwargs), action_repeat=4)
    theirs = DummyVecEnv([lambda: ActionRepeat(gym.make(SMALL, **kwargs), 4)] * n)
    for venv in (ours, theirs):
        venv.seed(11)
    a, b = ours.reset(), theirs.reset()
    rng = np.random.default_rng(2)
    ends = 0
    for _ in range(25):  # 100 env steps: two episodes and a half each
        np.testing.assert_array_equal(a["map"], b["map"])
        actions = rng.uniform(-1, 1, (n, 2)).astype(np.float32)
        a, ra, da, ia = ours.step(actions)
        b, rb, db, ib = theirs.step(actions)
        np.testing.assert_allclose(ra, rb, rtol=1e-6)
        np.testing.assert_array_equal(da, db)
        for x, y in zip(ia, ib, strict=True):  # the last step's info, the terminal observation
            assert x["coverage"] == y["coverage"] and x["max_steps"] == y["max_steps"]
            assert ("terminal_observation" in x) == ("terminal_observation" in y)
            if "terminal_observation" in y:
                np.testing.assert_array_equal(
                    x["terminal_observation"]["state"], y["terminal_observation"]["state"]
                )
        ends += int(db.sum())
    assert ends == 2 * n
    with pytest.raises(Exception, match="action_repeat must be an integer"):
        SB3VecEnv(gym.make_vec(SMALL, num_envs=n), action_repeat=0)

"""The native vector env (``gym.make_vec``'s default for every id): each sub-env is the single env
with its seed, autoresets as Gymnasium 1.x's NEXT_STEP, and a bad action names its sub-env."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registers the ids)
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.vector import SfWVectorEnv, batch_infos

SMALL = "SfW-ExploreSmall-v0"


def single_run(env_id: str, seed: int, actions: list, **kwargs) -> tuple[list, gym.Env]:
    """The single env driven by ``actions`` with NEXT_STEP autoreset: per step (obs, reward,
    terminated, truncated, info), and the env."""
    env = gym.make(env_id, **kwargs)
    obs, _ = env.reset(seed=seed)
    out, done = [], False
    for action in actions:
        if done:
            obs, info = env.reset()
            reward, terminated, truncated = 0.0, False, False
        else:
            obs, reward, terminated, truncated, info = env.step(action)
        out.append((obs, reward, terminated, truncated, info))
        done = terminated or truncated
    return out, env


@pytest.mark.parametrize(
    ("env_id", "steps", "kwargs"),
    [
        (SMALL, 1000, {"max_steps": 120}),  # eight episodes a sub-env, wall contacts
        pytest.param(
            SMALL, 1000, {"max_steps": 150, "pose_source": "true"}, marks=pytest.mark.slow
        ),
        pytest.param(  # odometry noise: normals drawn ahead for the robot and the radio
            SMALL,
            1000,
            {"robot": {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02}},
            marks=pytest.mark.slow,
        ),
        pytest.param("SfW-ExploreDiscrete-v0", 1000, {}, marks=pytest.mark.slow),
        # one episode longer than the histories' first capacity (1,024): they grow mid-batch
        pytest.param(SMALL, 1100, {"max_steps": 1100}, marks=pytest.mark.slow),
        pytest.param("SfW-ExploreGoals-v0", 30, {}, marks=pytest.mark.episode),  # not batched
    ],
)
def test_each_sub_env_is_the_single_env_with_its_seed_through_autoresets(env_id, steps, kwargs):
    """Observations, rewards, ends and infos, bit for bit, and the generators and robots left
    in the same state; the explore sub-envs step together (batch_step), near walls included."""
    seeds = [4, 9, 13]
    vec = gym.make_vec(env_id, num_envs=len(seeds), **kwargs)
    assert isinstance(vec, SfWVectorEnv)
    assert vec._batched == (env_id != "SfW-ExploreGoals-v0")  # Goals: one by one in Python
    vec.action_space.seed(0)
    actions = [vec.action_space.sample() for _ in range(steps)]
    vec.reset(seed=seeds)
    got = [vec.step(a) for a in actions]
    ends = 0
    runs, singles = [], []
    for i, seed in enumerate(seeds):
        expected, env = single_run(env_id, seed, [a[i] for a in actions], **kwargs)
        runs.append(expected)
        singles.append(env)
        for (obs, reward, terminated, truncated, _), step in zip(expected, got, strict=True):
            for key in obs:
                np.testing.assert_array_equal(step[0][key][i], obs[key])
            assert (step[1][i], step[2][i], step[3][i]) == (reward, terminated, truncated)
            ends += terminated or truncated
    for t, step in enumerate(got):
        _same(step[4], batch_infos([run[t][4] for run in runs]))
    for env, sub in zip(singles, vec.envs, strict=True):
        assert sub.np_random.bit_generator.state == env.unwrapped.np_random.bit_generator.state
        if vec._batched:  # the state written back: robot, counters, histories
            assert sub.unwrapped.scene.robot.pose == env.unwrapped.scene.robot.pose
            assert sub.unwrapped.collisions == env.unwrapped.collisions
            mine, theirs = sub.unwrapped.robot_view(), env.unwrapped.robot_view()
            np.testing.assert_array_equal(mine.rssi_history, theirs.rssi_history)
            np.testing.assert_array_equal(mine.odometry_trajectory, theirs.odometry_trajectory)
            np.testing.assert_array_equal(sub.unwrapped.trajectory, env.unwrapped.trajectory)
    if vec._batched:
        assert sum(env.unwrapped.collisions for env in singles) > 0  # contacts were compared
    long_episode = kwargs.get("max_steps", 0) > steps - 10
    assert ends >= (len(seeds) if env_id == SMALL and not long_episode else 0)  # autoresets
    vec.close()


def test_a_bad_action_or_option_names_its_sub_env():
    vec = gym.make_vec(SMALL, num_envs=3)
    vec.reset(seed=0)
    actions = np.zeros((3, 2), np.float32)
    actions[1, 0] = np.nan
    with pytest.raises(ConfigError, match=r"^sub-env 1: action must be finite"):
        vec.step(actions)
    with pytest.raises(ConfigError, match=r"one action per sub-env \(3\), got 2"):
        vec.step(actions[:2])
    with pytest.raises(ConfigError, match=r"^sub-env 0: reset options: unknown key 'nope'"):
        vec.reset(options={"nope": 1})
    with pytest.raises(ConfigError, match="num_envs must be an int >= 1"):
        gym.make_vec(SMALL, num_envs=0)


def _same(a, b) -> None:
    assert list(a) == list(b)  # keys and their order
    for key in a:
        if isinstance(a[key], dict):
            _same(a[key], b[key])
        else:
            assert a[key].dtype == b[key].dtype and a[key].shape == b[key].shape, key
            if a[key].dtype != object:
                np.testing.assert_array_equal(a[key], b[key], err_msg=key)
                continue
            for x, y in zip(a[key], b[key], strict=True):  # arrays of arrays, one by one
                np.testing.assert_array_equal(x, y, err_msg=key)


def test_infos_are_batched_as_gymnasiums_vector_envs_batch_them():
    from sfw_gym.envs.vector import batch_infos

    env = gym.make(SMALL, max_steps=5)
    _, first = env.reset(seed=0)
    for _ in range(5):
        *_, last = env.step(env.action_space.sample())
    assert "summary" in last  # a nested dict, at the episode's end
    infos = [first, None, last, {"other": "text", "final_obs": {"map": np.zeros(2)}}]
    reference = gym.make_vec(SMALL, num_envs=len(infos))
    expected: dict = {}
    for i, info in enumerate(infos):
        if info is not None:
            expected = reference._add_info(expected, info, i)
    _same(batch_infos(infos), expected)


def test_a_batch_handed_out_is_never_written_again():
    vec = gym.make_vec(SMALL, num_envs=2)
    first, _ = vec.reset(seed=0)
    stepped = vec.step(vec.action_space.sample())[0]
    batches = [first, stepped]
    kept = [{key: rows.copy() for key, rows in batch.items()} for batch in batches]
    vec.reset(seed=5, options={"reset_mask": np.array([True, False])})  # row 1 stays as stepped
    vec.step(vec.action_space.sample())
    for batch, copy in zip(batches, kept, strict=True):
        for key in copy:
            np.testing.assert_array_equal(batch[key], copy[key])
    with pytest.raises(ConfigError, match="at least one True"):
        vec.reset(options={"reset_mask": np.array([False, False])})


def test_a_sub_env_restored_from_its_snapshot_continues_as_it_did():
    """The resume state of ``sfw-gym train`` on the native env: a snapshot taken mid-episode
    (normals drawn ahead, state not yet written back) and restored replays the same steps."""
    vec = gym.make_vec(SMALL, num_envs=2, max_steps=60)
    vec.reset(seed=[1, 2])
    vec.action_space.seed(0)
    actions = [vec.action_space.sample() for _ in range(90)]
    for a in actions[:20]:
        vec.step(a)
    blob = vec.snapshot(1)
    first = [vec.step(a)[0]["state"][1].copy() for a in actions[20:]]
    vec.restore(1, blob)
    again = [vec.step(a)[0]["state"][1].copy() for a in actions[20:]]
    np.testing.assert_array_equal(np.array(first), np.array(again))


def test_a_sub_env_stepped_from_outside_the_batch_continues_as_the_single_env():
    """``call("step", …)`` steps each sub-env by itself (state written back first, read after):
    the batched steps that follow still give the single env's observations."""
    action = np.array([0.8, 0.3], np.float32)
    vec = gym.make_vec(SMALL, num_envs=2)
    singles = [gym.make(SMALL) for _ in range(2)]
    vec.reset(seed=[5, 6])
    for seed, env in zip([5, 6], singles, strict=True):
        env.reset(seed=seed)
    for t in range(40):
        if t == 20:
            vec.call("step", action)
            for env in singles:
                env.step(action)
        obs = vec.step(np.stack([action, action]))[0]
        for i, env in enumerate(singles):
            expected = env.step(action)[0]
            for key in expected:
                np.testing.assert_array_equal(obs[key][i], expected[key])

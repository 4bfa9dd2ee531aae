"""One suite over every registered env id: API, determinism, pickling, vectors, rendering."""

from __future__ import annotations

import copy
import pickle
import warnings

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env as gym_check_env

import sfw_gym
from sfw_gym.core.errors import ConfigError

ENV_IDS = sorted(sfw_gym.ENV_IDS)
#: Ids whose one action is many env steps (a goal, a region): shorter rollouts check the same.
MACRO_ACTION_IDS = ("SfW-ExploreGoals-v0", "SfW-ExploreRegions-v0")
#: Ids whose reset costs seconds (a survey and its GP gridmaps): the checkers, rendering and
#: repeats of these run in CI's full suite, not the quick loop.
SLOW_RESET_IDS = ("SfW-Localize-v0",)
#: Ids that are SfW-Explore-v0 with other radio, budget or odometry settings: the quick loop
#: checks them by their rollout determinism, the full suite by everything.
KWARG_VARIANT_IDS = (
    "SfW-ExploreThick-v0",
    "SfW-ExploreResidential-v0",
    "SfW-ExploreFull-v0",
    "SfW-ExploreDrift-v0",
)


def env_ids(heavy: tuple[str, ...] = SLOW_RESET_IDS + KWARG_VARIANT_IDS) -> list:
    """Every id; those in ``heavy`` marked ``episode`` (run by CI's full suite)."""
    return [pytest.param(i, marks=pytest.mark.episode) if i in heavy else i for i in ENV_IDS]


def _rollout_steps(env_id: str) -> int:
    return 10 if env_id in MACRO_ACTION_IDS else 60


#: Warnings we accept from the checkers, with why.
WARNING_WHITELIST = (
    # SB3's checker notes that image observations should be channel-last or -first of size ≥ 36;
    # ours are channel-first and ≥ 36: SB3 still prints a generic hint for non-square Box spaces.
    "It seems that your observation",
    # SfW-ExploreGoals-v0's ``candidates`` is K rows of features, read row by row by a
    # per-candidate scorer (a custom policy), not flattened.
    "Your observation candidates has an unconventional shape",
    # SfW-ExploreRegions-v0's ``candidate_px``: each candidate's (row, col) on the map image.
    "Your observation candidate_px has an unconventional shape",
)


def _rollout(env_id: str, seed: int, n: int) -> list:
    env = gym.make(env_id)
    env.action_space.seed(seed)
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for _ in range(n):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        out.append((obs, reward, terminated, truncated, info["true_pose"], info["coverage"]))
        if terminated or truncated:
            obs, _ = env.reset()
    env.close()
    return out


def _assert_same(a, b) -> None:
    if isinstance(a, dict):
        assert a.keys() == b.keys()
        for k in a:
            _assert_same(a[k], b[k])
    elif isinstance(a, tuple | list):
        assert len(a) == len(b)
        for x, y in zip(a, b, strict=True):
            _assert_same(x, y)
    else:
        np.testing.assert_array_equal(a, b)


def _assert_no_unlisted_warnings(check, env) -> None:
    """Run a checker on env; fail on any warning not in WARNING_WHITELIST."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check(env)
    bad = [str(w.message) for w in caught if not str(w.message).startswith(WARNING_WHITELIST)]
    assert not bad, bad


class TestEveryEnv:
    @pytest.mark.parametrize("env_id", env_ids())
    def test_gymnasium_check_env(self, env_id):
        _assert_no_unlisted_warnings(
            lambda env: gym_check_env(env, skip_render_check=False), gym.make(env_id).unwrapped
        )

    @pytest.mark.parametrize("env_id", env_ids())
    def test_sb3_check_env(self, env_id):
        from stable_baselines3.common.env_checker import check_env as sb3_check_env

        _assert_no_unlisted_warnings(
            lambda env: sb3_check_env(env, warn=True), gym.make(env_id).unwrapped
        )

    @pytest.mark.parametrize("env_id", env_ids(heavy=()))
    def test_same_seed_same_rollout(self, env_id):
        n = _rollout_steps(env_id)
        _assert_same(_rollout(env_id, 3, n), _rollout(env_id, 3, n))

    @pytest.mark.parametrize("env_id", env_ids())
    def test_different_seeds_differ(self, env_id):
        a, b = _rollout(env_id, 1, 5), _rollout(env_id, 2, 5)
        assert not np.array_equal(a[0]["map"], b[0]["map"]) or not np.array_equal(
            a[-1][4], b[-1][4]
        )

    @pytest.mark.parametrize("env_id", env_ids())
    def test_pickle_round_trip_continues_identically(self, env_id):
        env = gym.make(env_id)
        env.reset(seed=5)
        env.action_space.seed(0)  # reproducible: see the known divergence below
        for _ in range(10):
            env.step(env.action_space.sample())
        clone = pickle.loads(pickle.dumps(env))
        env.action_space.seed(9)
        actions = [env.action_space.sample() for _ in range(20)]
        for action in actions:
            a = env.step(action)
            b = clone.step(action)
            _assert_same(a[:4], b[:4])
            np.testing.assert_array_equal(a[4]["true_pose"], b[4]["true_pose"])

    @pytest.mark.parametrize("env_id", env_ids())
    def test_the_native_vector_env_steps_each_sub_env_as_the_single_env(self, env_id):
        vec = gym.make_vec(env_id, num_envs=2)
        assert type(vec).__name__ == "SfWVectorEnv"
        vec.action_space.seed(1)
        actions = [vec.action_space.sample() for _ in range(3)]
        vec.reset(seed=[3, 4])
        batches = [vec.step(a)[0] for a in actions]
        for i, seed in enumerate((3, 4)):
            env = gym.make(env_id)
            env.reset(seed=seed)
            for action, batch in zip(actions, batches, strict=True):
                obs = env.step(action[i])[0]
                for key in obs:
                    np.testing.assert_array_equal(batch[key][i], obs[key])

    @pytest.mark.parametrize("env_id", env_ids())
    def test_observations_fit_multi_input_policy(self, env_id):
        env = gym.make(env_id)
        obs, _ = env.reset(seed=0)
        assert env.observation_space.contains(obs)
        for key in ("map", "local"):
            img = obs[key]
            assert img.dtype == np.uint8 and img.shape[0] <= 3 and min(img.shape[1:]) >= 36

    @pytest.mark.parametrize("env_id", env_ids())
    @pytest.mark.parametrize(
        "mode", ["rgb_array", pytest.param("human", marks=pytest.mark.episode)]
    )
    def test_render_modes_headless(self, env_id, mode, monkeypatch):
        monkeypatch.setenv("MPLBACKEND", "Agg")
        env = gym.make(env_id, render_mode=mode)
        env.reset(seed=0)
        for _ in range(3):
            env.step(env.action_space.sample())
        frame = env.render()
        if mode == "rgb_array":
            assert frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3
            rgb = frame.astype(np.uint32)
            colours = np.unique((rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2])
            assert frame.shape[0] >= 200 and len(colours) > 4
        else:
            assert frame is None
        env.close()


def test_gymnasium_async_vector_env():
    envs = gym.vector.AsyncVectorEnv([lambda: gym.make("SfW-ExploreSmall-v0")] * 2)
    obs, info = envs.reset(seed=[1, 2])
    assert obs["map"].shape[0] == 2
    for _ in range(5):
        obs, rewards, _terminated, _truncated, info = envs.step(envs.action_space.sample())
    assert rewards.shape == (2,) and "coverage" in info
    envs.close()


@pytest.mark.episode
def test_sb3_subproc_vec_env():
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import SubprocVecEnv

    # SB3 starts workers with forkserver: they have not imported sfw_gym, so the id names its
    # module (Gymnasium imports it before making the env).
    venv = make_vec_env("sfw_gym:SfW-ExploreSmall-v0", n_envs=2, seed=0, vec_env_cls=SubprocVecEnv)
    venv.reset()
    for _ in range(5):
        obs, _rewards, _dones, infos = venv.step(np.array([venv.action_space.sample()] * 2))
    assert obs["state"].shape[0] == 2 and len(infos) == 2
    venv.close()


def test_registered_without_import():
    env = gym.make("sfw_gym:SfW-Explore-v0")
    assert env.unwrapped.spec.id == "SfW-Explore-v0"


class TestBadInput:
    @pytest.fixture
    def env(self):
        env = gym.make("SfW-ExploreSmall-v0")
        env.reset(seed=0)
        return env

    @pytest.mark.parametrize(
        "action, match",
        [
            ([np.nan, 0.0], "finite"),
            ([np.inf, 0.0], "finite"),
            ([0.0, 0.0, 0.0], "shape"),
            (np.zeros((2, 1)), "shape"),
        ],
    )
    def test_bad_continuous_actions_raise(self, env, action, match):
        pose = env.unwrapped.scene.robot.pose
        with pytest.raises(ValueError, match=match):
            env.unwrapped.step(np.array(action, dtype=np.float64))
        assert env.unwrapped.scene.robot.pose == pose  # nothing moved

    def test_out_of_range_actions_are_clipped(self, env):
        u = env.unwrapped
        u.reset(seed=1)
        a = u.step(np.array([5.0, -7.0]))
        u.reset(seed=1)
        b = u.step(np.array([1.0, -1.0]))
        np.testing.assert_array_equal(a[4]["true_pose"], b[4]["true_pose"])
        assert np.isfinite(a[4]["true_pose"]).all()

    def test_bad_discrete_actions_raise(self):
        env = gym.make("SfW-ExploreDiscrete-v0")
        env.reset(seed=0)
        for action in (3, -1, 1.5, np.nan):
            with pytest.raises(ValueError, match="action"):
                env.unwrapped.step(action)

    def test_unknown_reset_option(self, env):
        with pytest.raises(ConfigError, match=r"reset options: unknown key 'colour'"):
            env.reset(options={"colour": "red"})
        with pytest.raises(ConfigError, match=r"unknown key 'start'; did you mean 'start_pose'"):
            env.reset(options={"start": (1.0, 1.0, 0.0)})

    def test_router_in_a_wall(self, env):
        with pytest.raises(ConfigError, match=r"router 0 .* (inside a wall|outside the building)"):
            env.reset(options={"routers": [[-50.0, -50.0]]})

    def test_too_many_routers(self, env):
        with pytest.raises(ConfigError, match="router"):
            env.reset(options={"routers": 5})

    @pytest.mark.parametrize(
        "options, match",
        [
            ({"routers": [[1.0, 1.0]] * 5}, "5 positions given"),
            ({"routers": 0}, r"a count must be in \[1, 2\]"),
            ({"start_pose": (1.0, float("nan"), 0.0)}, "three finite numbers"),
            ({"start_pose": (1.0, 2.0)}, "three finite numbers"),
            ({"start_pose": (-40.0, -40.0, 0.0)}, "not in the free space"),
            ({"floorplan": 2.5}, "floorplan must be a Floorplan"),
        ],
    )
    def test_bad_reset_options_name_the_option(self, env, options, match):
        with pytest.raises(ConfigError, match=match):
            env.reset(options=options)

    @pytest.mark.parametrize(
        "kwargs, match",
        [
            ({"crop_px": 10}, r"^crop_px"),
            ({"max_steps": 10**7 + 1}, r"^max_steps"),
            ({"max_steps": 1.5}, r"^max_steps"),
            ({"max_steps": True}, r"^max_steps"),
            ({"radio": "loud"}, r"^radio must be a dict of overrides, got str"),
        ],
    )
    def test_bad_kwarg_values_name_the_kwarg(self, kwargs, match):
        with pytest.raises(ConfigError, match=match):
            gym.make("SfW-ExploreSmall-v0", **kwargs)

    def test_bad_kwargs(self):
        with pytest.raises(ConfigError, match="action_type"):
            gym.make("SfW-Explore-v0", action_type="teleport")
        with pytest.raises(ConfigError, match=r"(?i)radio"):
            gym.make("SfW-Explore-v0", radio={"walls_are_lava": True})
        with pytest.raises(ConfigError, match="preset"):
            gym.make("SfW-Explore-v0", radio_preset="swamp")
        with pytest.raises(ConfigError, match="resolution_m"):
            gym.make("SfW-Explore-v0", resolution_m=0.0)

    def test_step_before_reset(self):
        env = gym.make("SfW-ExploreSmall-v0").unwrapped
        with pytest.raises(gym.error.ResetNeeded):
            env.step(np.zeros(2))


@pytest.mark.slow
def test_a_clone_is_the_same_env_on_a_thousand_random_action_prefixes():
    """Pickled and deep-copied envs continue exactly as the original, wall contacts included
    (pymunk's cached contact state is rebuilt every step near a wall)."""
    rng = np.random.default_rng(0)
    envs = {
        "SfW-ExploreSmall-v0": gym.make("SfW-ExploreSmall-v0"),
        "SfW-ExploreDiscrete-v0": gym.make(
            "SfW-ExploreDiscrete-v0", resolution_m=0.2, map_px=36, crop_px=36
        ),
    }
    contacts = 0
    for i in range(1000):
        env = envs["SfW-ExploreSmall-v0" if i % 2 else "SfW-ExploreDiscrete-v0"]
        env.reset(seed=int(rng.integers(50)))
        env.action_space.seed(i)
        for _ in range(int(rng.integers(0, 40))):
            env.step(env.action_space.sample())
        clone = pickle.loads(pickle.dumps(env)) if i % 4 < 2 else copy.deepcopy(env)
        start = env.unwrapped.collisions
        for _ in range(15):
            action = env.action_space.sample()
            a, b = env.step(action), clone.step(action)
            np.testing.assert_array_equal(a[4]["true_pose"], b[4]["true_pose"], err_msg=str(i))
            assert a[1] == b[1], i
        contacts += env.unwrapped.collisions > start
    assert contacts > 100  # the prefixes reach walls


def test_env_classes_are_reachable_lazily_from_the_envs_package():
    import sfw_gym.envs as envs
    from sfw_gym.envs.explore import SfWExploreEnv
    from sfw_gym.envs.waypoint import WaypointWrapper

    assert envs.SfWExploreEnv is SfWExploreEnv and envs.WaypointWrapper is WaypointWrapper
    with pytest.raises(AttributeError):
        envs.NoSuchEnv  # noqa: B018


def test_human_render_mode_draws_every_step(monkeypatch):
    env = gym.make("SfW-ExploreSmall-v0", render_mode="human")
    env.reset(seed=0)
    drawn = []
    monkeypatch.setattr(env.unwrapped, "render", lambda: drawn.append(1))
    for _ in range(3):
        env.step(env.action_space.sample())
    assert len(drawn) == 3

"""Fuzz the env's inputs: ``gym.make`` kwargs, the radio / robot / mapper / generator overrides,
``reset`` options and actions. Each case ends in a working env or one clean ``SfwGymError``;
an accepted value is the value the env uses (nothing silently replaced)."""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
from hypothesis import given
from hypothesis import strategies as st

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.mapping import MapperConfig
from sfw_gym.world import RadioConfig, RobotConfig
from sfw_gym.world.generator import GeneratorConfig
from tests.fuzz.conftest import outcome
from tests.fuzz.strategies import junk, near, numbers

SMALL = "SfW-ExploreSmall-v0"
KWARGS = {
    "action_type": st.sampled_from(["continuous", "discrete", "Continuous", ""]) | junk,
    "n_routers": st.integers(-2, 20) | junk,
    "radio_preset": st.sampled_from(["default", "thick", "residential", "x"]) | junk,
    "radio_band": st.sampled_from(["2.4", "5", 2.4, 5]) | junk,
    "resolution_m": near(0.2),
    "map_px": st.integers(0, 600) | junk,
    "crop_px": st.integers(0, 600) | junk,
    "coverage_target": near(0.9),
    "collision_penalty": near(0.1),
    "reward_scale": near(0.01),
    "max_steps": st.integers(-5, 50) | junk,
    "steps_per_m2": near(10.0) | st.none(),
    "floorplan": st.integers(-3, 3) | junk,
    "render_mode": st.sampled_from([None, "rgb_array", "human", "x"]),
    "no_such_kwarg": junk,
}


def _run(env_id: str, steps: int = 3, options=None, actions=None, **kwargs) -> gym.Env:
    env = gym.make(env_id, **kwargs)
    try:
        obs, _ = env.reset(seed=0, options=options)
        assert env.observation_space.contains(obs)
        for i in range(steps):
            action = env.action_space.sample() if actions is None else actions[i % len(actions)]
            obs, reward, *_ = env.step(action)
            assert np.isfinite(reward) and env.observation_space.contains(obs)
    finally:
        env.close()
    return env


@given(st.fixed_dictionaries({}, optional=KWARGS))
def test_make_kwargs(kwargs):
    def make() -> None:
        env = _run(SMALL, **kwargs)
        cfg = env.unwrapped.config.explore  # an accepted setting is the one used
        for key in ("action_type", "n_routers", "map_px", "crop_px", "max_steps"):
            if key in kwargs:
                assert getattr(cfg, key) == kwargs[key], key

    outcome("env kwargs", make)


def _override_strategy(config_cls) -> st.SearchStrategy:
    fields = {}
    for f in dataclasses.fields(config_cls):
        default = f.default if f.default is not dataclasses.MISSING else None
        if isinstance(default, bool) or not isinstance(default, (int, float)):
            fields[f.name] = junk
        else:
            fields[f.name] = near(float(default))
    fields["no_such_field"] = junk
    return st.fixed_dictionaries({}, optional=fields)


@given(
    st.sampled_from(["radio", "robot", "mapper", "generator"]).flatmap(
        lambda name: st.tuples(
            st.just(name),
            _override_strategy(
                {
                    "radio": RadioConfig,
                    "robot": RobotConfig,
                    "mapper": MapperConfig,
                    "generator": GeneratorConfig,
                }[name]
            ),
        )
    )
)
def test_config_overrides(named):
    name, overrides = named
    outcome(f"{name} overrides", lambda: _run(SMALL, **{name: overrides}))


points = st.tuples(numbers, numbers).map(list) | st.tuples(
    st.floats(-5, 20), st.floats(-5, 20)
).map(list)


@given(
    st.fixed_dictionaries(
        {},
        optional={
            "floorplan": st.integers(-3, 5) | st.text(max_size=10) | junk,
            "routers": st.integers(-1, 4) | st.lists(points, max_size=3) | junk,
            "start_pose": st.tuples(st.floats(-5, 20), st.floats(-5, 20), st.floats(-7, 7)).map(
                list
            )
            | st.lists(numbers, max_size=4)
            | junk,
            "no_such_option": junk,
        },
    )
)
def test_reset_options(options):
    outcome("reset options", lambda: _run(SMALL, options=options))


actions = st.lists(numbers, min_size=0, max_size=3).map(np.array) | junk


@given(
    st.sampled_from([SMALL, "SfW-ExploreDiscrete-v0"]), st.lists(actions, min_size=1, max_size=3)
)
def test_actions(env_id, taken):
    kwargs = {} if env_id == SMALL else {"resolution_m": 0.2, "map_px": 36, "crop_px": 36}
    outcome("actions", lambda: _run(env_id, steps=len(taken), actions=taken, **kwargs))

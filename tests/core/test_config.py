"""The one configuration mechanism: ranges declared on fields, checked in one place."""

from __future__ import annotations

import math
from dataclasses import FrozenInstanceError, dataclass

import gymnasium as gym
import pytest

import sfw_gym  # noqa: F401  (registers the envs)
from sfw_gym import ConfigError
from sfw_gym.core.config import Config, Range, setting
from sfw_gym.mapping import MapperConfig
from sfw_gym.world import RadioConfig, RobotConfig
from sfw_gym.world.generator import GeneratorConfig


@dataclass(frozen=True)
class Toy(Config):
    rate: float = setting(0.5, gt=0.0, le=1.0)
    count: int = setting(3, integer=True, ge=1)
    mode: str = setting("a", choices=("a", "b"))
    limit: float | None = setting(None, optional=True, ge=0.0)


@pytest.mark.parametrize(
    ("rng", "text"),
    [
        (Range(ge=1, le=32, integer=True), "an int in [1, 32]"),
        (Range(gt=0.5, lt=1.0), "a finite number in (0.5, 1)"),
        (Range(gt=0.0), "a finite number > 0"),
        (Range(le=10**7, integer=True), "an int <= 10,000,000"),
        (Range(ge=0.0, optional=True), "None or a finite number >= 0"),
        (Range(choices=("x", "y")), "one of ('x', 'y')"),
    ],
)
def test_ranges_describe_themselves(rng, text):
    assert rng.describe() == text


def test_values_are_checked_and_normalised():
    toy = Toy(rate=1, count=2, limit=3)
    assert toy.rate == 1.0 and type(toy.rate) is float
    assert type(toy.count) is int and toy.limit == 3.0
    with pytest.raises(FrozenInstanceError):
        toy.rate = 0.2  # type: ignore[misc]
    bad = [
        ({"rate": 0.0}, r"^Toy\.rate must be a finite number in \(0, 1\], got 0\.0$"),
        ({"rate": math.nan}, r"^Toy\.rate must be"),
        ({"rate": True}, r"^Toy\.rate must be"),  # a bool is not a number here
        ({"count": 2.0}, r"^Toy\.count must be an int >= 1, got 2\.0$"),
        ({"mode": "c"}, r"^Toy\.mode must be one of \('a', 'b'\), got 'c'$"),
        ({"limit": -1}, r"^Toy\.limit must be None or a finite number >= 0, got -1$"),
    ]
    for kwargs, message in bad:
        with pytest.raises(ConfigError, match=message):
            Toy(**kwargs)


def test_from_dict_names_the_nearest_valid_key():
    assert Toy.from_dict({"rate": 0.25}).rate == 0.25
    assert Toy.from_dict(None) == Toy()
    with pytest.raises(ConfigError, match=r"^toy: unknown key 'rates'; did you mean 'rate'\?"):
        Toy.from_dict({"rates": 0.25}, "toy")
    with pytest.raises(ConfigError, match=r"^toy must be a dict of overrides, got list"):
        Toy.from_dict([("rate", 0.25)], "toy")  # type: ignore[arg-type]


def test_choices_compare_by_type_too():
    with pytest.raises(ConfigError, match="extend_past_robot"):
        MapperConfig(extend_past_robot=1)  # type: ignore[arg-type]


@pytest.mark.parametrize("cls", [MapperConfig, RadioConfig, RobotConfig, GeneratorConfig])
def test_every_subsystem_config_round_trips_through_a_dict(cls):
    config = cls()
    assert cls.from_dict(config.to_dict()) == config


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"map_pix": 64}, r"SfW-Explore kwargs: unknown key 'map_pix'; did you mean 'map_px'"),
        ({"robot": {"radius": 0.2}}, r"robot: unknown key 'radius'; did you mean 'radius_m'"),
        ({"radio": {"noise_db": 1}}, r"radio: unknown key 'noise_db'"),
        ({"mapper": {"max_kk": 2}}, r"mapper: unknown key 'max_kk'; did you mean 'max_k'"),
        ({"generator": {"area": 60}}, r"generator: unknown key 'area'; did you mean 'area_m2'"),
        ({"generator": {"area_m2": 5}}, r"GeneratorConfig\.area_m2 must be"),  # at make time
        ({"max_steps": 0}, r"^max_steps must be an int in \[1, 10,000,000\], got 0$"),
        ({"reward_scale": -1.0}, r"^reward_scale must be"),
        ({"render_size": (10, 10)}, r"render_size must be"),
    ],
)
def test_env_kwargs_are_checked_when_the_env_is_made(kwargs, message):
    with pytest.raises(ConfigError, match=message):
        gym.make("SfW-Explore-v0", **kwargs)


def test_env_config_dict_holds_every_subsystem():
    env = gym.make("SfW-ExploreSmall-v0")
    cfg = env.unwrapped.config_dict()
    assert cfg["map_px"] == 36 and cfg["generator"]["area_m2"] == 45.0
    assert {"radio", "robot", "mapper", "reward_scale", "coverage_target"} <= set(cfg)
    assert RobotConfig.from_dict(cfg["robot"]) == env.unwrapped.config.robot

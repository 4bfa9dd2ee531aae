"""PPO on the wheels: the views turned to the robot's frame, the recipe trains, the agent acts."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest
import torch
import yaml

import sfw_gym  # noqa: F401
from sfw_gym.core.data import DEFAULT_HYPERPARAMS
from sfw_gym.core.errors import ConfigError
from sfw_gym.rl.training import (
    load_hyperparams,
    native_action_repeat,
    parse_policy_kwargs,
    train_ppo,
    wrapper_specs,
)
from sfw_gym.rl.wheels_agent import WheelsPPOAgent
from sfw_gym.rl.wheels_policy import EgoMaps, WheelsPolicy, robot_centre

UNKNOWN, FREE = 127 / 255, 1.0


def views(theta: float, local: torch.Tensor, robot_rc: tuple[int, int] = (32, 32)):
    """EgoMaps' turned views of a hand-made observation (robot heading ``theta``)."""
    space = gym.make("SfW-Explore-v0").observation_space
    extractor = EgoMaps(space, local_px=48, map_px=64)  # full resolution: pixels are exact
    state = torch.zeros(1, space["state"].shape[0])
    state[0, -3], state[0, -2] = math.sin(theta), math.cos(theta)
    image = torch.zeros(1, 3, 64, 64)
    r, c = robot_rc
    image[0, 1, r - 1 : r + 2, c - 1 : c + 2] = 1.0  # the robot's 3 x 3 marker
    image[0, 0] = UNKNOWN
    image[0, 0, r, c + 10] = FREE  # one free pixel 10 px along +x (east) of the robot
    local_view, map_view = extractor.ego_views({"local": local, "map": image, "state": state})
    return local_view[0, 0], map_view[0]


@pytest.fixture
def east_corridor():
    """The local crop: unknown, with free cells 6–15 px east of the robot (columns grow with x)."""
    local = torch.full((1, 1, 48, 48), UNKNOWN)
    local[0, 0, 24, 30:40] = FREE
    return local


@pytest.mark.parametrize(
    ("theta", "where"),
    [(0.0, "ahead"), (math.pi, "behind"), (math.pi / 2, "side"), (-math.pi / 2, "other side")],
)
def test_the_local_view_puts_the_heading_up(east_corridor, theta, where):
    """Facing east, the free cells east of the robot are straight ahead (above the centre, in
    its column); facing west, straight behind; facing ±y, beside it on opposite sides."""
    view = views(theta, east_corridor)[0]
    rows, cols = np.nonzero(view.numpy() > 0.5)  # free reads +1 after the shift
    assert len(rows) >= 8
    centre = 23.5
    if where == "ahead":
        assert rows.max() < centre and np.all(np.abs(cols - centre) <= 1)
    elif where == "behind":
        assert rows.min() > centre and np.all(np.abs(cols - centre) <= 1)
    else:
        assert np.all(np.abs(rows - centre) <= 1)
        side = np.sign(cols.mean() - centre)
        assert side == (1 if where == "side" else -1)


def test_unknown_reads_zero_free_one_and_the_padding_unknown(east_corridor):
    view = views(math.pi / 4, east_corridor)[0].numpy()
    assert abs(view[0, 0]) < 0.01  # a corner beyond the turned crop: padding, read as unknown
    assert abs(np.median(view)) < 0.01  # unknown cells: 2 * 127/255 - 1
    assert view.max() > 0.5  # free, smeared by the bilinear turn of a one-pixel line


def test_the_map_view_is_centred_on_the_robot_marker():
    """The robot's marker lands at the view's centre wherever it is on the map, and the free
    pixel east of it lands 10 px ahead when facing east."""
    for rc in [(32, 32), (10, 50), (55, 8)]:
        _, image = views(0.0, torch.full((1, 1, 48, 48), UNKNOWN), robot_rc=rc)
        marker = np.argwhere(image[1].numpy() > 0.99)
        assert np.allclose(marker.mean(axis=0), (31.5, 31.5), atol=0.6)
        assert abs(np.median(image[0].numpy())) < 0.01  # the belief: unknown reads 0
        free = np.argwhere(image[0].numpy() > 0.5)
        if len(free):  # in the view unless the map's edge cuts it
            assert np.allclose(free.mean(axis=0), (31.5 - 10, 31.5), atol=1.0)


def test_robot_centre_is_the_marker_mean_in_normalised_coordinates():
    trajectory = torch.zeros(2, 64, 64)
    trajectory[0, 0:3, 0:3] = 1.0  # top-left corner: pixel centre 1 -> (2*1+1)/64 - 1
    trajectory[1, 60:63, 30:33] = 1.0
    centre = robot_centre(trajectory).numpy()
    assert np.allclose(centre[0], [3 / 64 - 1, 3 / 64 - 1])
    assert np.allclose(centre[1], [(2 * 31 + 1) / 64 - 1, (2 * 61 + 1) / 64 - 1])


def test_policy_kwargs_take_signed_numbers():
    assert parse_policy_kwargs("dict(log_std_init=-0.5, a=+2)") == {"log_std_init": -0.5, "a": 2}
    with pytest.raises(ConfigError, match="only dict"):
        parse_policy_kwargs("dict(a=-x)")


@pytest.fixture(scope="module")
def wheels_run(tmp_path_factory):
    """The shipped recipe's block (policy, hyperparameters) at smoke size on the small env."""
    root = tmp_path_factory.mktemp("wheels")
    block = dict(yaml.safe_load(DEFAULT_HYPERPARAMS.read_text())["SfW-Explore-v0"])
    block.update(n_envs=2, n_steps=64, batch_size=64, n_epochs=1)
    hyper = root / "ppo.yml"
    hyper.write_text(yaml.safe_dump({"SfW-ExploreSmall-v0": block}))
    out = root / "run"
    summary = train_ppo(
        "SfW-ExploreSmall-v0", 256, out, hyperparams_path=hyper, eval_every=10**9,
        checkpoint_every=128, progress_bar=False,
    )  # fmt: skip
    return out, summary


@pytest.mark.slow
def test_the_recipe_trains_the_wheels_policy(wheels_run):
    """A few hundred steps of the shipped block: WheelsPolicy on the raw continuous actions,
    the native vector env, per-head gradient norms logged."""
    from stable_baselines3 import PPO

    out, summary = wheels_run
    assert summary["steps"] >= 256
    model = PPO.load(out / "SfW-ExploreSmall-v0.zip", device="cpu")
    assert isinstance(model.policy, WheelsPolicy)
    assert set(model.policy.parameter_groups()) == {"features", "actor", "critic"}
    assert isinstance(model.action_space, gym.spaces.Box)


def test_the_shipped_block_is_the_wheels_recipe():
    params = load_hyperparams("SfW-Explore-v0")
    assert params["policy"] == "sfw_gym.rl.wheels_policy.WheelsPolicy"
    # the one wrapper the native vector env applies itself
    assert native_action_repeat(wrapper_specs(params["env_wrapper"])) == 4


def run_agent(agent: WheelsPPOAgent, seed: int, steps: int, agent_seed: int = 0) -> np.ndarray:
    env = gym.make("SfW-ExploreSmall-v0")
    obs, _ = env.reset(seed=seed)
    agent.reset(env, seed=agent_seed)
    actions = []
    for _ in range(steps):
        action = agent.act(obs)
        actions.append(np.asarray(action, np.float64))
        obs, *_ = env.step(action)
    return np.array(actions)


@pytest.mark.slow
def test_the_agent_same_seed_same_actions_and_sampling_follows_its_own_seed(wheels_run):
    out, _ = wheels_run
    deterministic = WheelsPPOAgent(path=out)
    assert deterministic.action_repeat == 4  # from the run's config, as trained
    a, b = run_agent(deterministic, 3, 40), run_agent(deterministic, 3, 40)
    assert np.array_equal(a, b)
    held = a.reshape(10, 4, 2)  # one decision every 4 steps, held
    assert np.all(held == held[:, :1])
    sampled = WheelsPPOAgent(path=out, deterministic=False)
    torch.manual_seed(0)
    c = run_agent(sampled, 3, 40, agent_seed=1)
    torch.manual_seed(123)  # torch's global generator plays no part
    d = run_agent(sampled, 3, 40, agent_seed=1)
    assert np.array_equal(c, d)
    assert not np.array_equal(c, run_agent(sampled, 3, 40, agent_seed=2))


def test_the_agent_refuses_a_policy_trained_through_another_wrapper(tmp_path):
    (tmp_path / "config.yml").write_text(
        yaml.safe_dump(
            {
                "env_id": "SfW-Explore-v0",
                "hyperparameters": {"env_wrapper": "gymnasium.wrappers.TimeLimit"},
            }
        )
    )
    (tmp_path / "SfW-Explore-v0.zip").write_bytes(b"")
    with pytest.raises(ConfigError, match="cannot replay"):
        WheelsPPOAgent(path=tmp_path)


def test_the_agent_refuses_a_waypoint_policy_folder(tmp_path):
    (tmp_path / "config.yml").write_text(
        yaml.safe_dump(
            {
                "env_id": "SfW-Explore-v0",
                "hyperparameters": {"env_wrapper": "sfw_gym.envs.waypoint.WaypointWrapper"},
            }
        )
    )
    (tmp_path / "SfW-Explore-v0.zip").write_bytes(b"")
    with pytest.raises(ConfigError, match="holds a waypoint policy"):
        WheelsPPOAgent(path=tmp_path)


def test_the_shipped_agent_refuses_the_discrete_env_by_name():
    """Its policy names continuous wheel commands: on three discrete actions it would not act
    as trained."""
    env = gym.make("SfW-ExploreDiscrete-v0")
    env.reset(seed=0)
    with pytest.raises(ConfigError, match="supports action types"):
        WheelsPPOAgent().reset(env, seed=0)


@pytest.mark.slow
def test_the_discrete_block_trains_the_same_policy_on_three_actions(tmp_path):
    from stable_baselines3 import PPO

    block = dict(yaml.safe_load(DEFAULT_HYPERPARAMS.read_text())["SfW-ExploreDiscrete-v0"])
    block.update(n_envs=2, n_steps=32, batch_size=32, n_epochs=1)
    hyper = tmp_path / "ppo.yml"
    hyper.write_text(yaml.safe_dump({"SfW-ExploreDiscrete-v0": block}))
    train_ppo(
        "SfW-ExploreDiscrete-v0", 64, tmp_path / "run", hyperparams_path=hyper,
        eval_every=10**9, progress_bar=False,
    )  # fmt: skip
    model = PPO.load(tmp_path / "run" / "SfW-ExploreDiscrete-v0.zip", device="cpu")
    assert isinstance(model.policy, WheelsPolicy)
    assert model.action_space == gym.spaces.Discrete(3)

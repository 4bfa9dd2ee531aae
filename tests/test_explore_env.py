"""SfW-Explore behaviour: episodes, options, rewards, info metrics, the robot's view."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401
from sfw_gym import metrics
from sfw_gym.errors import ConfigError
from sfw_gym.world import generate_floorplan
from tests.conftest import two_rooms_polygon


def drive(env, n: int, seed: int = 0):
    env.action_space.seed(seed)
    out = None
    for _ in range(n):
        out = env.step(env.action_space.sample())
        if out[2] or out[3]:
            break
    return out


def test_incremental_info_metrics_equal_the_full_map_metrics():
    env = gym.make("SfW-Explore-v0")
    env.reset(seed=4)
    *_, info = drive(env, 400)
    u = env.unwrapped
    full = metrics.evaluate_map(u.mapper.occupancy_u8, u.scene.truth_u8)
    assert info["coverage"] == pytest.approx(full["coverage"])
    assert info["map_iou"] == pytest.approx(full["paper_iou"])
    assert info["free_iou"] == pytest.approx(full["free_iou"])
    assert info["wall_precision"] == pytest.approx(np.nan_to_num(full["wall_precision"]))
    assert info["interior_wall_recall"] == pytest.approx(full["interior_wall_recall"])
    assert 0 < info["coverage"] <= 1 and info["path_length_m"] > 0


def test_reward_is_scaled_information_gain_minus_collision_penalty():
    env = gym.make("SfW-Explore-v0", reward_scale=0.5, collision_penalty=3.0)
    env.reset(seed=2)
    env.action_space.seed(0)
    for _ in range(200):
        _, reward, *_, info = env.step(env.action_space.sample())
        bumped = env.unwrapped.scene.robot.bumped
        assert reward == pytest.approx(0.5 * info["info_gain_bits"] - 3.0 * bumped)


def test_terminates_at_the_coverage_target_and_reports_a_summary():
    env = gym.make("SfW-ExploreSmall-v0", coverage_target=0.01)
    env.reset(seed=0)
    _, _, terminated, truncated, info = drive(env, 300)
    assert terminated and not truncated
    assert info["coverage"] >= 0.01 and info["summary"]["steps"] >= 1
    assert 0 <= info["summary"]["map_mse"] <= 1


def test_truncates_at_max_steps():
    env = gym.make("SfW-ExploreSmall-v0", max_steps=7, coverage_target=1.0)
    env.reset(seed=0)
    for i in range(7):
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        assert truncated == (i == 6) and not terminated
    assert info["summary"]["steps"] == 7


def test_step_budget_scales_with_the_plan_area():
    env = gym.make("SfW-ExploreSmall-v0", steps_per_m2=0.2, coverage_target=1.0)
    _, info = env.reset(seed=0)
    area = env.unwrapped.scene.floorplan.area_m2
    budget = info["max_steps"]
    assert budget == math.ceil(0.2 * area) and 2 <= budget < 300
    steps = 0
    while True:
        steps += 1
        _, _, terminated, truncated, info = env.step(env.action_space.sample())
        if terminated or truncated:
            break
    assert truncated and steps == budget == info["summary"]["steps"]
    capped = gym.make("SfW-ExploreSmall-v0", steps_per_m2=1000.0, max_steps=50)
    assert capped.reset(seed=0)[1]["max_steps"] == 50  # max_steps caps the scaled budget
    full = gym.make("SfW-ExploreFull-v0")
    _, info = full.reset(seed=1)
    assert info["max_steps"] == math.ceil(60 * full.unwrapped.scene.floorplan.area_m2)
    for bad in (-1.0, float("nan"), "60"):
        with pytest.raises(ConfigError, match="steps_per_m2"):
            gym.make("SfW-Explore-v0", steps_per_m2=bad)


def test_reset_options(tmp_path):
    env = gym.make("SfW-Explore-v0")
    plan = generate_floorplan(11)
    obs, info = env.reset(seed=0, options={"floorplan": plan})
    assert info["floorplan"] == plan.name
    _, info = env.reset(options={"floorplan": 11})
    assert info["floorplan"] == plan.name
    path = plan.save(tmp_path / "plan.json")
    _, info = env.reset(options={"floorplan": str(path)})
    assert info["floorplan"] == plan.name
    from sfw_gym.world import floorplan_from_polygon

    rooms = floorplan_from_polygon(two_rooms_polygon(), name="two-rooms")
    _, info = env.reset(
        options={"floorplan": rooms, "routers": [[1.0, 1.0]], "start_pose": (8.0, 2.0, 0.5)}
    )
    u = env.unwrapped
    np.testing.assert_array_equal(u.scene.radio.routers, [[1.0, 1.0]])
    assert tuple(info["true_pose"]) == pytest.approx((8.0, 2.0, 0.5))
    assert obs["state"].shape == (10,)


def test_fixed_floorplan_kwarg_and_folder(tmp_path):
    for seed in (3, 4):
        generate_floorplan(seed).save(tmp_path / f"p{seed}.json")
    env = gym.make("SfW-ExploreSmall-v0", floorplan=str(tmp_path))
    names = {env.reset(seed=s)[1]["floorplan"] for s in range(8)}
    assert names == {"gen-apartment-3", "gen-office-4"} or len(names) == 2
    env = gym.make("SfW-ExploreSmall-v0", floorplan=7)
    assert {env.reset(seed=s)[1]["floorplan"] for s in range(3)} == {generate_floorplan(7).name}


def test_robot_view_holds_no_ground_truth():
    env = gym.make("SfW-Explore-v0", robot={"odometry_translation_std": 0.05})
    env.reset(seed=0)
    drive(env, 30)
    view = env.unwrapped.robot_view()
    assert not {"truth_u8", "true_pose", "scene", "floorplan", "true_k"} & set(view)
    info_pose = env.unwrapped.scene.robot.pose
    assert view["odometry_pose"] != pytest.approx(tuple(info_pose))  # drift: odometry ≠ truth
    assert view["belief_u8"].shape == view["grid"].shape
    assert view["rssi_history"].shape == (31, 2)


def test_discrete_actions_move_or_turn():
    env = gym.make("SfW-ExploreDiscrete-v0")
    env.reset(seed=3, options={"floorplan": 3})
    u = env.unwrapped
    x0, y0, t0 = u.scene.robot.pose
    env.step(1)
    assert u.scene.robot.pose[2] != pytest.approx(t0)
    assert u.scene.robot.pose[:2] == pytest.approx((x0, y0), abs=1e-6)


def test_mapper_options_reach_the_mapper():
    env = gym.make("SfW-Explore-v0", mapper={"k_estimator": "kmeans", "router_policy": "all"})
    env.reset(seed=0)
    cfg = env.unwrapped.mapper.config
    assert cfg.k_estimator == "kmeans" and cfg.router_policy == "all" and cfg.k0_level_dbm is None
    default = gym.make("SfW-Explore-v0").unwrapped.mapper_config
    assert default.k0_level_dbm == pytest.approx(20.0 - 40.18, abs=0.01)  # P_tx − PL(1 m)

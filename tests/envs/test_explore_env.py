"""SfW-Explore behaviour: episodes, options, rewards, info metrics, the robot's view."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401
from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.mapping import metrics
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
    env.reset(seed=1)
    *_, info = drive(env, 800)
    u = env.unwrapped
    full = metrics.evaluate_map(u.mapper.occupancy_u8, u.scene.truth_u8)
    assert info["coverage"] == pytest.approx(full["coverage"])
    assert info["map_iou"] == pytest.approx(full["paper_iou"])
    assert info["free_iou"] == pytest.approx(full["free_iou"])
    assert info["wall_precision"] == pytest.approx(np.nan_to_num(full["wall_precision"]))
    assert info["interior_wall_recall"] == pytest.approx(full["interior_wall_recall"])
    assert 0 < info["coverage"] <= 1 and info["path_length_m"] > 0
    assert 0 < info["wall_precision"] < 1 and info["interior_wall_recall"] > 0  # walls found


def test_k_accuracy_reads_the_largest_k_as_that_many_walls_or_more():
    """With max_k = 1 the truth often exceeds it: an estimate of 1 is right there (Eq. 8 with
    max_k, as sfw_gym.mapping.metrics.k_value_accuracy computes it)."""
    env = gym.make("SfW-Explore-v0", mapper={"max_k": 1}, pose_source="true")
    _, info = env.reset(seed=0)  # up to 3 walls from a router within 300 random steps
    env.action_space.seed(0)
    u, est, true = env.unwrapped, [], []
    for step in range(301):  # the reading at reset, then one per step
        if step:
            _, _, _, _, info = env.step(env.action_space.sample())
        heard = u.rssi_history.view[-1] > NOT_HEARD_DBM
        est.append(np.where(heard, u.mapper.last_k, -1))
        true.append(u.scene.radio.true_k(info["true_pose"][:2])[0])
    est, true = np.array(est), np.array(true)
    assert (true[est >= 0] > 1).any()  # the cap mattered
    assert info["k_accuracy"] == pytest.approx(metrics.k_value_accuracy(est, true, max_k=1))


def test_router_slots_an_episode_does_not_use_read_not_heard():
    env = gym.make("SfW-Explore-v0", n_routers=2)
    obs, _ = env.reset(seed=0, options={"routers": 1})
    obs, *_ = env.step(env.action_space.sample())
    assert obs["state"][1] == 0.0 and obs["state"][3] == 0.0  # the second slot: RSSI, heard
    assert obs["state"][2] == 1.0  # the one router is heard


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
    assert not {"truth_u8", "true_pose", "scene", "floorplan", "true_k"} & set(vars(view))
    info_pose = env.unwrapped.ground_truth().trajectory[-1]
    assert view.odometry_pose[:2] != pytest.approx(tuple(info_pose))  # drift: odometry ≠ truth
    assert view.belief_u8.shape == view.grid.shape
    assert view.rssi_history.shape == (31, 2)


def test_the_ground_truth_holds_the_true_pose_now():
    env = gym.make("SfW-Explore-v0", robot={"odometry_translation_std": 0.05})
    env.reset(seed=0)
    info = drive(env, 30)[4]
    truth = env.unwrapped.ground_truth()
    assert truth.pose == tuple(info["true_pose"])
    assert truth.pose[:2] == tuple(truth.trajectory[-1])


def test_robot_view_is_read_only_views_not_copies():
    """robot_view() is O(1): read-only views of the env's arrays, whatever the episode length."""
    env = gym.make("SfW-ExploreSmall-v0", max_steps=1100)
    env.reset(seed=0)
    drive(env, 1050)  # past the history buffer's first growth (1,024 rows)
    assert env.unwrapped.steps > 1024
    u = env.unwrapped
    view = u.robot_view()
    assert np.shares_memory(view.belief_u8, u.mapper.occupancy_u8)
    assert np.shares_memory(view.log_odds, u.mapper.log_odds)
    for array in (view.belief_u8, view.log_odds, view.rssi_history, view.routers_xy):
        assert not array.flags.writeable
    assert view.rssi_history.shape == (u.steps + 1, u.config.explore.n_routers)
    assert view.probability == pytest.approx(u.mapper.probability)
    kept = view.rssi_history.copy()
    drive(env, 5)
    assert np.array_equal(view.rssi_history, kept)  # appends never write into an earlier view


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
    default = gym.make("SfW-Explore-v0").unwrapped.config.mapper
    assert default.k0_level_dbm == pytest.approx(20.0 - 40.18, abs=0.01)  # P_tx − PL(1 m)


def test_the_local_crop_reads_unknown_outside_the_grid_at_every_edge():
    from sfw_gym.core.constants import U8_UNKNOWN
    from sfw_gym.envs.observation import ObservationBuilder
    from sfw_gym.mapping import GridSpec

    belief = np.random.default_rng(0).integers(0, 256, (30, 50)).astype(np.uint8)
    grid = GridSpec((0.0, 0.0), 0.1, belief.shape)
    builder = ObservationBuilder(grid, np.array([[1.0, 1.0]]), 1, 36, 36)
    half = 18
    padded = np.pad(belief, half, constant_values=U8_UNKNOWN)  # the crop's definition
    for x, y in [(0.05, 0.05), (4.95, 0.05), (0.05, 2.95), (4.95, 2.95), (2.5, 1.5)]:
        local = builder.build(belief, [-60.0], False, (x, y, 0.0), 0.5)["local"][0]
        r, c = int(y / 0.1), int(x / 0.1)
        np.testing.assert_array_equal(local, padded[r : r + 36, c : c + 36])

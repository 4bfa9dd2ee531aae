"""SfW-ExploreRegions-v0: decisions that go somewhere, the commitment rule, the agent that acts
as the env does, the privileged observation kept apart, bad input."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents.regions import RegionAgent
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.observation import map_pixels

#: SfW-ExploreSmall-v0's plans and grid, for quick episodes.
SMALL = dict(generator={"area_m2": 45.0}, resolution_m=0.2, map_px=36, crop_px=36, max_steps=300)


def make(env_id: str = "SfW-ExploreRegions-v0", **kwargs):
    return gym.make(env_id, **{**SMALL, **kwargs})


def teacher_episode(seed: int, teacher: str = "explore_lite", **kwargs) -> tuple[list, list[dict]]:
    env = make(**kwargs)
    env.reset(seed=seed)
    poses, infos, done = [], [], False
    while not done:
        _, _, terminated, truncated, info = env.step(env.unwrapped.teacher_action(teacher))
        poses.append(info["true_pose"])
        infos.append(info)
        done = terminated or truncated
    return poses, infos


def test_every_decision_lasts_decision_steps_until_the_episode_ends():
    _, infos = teacher_episode(0)
    steps = [i["decision_steps"] for i in infos]
    assert sum(steps) == infos[-1]["summary"]["steps"]
    assert all(s == 20 for s in steps[:-1]) and 1 <= steps[-1] <= 20
    assert len(infos) <= -(-300 // 20)  # ≤ 150 on the default 3,000-step episodes
    # a goal chosen inside a decision is driven over several steps, not chosen again every step
    micro = [i["micro_decisions"] for i in infos]
    assert all(m >= 1 for m in micro) and sum(micro) < sum(steps)


@pytest.mark.parametrize("teacher", ["explore_lite", "greedy"])
def test_the_region_agent_acts_on_the_explore_env_exactly_as_the_env_does(teacher):
    poses, infos = teacher_episode(1, teacher)
    env = make("SfW-Explore-v0")
    obs, _ = env.reset(seed=1)
    agent = RegionAgent(teacher=teacher)
    agent.reset(env, seed=1)
    boundaries = np.cumsum([i["decision_steps"] for i in infos])
    for step in range(1, boundaries[-1] + 1):
        obs, _, _, _, info = env.step(agent.act(obs))
        if step in boundaries:
            np.testing.assert_array_equal(info["true_pose"], poses[list(boundaries).index(step)])
    assert agent.n_decisions == len(infos)


def test_the_robot_keeps_to_the_chosen_region():
    """The farthest candidate as the region, after three teacher decisions: the decision ends
    nearer to it than it started, and nearer than the unanchored steering gets."""
    for seed in (5, 6, 7):
        ends = []
        for cost in (3.0, 0.0):
            env = make(regions={"anchor_cost_per_m": cost})
            env.reset(seed=seed)
            u = env.unwrapped
            for _ in range(3):
                env.step(u.teacher_action())
            far = np.where(u.menu.valid, u.menu.feature("distance_m"), -1.0)
            i = int(np.argmax(far))
            anchor_xy = u.robot_view().grid.cell_to_world(u.menu.target_rc[i])
            before = np.linalg.norm(u.robot_view().xy - anchor_xy)
            env.step(i)
            ends.append(np.linalg.norm(u.robot_view().xy - anchor_xy))
        assert ends[0] < before and ends[0] < ends[1] - 0.2


def test_without_anchor_cost_the_region_does_not_change_the_steering():
    poses = []
    for action in (0, 1):
        env = make(regions={"anchor_cost_per_m": 0.0})
        env.reset(seed=4)
        assert env.unwrapped.action_masks()[:2].all()
        _, _, _, _, info = env.step(action)
        poses.append(info["true_pose"])
    np.testing.assert_array_equal(poses[0], poses[1])


def test_a_masked_action_steers_without_a_region():
    env = make(regions={"max_candidates": 64})  # more slots than candidates: the last is empty
    env.reset(seed=0)
    assert not env.unwrapped.action_masks()[-1]
    _, _, _, _, info = env.step(63)
    assert info["invalid_action"] and info["decision_steps"] == 20 and info["decision_m"] > 0


def test_candidate_pixels_point_at_the_candidates_targets():
    env = make()
    obs, _ = env.reset(seed=5)
    u = env.unwrapped
    menu, builder = u.menu, u.explore.obs_builder
    px = obs["candidate_px"][: len(menu)]
    assert np.all(obs["candidate_px"][len(menu) :] == 0)
    xy = u.robot_view().grid.cell_to_world(menu.target_rc)
    expected = np.array([builder.pixel_of(x, y) for x, y in xy])
    np.testing.assert_array_equal(np.floor(px * builder.map_px).astype(int), expected)
    np.testing.assert_array_equal(
        px, map_pixels(u.robot_view().grid, builder.map_px, menu.target_rc)
    )


def test_the_true_map_is_only_in_privileged_observations():
    plain, _ = make().reset(seed=6)
    privileged, _ = make(privileged=True).reset(seed=6)
    assert "true_map" not in plain
    assert privileged.keys() - plain.keys() == {"true_map"}
    for key in plain:
        np.testing.assert_array_equal(plain[key], privileged[key])
    truth = privileged["true_map"][0]
    assert {0, 255} <= set(np.unique(truth).tolist())  # walls and free space of the true plan
    assert not np.array_equal(truth, plain["map"][0])  # not the belief


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"privileged": "yes"}, "privileged must be one of"),
        ({"regions": {"decision_step": 5}}, "did you mean 'decision_steps'"),
        ({"regions": {"decision_steps": 0}}, r"regions.decision_steps must be an int >= 1"),
    ],
)
def test_bad_settings_name_the_setting(kwargs, match):
    with pytest.raises(ConfigError, match=match):
        make(**kwargs)


def _decision_with_anchor(anchor, seed: int = 8):
    """One decision of the regions env steered towards ``anchor`` (a cell or None)."""
    env = make()
    env.reset(seed=seed)
    u = env.unwrapped
    cell = u.robot_view().cell
    u.steering.start(anchor(cell) if anchor else None, u.config.decision_steps)
    _, _, _, _, info = u._decide(lambda view: u.steering.command(view, u.explore.steps), False)
    return info["true_pose"], u.steering.anchor_rc


def test_a_region_already_explored_is_released_at_once():
    """An anchor on a resolved cell (the robot's own, free) steers as no anchor does."""
    released, left = _decision_with_anchor(lambda cell: cell)
    unanchored, _ = _decision_with_anchor(None)
    np.testing.assert_array_equal(released, unanchored)
    assert left is None


def test_the_teachers_choose_by_their_own_scores():
    env = make()
    env.reset(seed=9)
    u = env.unwrapped
    menu, mask = u.menu, u.menu.valid
    cost = menu.feature("path_cost_m") + 0.3 * menu.feature("heading_change_rad")
    utility = np.where(
        mask & (menu.source == 0), menu.feature("cluster_size_m") - 3 * cost, -np.inf
    )
    assert u.teacher_action() == int(np.argmax(utility))
    bits = menu.feature("expected_gain_bits") / (menu.feature("path_cost_m") + 0.3)
    assert u.teacher_action("greedy") == int(np.argmax(np.where(mask, bits, -np.inf)))
    with pytest.raises(ConfigError, match="unknown teacher 'oracle'; known: \\['explore_lite'"):
        u.teacher_action("oracle")


def test_explore_lite_refuses_a_menu_without_its_features():
    """A menu computed without cluster sizes would make every utility NaN (and the first
    candidate the choice every time): an error instead."""
    from sfw_gym.navigation.menu import explore_lite_choice
    from sfw_gym.navigation.planning import cost_field

    env = make()
    env.reset(seed=0)
    u = env.unwrapped
    view = u.robot_view()
    paths = cost_field(u.finder.costs(view), view.cell, view.grid.resolution_m)
    partial = u.finder.find(view, paths, features=("path_cost_m", "heading_change_rad"))
    with pytest.raises(ValueError, match="needs the menu's path_cost_m, heading_change_rad"):
        explore_lite_choice(partial)

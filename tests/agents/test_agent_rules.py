"""The agents' documented rules, worked on hand-made inputs (found missing by mutation review)."""

from __future__ import annotations

import dataclasses

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registers the envs)
from sfw_gym.agents import CrossPassAgent, FrontierAgent, GreedyInfoGainAgent, RandomAgent
from sfw_gym.core.errors import ConfigError
from sfw_gym.navigation.planning import cost_field, disk_offsets
from sfw_gym.rl.waypoint_agent import waypoint_settings
from tests.agents.test_agents import F, FakeEnv, U, W, _walled_room_with_unreachable_frontier

SMALL = "SfW-ExploreSmall-v0"


# ------------------------------------------------------------------------------ random agent
def random_actions(action_type: str, hold_steps: int, n: int = 40) -> list:
    env = gym.make(SMALL, action_type=action_type)
    obs, _ = env.reset(seed=0)
    agent = RandomAgent(hold_steps=hold_steps)
    agent.reset(env, seed=0)
    actions, bumps = [], []
    for _ in range(n):
        actions.append(np.asarray(agent.act(obs)).tolist())
        obs, *_ = env.step(actions[-1])
        bumps.append(env.unwrapped.scene.robot.bumped)
    return actions, bumps


def test_random_agent_holds_each_draw_for_hold_steps_and_draws_anew_after_a_bump():
    actions, bumps = random_actions("continuous", hold_steps=3, n=300)
    assert actions[0] != [0.0, 0.0]  # the first action is a draw
    values = np.array(actions)
    assert values.min() < -0.5 and values.max() > 0.5  # uniform on [-1, 1]
    start = 0  # the current draw was made at this step
    for t in range(1, len(actions)):
        if bumps[t - 1] or t - start == 3:
            start = t  # a new draw: after a bump, or after hold_steps steps
        else:
            assert actions[t] == actions[start], t
    assert any(bumps)


def test_random_agent_discrete_actions_cover_all_three():
    actions, _ = random_actions("discrete", hold_steps=1, n=60)
    assert set(np.ravel(actions).tolist()) == {0, 1, 2}
    env = gym.make(SMALL, action_type="discrete")
    obs, _ = env.reset(seed=0)
    agent = RandomAgent(hold_steps=1)
    agent.reset(env, seed=0)
    for _ in range(20):  # drawn from the three actions' own commands, not mapped from [-1, 1]²
        agent.act(obs)
        assert agent.last_command in {(1.0, 0.0), (0.0, 1.0), (0.0, -1.0)}


def test_robot_view_handle_refuses_an_object_without_an_env():
    from sfw_gym.agents import RobotViewHandle

    with pytest.raises(ConfigError, match="robot_view"):
        RobotViewHandle(object())


def test_random_agent_parameters():
    RandomAgent(hold_steps=1)  # the i.i.d. random policy
    for bad in (0, 1.5, True):
        with pytest.raises(ConfigError, match="hold_steps"):
            RandomAgent(hold_steps=bad)
    env = gym.make(SMALL)
    obs, _ = env.reset(seed=0)
    agent = RandomAgent(max_steps=3)
    agent.reset(env, seed=0)
    for _ in range(3):
        agent.act(obs)
    assert agent.act(obs).tolist() == [0.0, 0.0] and agent.stop_reason == "max_steps"


# ------------------------------------------------------------------------------ base
def test_params_are_every_constructor_parameter_of_the_class_chain():
    agent = CrossPassAgent(band_m=0.5, potential_scale=2.0)
    params = agent.params()
    assert params["band_m"] == 0.5 and params["potential_scale"] == 2.0
    assert {"band_bonus", "gain_scale", "stall_steps", "max_steps"} <= set(params)
    assert "self" not in params and "frontier_params" not in params


# ------------------------------------------------------------------------------ PPO agent config
def test_waypoint_settings_of_a_config_without_wrapper_or_hyperparameters():
    assert waypoint_settings({}) is None
    assert waypoint_settings({"hyperparameters": {}}) is None
    name = "sfw_gym.envs.waypoint.WaypointWrapper"
    config = {"hyperparameters": {"env_wrapper": [{name: {"grid_cells": 4}}]}}
    assert waypoint_settings(config) == {"grid_cells": 4}


# ------------------------------------------------------------------------------ greedy
def greedy_on(belief: np.ndarray, routers, pose=(0.05, 0.05, 0.0)):
    """A greedy agent bound to a fake env showing ``belief``, zones fixed to router 0."""
    env = FakeEnv(belief, pose=pose, routers=routers)
    agent = GreedyInfoGainAgent()
    agent.reset(env, seed=0)
    agent._zone = np.zeros(belief.shape, np.int64)
    agent._zones_at = agent.steps
    view = env.robot_view()
    return agent, view


def test_expected_gain_counts_each_unknown_ray_cell_once_plus_the_footprint():
    b = np.full((10, 10), F, np.uint8)
    b[4, :] = U  # one unknown row; the router at its left end, the candidate at its right end
    agent, view = greedy_on(b, routers=((0.05, 0.45),))
    assert len(agent._reach_offsets) == len(disk_offsets(1.1)) == 5
    # ray: the 10 cells of row 4; footprint (a 5-cell cross): the unknown (4, 9), (4, 8), the
    # free (3, 9), (5, 9); (4, 10) lies outside the grid and counts for nothing
    assert agent.expected_gain(view, np.array([[4, 9]])).tolist() == [10 + 2]
    # the same along the top and the bottom row (two footprint cells outside the grid)
    for row in (0, 9):
        b = np.full((10, 10), F, np.uint8)
        b[row, :] = U
        agent, view = greedy_on(b, routers=((0.05, row * 0.1 + 0.05),))
        assert agent.expected_gain(view, np.array([[row, 9]])).tolist() == [10 + 2]
    # and up the first column
    b = np.full((10, 10), F, np.uint8)
    b[:, 0] = U
    agent, view = greedy_on(b, routers=((0.05, 0.05),))
    assert agent.expected_gain(view, np.array([[9, 0]])).tolist() == [10 + 2]


def test_greedy_subsamples_its_candidates_evenly():
    b = np.full((30, 30), F, np.uint8)
    b[:, 15:] = U
    env = FakeEnv(b, pose=(0.5, 0.5, 0.0))
    agent = GreedyInfoGainAgent(max_candidates=7)
    agent.reset(env, seed=0)
    agent.act(None)
    assert len(agent.candidates) == 7
    rows = [cell[0] for cell, _ in agent.candidates]
    assert rows == sorted(rows) and rows[0] == 0 and rows[-1] == 29  # first to last, in order
    with pytest.raises(ConfigError, match="max_candidates"):
        GreedyInfoGainAgent(max_candidates=0)


def test_greedy_zone_model_uses_the_readings_and_refits_every_zones_every_steps(monkeypatch):
    import sfw_gym.navigation.candidates as candidates  # the greedy agent's menu refits the model

    calls = []

    def spy(grid, routers, xy, rssi, **kwargs):
        calls.append((len(xy), None if rssi is None else len(rssi)))
        return real(grid, routers, xy, rssi, **kwargs)

    real = candidates.router_scores
    monkeypatch.setattr(candidates, "router_scores", spy)
    b = np.full((30, 30), F, np.uint8)
    b[:, 15:] = U
    env = FakeEnv(b, pose=(0.5, 0.5, 0.0))
    agent = GreedyInfoGainAgent(zones_every_steps=25, replan_every_steps=1)
    agent.reset(env, seed=0)
    for _ in range(60):
        env.step(agent.act(None))
    assert 2 <= len(calls) <= 3  # steps 0, 25, 50
    assert all(n_xy == n_rssi and n_xy >= 1 for n_xy, n_rssi in calls)
    assert calls[-1][0] > calls[0][0]  # the path so far, with its readings


def test_greedy_blacklists_walled_off_frontiers_for_a_while_and_says_so():
    belief = _walled_room_with_unreachable_frontier()
    env = FakeEnv(belief)
    agent = GreedyInfoGainAgent(unreachable_ttl_steps=200)
    agent.reset(env, seed=0)
    for _ in range(5):
        env.step(agent.act(None))
    assert agent.stop_reason == "all_blacklisted"
    assert agent.unreachable.any() and agent.unreachable_until.max() > agent.steps + 150


# ------------------------------------------------------------------------------ frontier escape
def test_escape_goal_reaches_a_hidden_room_behind_the_maps_wall():
    b = np.full((30, 30), W, np.uint8)
    b[1:29, 1:14] = F  # the explored room
    b[1:3, 1:29] = F  # and a corridor along its top
    b[4:29, 16:29] = U  # a room the map closed off (walls all round): no frontier, hidden
    env = FakeEnv(b, pose=(0.5, 1.5, 0.0))
    agent = FrontierAgent()
    agent.reset(env, seed=0)
    view = env.robot_view()
    paths = cost_field(agent._costs(view, True), view.cell, view.grid.resolution_m)
    goal = agent._escape_goal(view, paths, rooms_only=True)
    assert goal is not None and goal.kind == "escape"
    assert 21 <= goal.target[1] <= 23 and 10 <= goal.target[0] <= 22  # the room's deepest cells
    assert agent._escape_goal(view, paths, rooms_only=False) is not None


def test_sweep_goal_is_the_reachable_unvisited_cell_farthest_from_the_path():
    b = np.full((12, 40), W, np.uint8)
    b[1:11, 1:39] = F  # a closed, fully known corridor: nothing to explore, so it sweeps
    env = FakeEnv(b, pose=(0.35, 0.55, 0.0))
    agent = FrontierAgent()
    agent.reset(env, seed=0)
    agent.act(None)
    assert agent.stop_reason == "no_frontiers"
    assert agent.goal is not None and agent.goal.kind == "sweep"
    assert agent.goal.cell[1] >= 35  # the far end of the corridor


# ------------------------------------------------------------------------------ frontier's rules
class BumpingEnv(FakeEnv):
    """:class:`FakeEnv` whose view reports a bump while ``bump`` is set."""

    bump = False

    def robot_view(self):
        return dataclasses.replace(super().robot_view(), bumped=self.bump)


def open_room() -> np.ndarray:
    """A known free 16 x 16-cell room in unknown space: frontiers all round."""
    b = np.full((20, 20), U, np.uint8)
    b[2:18, 2:18] = F
    return b


def bumped_step(agent, env, forward: bool = True):
    """One act on a view that reports a bump, the last command having been ``forward``
    (full speed ahead) or a turn on the spot."""
    env.bump = True
    agent.last_command = (1.0, 0.0) if forward else (0.0, 1.0)
    action = agent.act(None)
    env.bump = False
    env.step(action)
    return action


def test_a_bump_driving_forward_marks_the_one_cell_disk_just_ahead_and_nothing_else():
    """Hand-derived: the robot (radius 0.17 m) at (1.01, 1.05) facing +x touches half a cell
    beyond its rim, at x = 1.01 + 0.17 + 0.05 = 1.23 m: cell (10, 12) (its rim, 1.18 m, is in
    column 11), marked with its 4 neighbours. A bump while turning on the spot, or while the
    robot still moved at least half the commanded 0.1 m (sliding along a wall), marks
    nothing."""
    env = BumpingEnv(open_room(), pose=(1.01, 1.05, 0.0), frozen=True)
    agent = FrontierAgent(backoff_steps=0)
    agent.reset(env, seed=0)
    env.step(agent.act(None))
    bumped_step(agent, env, forward=False)
    assert not agent.bumps.any() and agent.n_bumps == 0
    bumped_step(agent, env, forward=True)
    cross = [(9, 12), (10, 11), (10, 12), (10, 13), (11, 12)]
    assert sorted(map(tuple, np.argwhere(agent.bumps).tolist())) == cross
    assert agent.n_bumps == 1
    sliding = BumpingEnv(open_room(), pose=(1.05, 1.05, 0.0))  # it moves 0.1 m a step
    agent = FrontierAgent(backoff_steps=0)
    agent.reset(sliding, seed=0)
    sliding.step(np.array([1.0, 0.0]))  # moved 0.1 m since the agent's last view
    bumped_step(agent, sliding, forward=True)
    assert not agent.bumps.any() and agent.n_bumps == 0


@pytest.mark.parametrize("backoff_steps", [0, 1, 3])
def test_after_a_bump_it_reverses_for_exactly_backoff_steps_steps(backoff_steps):
    """The step that sees the bump and the next ``backoff_steps - 1`` are full reverse
    ``(-1, 0)``; then it drives again (never reverse: pure pursuit goes forward or turns)."""
    env = BumpingEnv(open_room(), pose=(1.05, 1.05, 0.0), frozen=True)
    agent = FrontierAgent(backoff_steps=backoff_steps)
    agent.reset(env, seed=0)
    env.step(agent.act(None))
    actions = [bumped_step(agent, env).tolist()]
    for _ in range(5):
        actions.append(agent.act(None).tolist())
        env.step(actions[-1])
    reverse = [a == [-1.0, 0.0] for a in actions]
    assert reverse == [True] * backoff_steps + [False] * (6 - backoff_steps), actions


def test_a_goal_is_blacklisted_at_its_max_bumps_per_goal_th_bump_for_blacklist_ttl_steps():
    """``max_bumps_per_goal=3``: after bumps 1 and 2 on the way to a goal it is kept (nothing
    blacklisted); the 3rd, at act call k, blacklists the cells within ``blacklist_radius_m``
    (2.5 cells) of its target until step k + ``blacklist_ttl_steps``: for exactly that many
    steps."""
    ttl = 7
    env = BumpingEnv(open_room(), pose=(1.05, 1.05, 0.0), frozen=True)
    agent = FrontierAgent(
        backoff_steps=0, max_bumps_per_goal=3, blacklist_ttl_steps=ttl, blacklist_radius_m=0.25
    )
    agent.reset(env, seed=0)
    env.step(agent.act(None))
    bumped_step(agent, env)  # the contact cell marked: the goals from now on avoid it
    target = agent.goal.target
    assert agent.goal.bumps == 0 and not agent.blacklisted.any()
    for n in (1, 2):  # the frozen robot bumps the same cell again and again
        bumped_step(agent, env)
        assert agent.goal is not None and agent.goal.target == target  # the same goal
        assert agent.goal.bumps == n and not agent.blacklisted.any()
    k = agent.steps
    bumped_step(agent, env)  # act call k: the 3rd bump
    assert agent.n_blacklisted == 1 and agent.goal.target != target
    disk = np.zeros(agent.blacklisted.shape, bool)
    rr, cc = np.ogrid[:20, :20]
    disk[(rr - target[0]) ** 2 + (cc - target[1]) ** 2 <= 2.5**2] = True
    np.testing.assert_array_equal(agent.finder.failed_until > 0, disk)
    assert (agent.finder.failed_until[disk] == k + ttl).all()
    blacklisted = [bool(agent.blacklisted[target])]  # after act call k
    while agent.steps < k + ttl + 2:
        env.step(agent.act(None))  # act call agent.steps
        blacklisted.append(bool(agent.blacklisted[target]))
    # after calls k .. k + ttl - 1: blacklisted (ttl steps); after call k + ttl: free again
    assert blacklisted == [True] * ttl + [False] * 2


def row_of_cells(free: slice, n: int = 30) -> np.ndarray:
    """A one-cell-high map: ``free`` columns known free, the rest unknown."""
    b = np.full((1, n), U, np.uint8)
    b[0, free] = F
    return b


@pytest.mark.parametrize(("turn_cost", "chosen"), [(0.0, (0, 25)), (0.2, (0, 25)), (0.25, (0, 4))])
def test_turn_cost_adds_turn_cost_times_the_turn_to_a_clusters_path(turn_cost, chosen):
    """One row, free over columns 5-24; the robot at column 18 facing -x. Two one-cell frontiers:
    (0, 4) ahead (turn 0), reached from column 5: 1.3 m; (0, 25) behind (turn π), reached from
    column 24: 0.6 m. Utility = 1.0 · 0.1 − 3.0 · (path + turn_cost · turn): the one behind wins
    until turn_cost · π > 0.7 m, i.e. turn_cost > 0.223."""
    env = FakeEnv(row_of_cells(slice(5, 25)), pose=(1.85, 0.05, np.pi), routers=((1.5, 0.05),))
    agent = FrontierAgent(
        turn_cost_m_per_rad=turn_cost, min_frontier_size_m=0.0, min_unknown_region_m2=0.0
    )
    agent.reset(env, seed=0)
    agent.act(None)
    expected = {(0, 4): 0.1 - 3.0 * 1.3, (0, 25): 0.1 - 3.0 * (0.6 + turn_cost * np.pi)}
    assert dict(agent.candidates) == pytest.approx(expected, abs=1e-9)
    assert agent.goal.target == chosen


# ------------------------------------------------------------------------------ cross-pass loop
def test_cross_pass_loop_is_a_rectangle_across_the_border():
    b = np.full((30, 60), F, np.uint8)
    b[:, 26:34] = U
    b[0, :] = b[-1, :] = W
    env = FakeEnv(b, pose=(1.5, 1.5, 0.0), routers=((1.0, 1.5), (5.0, 1.5)))
    agent = CrossPassAgent(pass_trigger_m=10.0, pass_offset_m=0.5, pass_length_m=1.5)
    agent.reset(env, seed=0)
    agent.act(None)
    cells = np.array([agent.goal.cell, *agent.goal.waypoints])
    xs, ys = cells[:, 1] * 0.1 + 0.05, cells[:, 0] * 0.1 + 0.05
    # legs along the border (x = 3 m), 0.5 m either side of it; 1.5 m long
    assert sorted({round(x, 2) for x in xs}) == pytest.approx([2.55, 3.55], abs=0.11)
    assert np.ptp(ys) == pytest.approx(1.5, abs=0.15)
    assert len(cells) == 5 and (cells[0] == cells[-1]).all()


# ------------------------------------------------------------------------------ parameters
@pytest.mark.parametrize("cls", [FrontierAgent, CrossPassAgent, GreedyInfoGainAgent, RandomAgent])
def test_a_bad_value_of_any_parameter_is_an_error_naming_it(cls):
    defaults = cls().params()  # every constructor parameter of the class chain
    names = [k for k, v in defaults.items() if type(v) in (int, float)]
    assert names
    for name in names:
        with pytest.raises(ConfigError, match=rf"^{name} must be"):
            cls(**{name: -1})


@pytest.mark.parametrize("seed", [0, 1])
def test_a_bounded_first_search_makes_the_same_choices_as_a_full_one(seed):
    """The frontier agent searches paths only up to search_radius_m first, and keeps the choice
    only when no cluster beyond could beat it: its actions equal those of an unbounded search."""
    runs = []
    for radius in (0.8, 1e9):
        env = gym.make("SfW-Explore-v0", max_steps=400)
        obs, _ = env.reset(seed=seed)
        agent = FrontierAgent(search_radius_m=radius)
        agent.reset(env, seed=seed)
        actions = []
        for _ in range(400):
            action = agent.act(obs)
            actions.append(action)
            obs, _, terminated, truncated, _ = env.step(action)
            if terminated or truncated:
                break
        runs.append((np.array(actions), agent.n_full_searches, agent.n_plans))
    (bounded, full_searches, plans), (unbounded, _, _) = runs
    assert 0 < full_searches < plans  # both ways of choosing happened
    assert np.array_equal(bounded, unbounded)


def test_without_replanning_on_resolution_the_frontier_agent_drives_on_to_its_goal():
    """``replan_when_resolved=False`` (explore_lite's way): a resolved target no longer triggers
    a replan, so the same episode prefix takes fewer replans than with the default."""
    plans = {}
    for flag in (True, False):
        env = gym.make("SfW-Explore-v0", max_steps=300)
        obs, _ = env.reset(seed=4)
        agent = FrontierAgent(replan_when_resolved=flag)
        agent.reset(env, seed=4)
        for _ in range(300):
            obs, _, terminated, truncated, _ = env.step(agent.act(obs))
            if terminated or truncated:
                break
        plans[flag] = agent.n_plans
    assert plans[False] < plans[True]  # 205 against 247

"""Baseline agents: frontier detection, the robot-view boundary, blacklisting, planning, passes."""

from __future__ import annotations

import gc
import pickle
import time
from collections import deque
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

import sfw_gym  # noqa: F401  (registers the envs)
from sfw_gym.agents import (
    AGENTS,
    DEPRECATED_AGENTS,
    CrossPassAgent,
    FrontierAgent,
    GreedyInfoGainAgent,
    RandomAgent,
    RobotView,
    RobotViewHandle,
    agent_class,
    known_agent,
    make_agent,
)
from sfw_gym.core.angles import wrap_angle
from sfw_gym.core.errors import ConfigError
from sfw_gym.mapping import GridSpec
from sfw_gym.navigation import (
    dominance_bands,
    find_frontiers,
    frontier_mask,
    hidden_rooms,
    router_scores,
)
from sfw_gym.navigation.planning import (
    PurePursuit,
    cost_field,
    to_discrete,
    traversal_costs,
)

W, U, F = 0, 127, 255  # wall, unknown, free
SMALL = "SfW-ExploreSmall-v0"


# ------------------------------------------------------------------------------ frontier detection
def test_no_frontier_on_an_unknown_map():
    assert find_frontiers(np.full((20, 20), U, np.uint8)) == []


def test_free_square_in_unknown_space_has_its_ring_as_one_frontier():
    b = np.full((20, 20), U, np.uint8)
    b[5:10, 5:10] = F
    fronts = find_frontiers(b)
    assert len(fronts) == 1
    assert fronts[0].size == 7 * 7 - 5 * 5  # the 8-connected ring around the 5 × 5 square
    rows, cols = fronts[0].cells.T
    assert rows.min() == 4 and rows.max() == 10 and cols.min() == 4 and cols.max() == 10
    assert fronts[0].centroid_rc == pytest.approx((7.0, 7.0))


def test_walled_room_has_no_frontier():
    b = np.full((20, 20), U, np.uint8)
    b[4:12, 4:12] = W
    b[5:11, 5:11] = F
    assert not frontier_mask(b).any()


def test_a_doorway_in_the_wall_is_a_frontier():
    b = np.full((20, 20), U, np.uint8)
    b[4:12, 4:12] = W
    b[5:11, 5:11] = F
    b[11, 7:9] = F  # a 2-cell gap in the bottom wall
    fronts = find_frontiers(b)
    assert len(fronts) == 1
    assert {tuple(c) for c in fronts[0].cells} == {(12, 6), (12, 7), (12, 8), (12, 9)}


def test_hidden_room_is_found_behind_a_closed_doorway_but_not_outside_the_building():
    b = np.full((30, 40), U, np.uint8)  # the building's surroundings are unknown too
    b[5:10, 5:35] = F  # an explored corridor ...
    b[4, 5:35] = b[10, 5:35] = W  # ... whose walls the map closed all along
    b[11:25, 5:20] = F  # an explored room below it, so the explored extent spans rows 5..24
    depth = hidden_rooms(b, min_depth_cells=3)
    # the unexplored 14 x 15 block beside the room (rows 11-24, cols 20-34) is a hidden room
    assert depth[18, 27] >= 3 and depth[11:25, 20:35].max() == depth.max()
    assert not depth[:4].any() and not depth[:, :5].any()  # outside the explored extent: never
    assert not depth[5:11].any()  # the corridor and its walls are known
    assert hidden_rooms(b, min_depth_cells=10).max() == 0  # the block is only ~7 cells deep
    assert not hidden_rooms(np.full((10, 10), U, np.uint8), 1).any()  # nothing explored yet


def test_clusters_are_sorted_filtered_and_excludable():
    b = np.full((30, 30), U, np.uint8)
    b[2:4, 2:4] = F  # ring of 12
    b[15:25, 15:25] = F  # ring of 44
    fronts = find_frontiers(b)
    assert [f.size for f in fronts] == [44, 12]
    assert [f.size for f in find_frontiers(b, min_size_cells=13)] == [44]
    exclude = np.zeros_like(b, bool)
    exclude[:10, :10] = True
    assert [f.size for f in find_frontiers(b, exclude=exclude)] == [44]


def test_graded_belief_values_are_thresholded():
    b = np.full((10, 10), 150, np.uint8)  # weakly free: still unknown
    b[4:6, 4:6] = 200  # free
    b[0, :] = 60  # wall
    mask = frontier_mask(b)
    assert mask.sum() == 4 * 4 - 2 * 2
    assert not mask[0].any()


# ------------------------------------------------------------------------------ fake environment
class FakeEnv:
    """A robot on a fixed hand-made belief map that drives kinematically through anything.

    Exposes only ``unwrapped.robot_view()``, as an agent may use. ``frozen=True``: the robot
    never moves (a robot stuck against something the map does not show).
    """

    def __init__(
        self, belief, pose=(0.55, 0.55, 0.0), frozen=False, routers=((0.5, 0.5), (2.5, 0.5))
    ):
        self.belief = belief
        self.routers = np.array(routers, np.float64)
        self.grid = GridSpec((0.0, 0.0), 0.1, belief.shape)
        self.pose = np.array(pose, np.float64)
        self.frozen = frozen
        self.unwrapped = self
        self.t = 0
        self.path = [self.pose[:2].copy()]

    def robot_view(self) -> RobotView:
        return RobotView.hand_made(
            self.belief.copy(),
            self.grid,
            tuple(self.pose),
            self.routers.copy(),
            rssi_history=np.tile(self._rssi(), (self.t + 1, 1)),
            odometry_trajectory=np.array(self.path),
        )

    def _rssi(self) -> np.ndarray:
        d = np.maximum(np.linalg.norm(self.routers - self.pose[:2], axis=1), 1.0)
        return np.round(-40.0 - 20.0 * np.log10(d))

    def step(self, action) -> None:
        self.t += 1
        if not self.frozen:
            lin, ang = np.clip(action, -1, 1)
            self.pose[2] = wrap_angle(self.pose[2] + 0.3 * ang)
            self.pose[:2] += 0.1 * lin * np.array([np.cos(self.pose[2]), np.sin(self.pose[2])])
        self.path.append(self.pose[:2].copy())


def _walled_room_with_unreachable_frontier() -> np.ndarray:
    """A 1 m room walled in on every side; beyond its right wall, a free patch by unknown space."""
    b = np.full((12, 30), U, np.uint8)
    b[0:12, 0:12] = W
    b[1:11, 1:11] = F  # the robot's room
    b[3:8, 14:17] = F  # reachable only through the wall: its ring is the only frontier
    b[2:9, 13] = W  # and it is walled off from the unknown on the room's side
    return b


def test_unreachable_only_frontier_is_blacklisted_and_reported():
    belief = _walled_room_with_unreachable_frontier()
    assert len(find_frontiers(belief)) >= 1
    env = FakeEnv(belief)
    agent = FrontierAgent()
    agent.reset(env, seed=0)
    rows, cols = np.nonzero(frontier_mask(belief))
    start = time.perf_counter()
    for step in range(450):  # no endless loop: every act returns, the agent keeps moving
        action = agent.act(None)
        assert action.shape == (2,) and np.isfinite(action).all()
        env.step(action)
        if step == 100:
            assert agent.stop_reason == "all_blacklisted"
            assert agent.blacklisted[rows, cols].all()
    assert time.perf_counter() - start < 30
    # Walled-off clusters are retried after unreachable_ttl_steps (the map may change), and
    # blacklisted again.
    assert agent.stop_reason == "all_blacklisted"
    assert agent.n_blacklisted >= 2
    assert np.ptp(np.array(agent.trajectory), axis=0).max() > 0.3  # it kept sweeping its room


def test_frontier_the_robot_cannot_get_to_is_blacklisted_after_the_timeout():
    b = np.full((20, 20), U, np.uint8)
    b[2:18, 2:18] = F  # an open room in unknown space: frontiers all around
    env = FakeEnv(b, pose=(1.0, 1.0, 0.0), frozen=True)  # stuck: no progress ever
    agent = FrontierAgent(progress_timeout_steps=10)
    agent.reset(env, seed=0)
    for _ in range(400):
        env.step(agent.act(None))
        if agent.stop_reason == "all_blacklisted":
            break
    assert agent.n_blacklisted >= 1
    assert agent.stop_reason == "all_blacklisted"


def test_no_frontiers_is_reported_on_a_closed_known_map():
    b = np.full((12, 12), W, np.uint8)
    b[1:11, 1:11] = F
    env = FakeEnv(b)
    agent = FrontierAgent()
    agent.reset(env)
    for _ in range(5):
        env.step(agent.act(None))
    assert agent.stop_reason == "no_frontiers"


def test_max_steps_stops_the_agent():
    env = FakeEnv(np.full((20, 20), U, np.uint8), pose=(1.0, 1.0, 0.0))
    agent = FrontierAgent(max_steps=3)
    agent.reset(env)
    actions = [agent.act(None) for _ in range(5)]
    assert agent.stop_reason == "max_steps"
    np.testing.assert_array_equal(actions[-1], [0.0, 0.0])


# ------------------------------------------------------------------------------ the robot's view
class OnlyRobotView:
    """An env stand-in with nothing but ``unwrapped.robot_view()``; anything else fails."""

    def __init__(self, env: gym.Env) -> None:
        object.__setattr__(self, "_view", env.unwrapped.robot_view)

    @property
    def unwrapped(self) -> OnlyRobotView:
        return self

    def robot_view(self) -> RobotView:
        return object.__getattribute__(self, "_view")()

    def __getattr__(self, name: str) -> Any:
        raise AssertionError(f"agent reached env.{name}: only robot_view() is allowed")


def _reachable(obj: Any, stop: tuple[type, ...], until: tuple[Any, ...] = ()) -> list[Any]:
    """Objects reachable from ``obj`` through attributes and containers (not through ``stop``),
    nearest first; with ``until``, the walk ends once it has reached all of those (a walk past
    a function's globals would go on through every loaded module)."""
    seen, out, todo = set(), [], deque([obj])
    wanted = {id(o) for o in until}
    while todo and not (wanted and wanted <= seen):
        o = todo.popleft()
        if id(o) in seen or isinstance(o, type):
            continue
        seen.add(id(o))
        out.append(o)
        if isinstance(o, stop):
            continue
        todo.extend(gc.get_referents(o))
    return out


def env_for(name: str, **kwargs: Any) -> gym.Env:
    """SMALL, except for the shipped learned agents, which need the default 64 x 64 observations."""
    learned = ("regions-ppo", "goals-ppo", "waypoint-ppo", "wheels-ppo")
    return gym.make("SfW-Explore-v0" if name in learned else SMALL, **kwargs)


#: Every registered agent but the oracles (privileged: they read the ground truth on purpose).
ROBOT_AGENTS = sorted(n for n in AGENTS if not agent_class(n).privileged)


@pytest.mark.parametrize("name", ROBOT_AGENTS)
def test_agent_cannot_reach_ground_truth_through_the_interface(name):
    env = env_for(name)
    obs, _ = env.reset(seed=3)
    u = env.unwrapped
    agent = make_agent(name)
    agent.reset(OnlyRobotView(env), seed=3)
    proxy_actions = []
    for _ in range(40):
        a = agent.act(obs)
        proxy_actions.append(np.asarray(a).copy())
        obs, *_ = env.step(a)
    # The agent holds no ground truth: not the env, its scene, plan, radio, robot or truth grid.
    forbidden = {
        id(x)
        for x in (
            env,
            u,
            u.scene,
            u.scene.floorplan,
            u.scene.radio,
            u.scene.robot,
            u.scene.truth_u8,
            u.mapper,
            u.tracker,
        )
    }
    held = _reachable(agent, stop=(RobotViewHandle,))
    assert not [type(o).__name__ for o in held if id(o) in forbidden]
    assert not any(type(o).__module__.startswith("sfw_gym.world") for o in held)
    # It used nothing but robot_view(): same actions with the real env as through the proxy.
    env2 = env_for(name)
    obs, _ = env2.reset(seed=3)
    agent2 = make_agent(name)
    agent2.reset(env2, seed=3)
    for a in proxy_actions:
        b = agent2.act(obs)
        np.testing.assert_array_equal(np.asarray(b), a)
        obs, *_ = env2.step(b)


def test_robot_view_handle_shows_only_the_documented_fields():
    env = gym.make(SMALL)
    env.reset(seed=0)
    view = RobotViewHandle(env)()
    assert isinstance(view, RobotView)
    fields = set(vars(view))
    assert fields == {f for f in RobotView.__dataclass_fields__}
    assert not any("true" in k or "truth" in k or "scene" in k for k in fields)
    with pytest.raises(TypeError):
        pickle.dumps(RobotViewHandle(env))
    with pytest.raises(ConfigError, match="robot_view"):
        RobotViewHandle(gym.make("CartPole-v1"))


# ------------------------------------------------------------------------------ interface
@pytest.mark.parametrize("name", sorted(AGENTS))
def test_every_agent_builds_without_arguments_and_drives_the_action_types_it_has(name):
    agent = agent_class(name)()
    assert agent.name == name
    assert isinstance(agent.params(), dict)
    kinds = [{}, {"action_type": "discrete"}]
    if "discrete" not in agent.action_types:  # wheels-ppo: a policy of continuous commands
        discrete = env_for(name, action_type="discrete")
        discrete.reset(seed=1)
        with pytest.raises(ConfigError, match="supports action types"):
            agent.reset(discrete, seed=1)
        kinds = [{}]
    for env_kwargs in kinds:
        env = env_for(name, **env_kwargs)
        obs, _ = env.reset(seed=1)
        agent.reset(env, seed=1)
        for _ in range(30):
            action = agent.act(obs)
            assert env.action_space.contains(
                np.int64(action) if env_kwargs else np.asarray(action, np.float32)
            )
            obs, *_ = env.step(action)


def test_act_before_reset_and_bad_parameters_raise():
    with pytest.raises(RuntimeError, match="reset"):
        FrontierAgent().act(None)
    with pytest.raises(ConfigError, match="potential_scale"):
        FrontierAgent(potential_scale=-1)
    with pytest.raises(ConfigError, match="hold_steps"):
        RandomAgent(hold_steps=0)
    with pytest.raises(ConfigError, match="unknown agent"):
        make_agent("nope")
    with pytest.raises(ConfigError, match="agent 'frontier': unknown key 'nope'"):
        make_agent("frontier", nope=1)


# ------------------------------------------------------------------------------ acting on info
def _env_bound_actions(name: str, seed: int, steps: int) -> list[np.ndarray]:
    env, agent = gym.make(SMALL), make_agent(name)
    obs, _ = env.reset(seed=seed)
    agent.reset(env, seed=seed)
    actions = []
    for _ in range(steps):
        actions.append(np.asarray(agent.act(obs)))
        obs, *_ = env.step(actions[-1])
    return actions


@pytest.mark.parametrize("name", ["frontier", "cross-pass"])
def test_an_agent_acts_on_the_info_of_a_vector_env_as_it_does_on_the_env(name):
    from sfw_gym.envs import RobotViewInInfo

    seeds, steps = [5, 6], 60
    envs = gym.make_vec(SMALL, num_envs=2, vectorization_mode="sync", wrappers=[RobotViewInInfo])
    agents = [make_agent(name) for _ in seeds]
    _, info = envs.reset(seed=seeds)
    for i, agent in enumerate(agents):
        agent.reset(info={"robot_view": info["robot_view"][i]}, seed=seeds[i])
    got: list[list[np.ndarray]] = [[], []]
    for _ in range(steps):
        actions = []
        for i, agent in enumerate(agents):
            actions.append(np.asarray(agent.act(None, {"robot_view": info["robot_view"][i]})))
            got[i].append(actions[-1])
        _, _, terminated, truncated, info = envs.step(np.stack(actions))
        assert not (terminated | truncated).any()
    for i, seed in enumerate(seeds):
        expected = _env_bound_actions(name, seed, steps)
        np.testing.assert_array_equal(np.array(got[i]), np.array(expected))


def test_acting_on_info_without_the_view_is_a_clear_error():
    from sfw_gym.envs import RobotViewInInfo

    env = RobotViewInInfo(gym.make(SMALL))
    obs, info = env.reset(seed=0)
    agent = FrontierAgent()
    with pytest.raises(ConfigError, match="needs the env or the reset's info"):
        agent.reset(seed=0)
    with pytest.raises(ConfigError, match=r"info\['robot_view'\].*got keys"):
        agent.reset(info={"coverage": 0.0})
    agent.reset(info=info, seed=0)
    with pytest.raises(ConfigError, match=r"needs info\['robot_view'\]"):
        agent.act(obs)
    with pytest.raises(ConfigError, match="robot_view"):
        RobotViewInInfo(gym.make("CartPole-v1"))


# ------------------------------------------------------------------------------ planning
def test_costs_make_walls_obstacles_and_unknown_dearer():
    b = np.full((10, 10), F, np.uint8)
    b[:, 0] = U
    b[5, 5] = W
    c = traversal_costs(b, 0.1, 0.17, unknown_cost=2.0, lethal_radius_m=0.17)
    assert np.isinf(c[5, 5]) and np.isinf(c[5, 6]) and np.isinf(c[6, 5])
    assert c[0, 0] == 2.0 and c[0, 9] == 1.0
    assert c[5, 8] > 1.0  # within the clearance band


def test_planner_goes_around_a_wall():
    b = np.full((20, 20), F, np.uint8)
    b[10, 0:17] = W
    paths = cost_field(traversal_costs(b, 0.1, 0.17), (2, 2), 0.1)
    path = paths.path((18, 2))
    assert tuple(path[0]) == (2, 2) and tuple(path[-1]) == (18, 2)
    assert all(b[r, c] != W for r, c in path)
    assert path[:, 1].max() >= 17  # around the wall's end
    blocked = b.copy()
    blocked[10, :] = W
    assert len(cost_field(traversal_costs(blocked, 0.1, 0.17), (2, 2), 0.1).path((18, 2))) == 0


def test_pure_pursuit_drives_a_unicycle_to_the_end_of_a_path():
    pp = PurePursuit(lookahead_m=0.3, goal_tolerance_m=0.1)
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    pp.set_path(path)
    pose = np.array([0.0, 0.0, np.pi])
    for _ in range(200):
        lin, ang = pp.command(tuple(pose))
        if not pp.has_path:
            break
        pose[2] = wrap_angle(pose[2] + 0.3 * ang)
        pose[:2] += 0.1 * lin * np.array([np.cos(pose[2]), np.sin(pose[2])])
    assert not pp.has_path
    assert np.linalg.norm(pose[:2] - path[-1]) <= 0.1
    assert to_discrete(1.0, 0.0) == 0 and to_discrete(0.0, 1.0) == 1 and to_discrete(0.2, -0.9) == 2


# ------------------------------------------------------------------------------ cross passes
def test_dominance_zones_of_two_equal_routers_meet_at_the_bisector():
    grid = GridSpec((0.0, 0.0), 0.1, (20, 60))
    scores = router_scores(grid, np.array([[1.0, 1.0], [5.0, 1.0]]))
    zone, band = dominance_bands(scores, band_cells=3)
    assert (zone[:, :29] == 0).all() and (zone[:, 31:] == 1).all()
    assert band[:, 27:33].all() and not band[:, :25].any() and not band[:, 35:].any()


def test_measured_residuals_shift_the_zone_border():
    grid = GridSpec((0.0, 0.0), 0.1, (20, 60))
    routers = np.array([[1.0, 1.0], [5.0, 1.0]])
    xs = np.linspace(2.6, 3.4, 9)
    samples = np.stack([xs, np.full_like(xs, 1.0)], 1)
    rssi = np.tile([-60.0, -60.0], (len(xs), 1))
    rssi[:, 1] -= 15.0  # router 1 measured behind a wall
    zone, _ = dominance_bands(router_scores(grid, routers, samples, rssi), 3)
    assert (zone[10, 26:34] == 0).all()


def test_cross_pass_agent_plans_a_loop_across_an_unknown_border_band():
    b = np.full((20, 60), F, np.uint8)
    b[:, 26:34] = U  # the band between the zones of routers at x = 1 m and x = 5 m
    b[0, :] = b[-1, :] = W
    env = FakeEnv(b, pose=(1.5, 1.0, 0.0), routers=((1.0, 1.0), (5.0, 1.0)))
    agent = CrossPassAgent(pass_trigger_m=10.0)
    agent.reset(env, seed=0)
    agent.act(None)
    assert agent.goal is not None and agent.goal.kind == "pass"
    cells = [agent.goal.cell, *agent.goal.waypoints]
    xs = [c[1] * 0.1 + 0.05 for c in cells]
    assert min(xs) < 3.0 < max(xs)  # the loop crosses the border (x = 3 m)
    assert len(cells) >= 4 and cells[0] == cells[-1]
    assert agent.n_passes == 1


def test_greedy_gain_prefers_goals_that_open_more_unknown():
    b = np.full((30, 30), F, np.uint8)
    b[:, 15:] = U
    env = FakeEnv(b, pose=(0.5, 0.5, 0.0))
    agent = GreedyInfoGainAgent()
    agent.reset(env)
    gain = agent.expected_gain(agent._view(), np.array([[5, 10], [5, 25]]))
    assert gain[1] > gain[0]


@pytest.mark.parametrize(("old", "new"), sorted(DEPRECATED_AGENTS.items()))
def test_an_old_agent_name_warns_and_builds_the_agent_it_names_now(old, new):
    with pytest.warns(FutureWarning, match=f"agent name {old!r} is deprecated: use {new!r}"):
        assert agent_class(old) is agent_class(new)
    assert known_agent(old) and not known_agent("ppo-nonsense")


def test_params_hold_a_settings_class_and_an_own_constructors_parameters():
    class OwnInit(RandomAgent):  # an agent written as before issue 32, with its own __init__
        name = "own-init"

        def __init__(self, turn_steps: int = 8, **params) -> None:
            super().__init__(**params)
            self.turn_steps = turn_steps

    assert OwnInit(turn_steps=3, hold_steps=2).params() == {
        "max_steps": None,
        "hold_steps": 2,
        "turn_steps": 3,
    }
    assert RandomAgent(hold_steps=4).params() == {"max_steps": None, "hold_steps": 4}

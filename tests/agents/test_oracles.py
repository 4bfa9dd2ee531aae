"""The oracles (issue 40): privileged explorers that read the ground truth, marked as such and run
only where they are named; the coverage oracle's gain on cases computed by hand, and its tour
covering a small plan within its budget."""

from __future__ import annotations

from pathlib import Path
from types import ModuleType, SimpleNamespace

import gymnasium as gym
import numpy as np
import pytest
import yaml
from shapely.geometry import Polygon

import sfw_gym  # noqa: F401  (registration)
from sfw_gym.agents import AGENTS, agent_class, is_privileged, make_agent
from sfw_gym.agents.oracles import ORACLE_PREFIX
from sfw_gym.cli import build_parser
from sfw_gym.core.constants import U8_FREE, U8_UNKNOWN
from sfw_gym.core.data import data_path
from sfw_gym.core.errors import ConfigError
from sfw_gym.demo import DEMO_AGENTS
from sfw_gym.envs.robot_view_info import RobotViewInInfo
from sfw_gym.evaluation import benchmark as bm
from sfw_gym.evaluation import evaluate
from sfw_gym.evaluation.benchmark import results_markdown as benchmark_markdown
from sfw_gym.evaluation.metric_table import TABLE_METRICS
from sfw_gym.evaluation.report import PRIVILEGED_NOTE, results_markdown
from sfw_gym.navigation.planning import cost_field, wall_distance_m
from sfw_gym.world.floorplan import Floorplan
from tests.agents.test_agents import _reachable
from tests.conftest import script_module

ROOT = Path(__file__).resolve().parents[2]
ORACLES = sorted(n for n in AGENTS if agent_class(n).privileged)


def two_rooms() -> Floorplan:
    """Two 4 x 4 m rooms; the 0.2 m brick wall between them (x 4.0-4.2) has a door at y 1.5-2.5."""
    left = [(0, 0), (4, 0), (4, 1.5), (4.2, 1.5), (4.2, 0)]
    right = [(8.2, 0), (8.2, 4), (4.2, 4), (4.2, 2.5), (4, 2.5), (4, 4), (0, 4)]
    free = Polygon([*left, *right])
    shell = Polygon([(-0.2, -0.2), (8.4, -0.2), (8.4, 4.2), (-0.2, 4.2)])
    return Floorplan(free, shell, ("brick",) * 12, name="two-rooms")


def test_every_oracle_is_named_and_marked_as_one():
    assert "oracle-coverage" in ORACLES
    for name in AGENTS:
        assert agent_class(name).privileged == name.startswith(ORACLE_PREFIX), name
        assert is_privileged(name) == name.startswith(ORACLE_PREFIX)


@pytest.mark.parametrize("name", ORACLES)
def test_an_oracle_needs_the_env_itself(name):
    env = RobotViewInInfo(gym.make("SfW-ExploreSmall-v0"))
    _, info = env.reset(seed=0)
    with pytest.raises(ConfigError, match="oracle"):
        make_agent(name).reset(info=info, seed=0)
    with pytest.raises(ConfigError, match="oracle"):  # a stand-in with only robot_view()
        make_agent(name).reset(SimpleNamespace(robot_view=env.unwrapped.robot_view), seed=0)


@pytest.mark.parametrize("name", ORACLES)
def test_an_oracle_holds_the_ground_truth_that_robot_agents_may_not(name):
    """The object-graph check that keeps the robot agents from the ground truth sees an
    oracle's: so it would see a robot agent's."""
    env = gym.make("SfW-ExploreSmall-v0")
    obs, _ = env.reset(seed=3)
    agent = make_agent(name)
    agent.reset(env, seed=3)
    for _ in range(3):
        obs, *_ = env.step(agent.act(obs))
    truth = (env.unwrapped, env.unwrapped.scene.floorplan)
    held = {id(o) for o in _reachable(agent, stop=(ModuleType,), until=truth)}
    assert id(env.unwrapped) in held
    assert id(env.unwrapped.scene.floorplan) in held


def test_no_default_runs_an_oracle():
    assert not any(is_privileged(a) for a in DEMO_AGENTS)
    evaluate = build_parser().parse_args(["evaluate"])
    assert not any(is_privileged(a) for a in evaluate.agents.split(","))
    shipped = script_module("benchmarks/benchmark_shipped.py")
    assert set(shipped.shipped_agents()) == {n for n in AGENTS if n not in ORACLES}


def test_tables_mark_an_oracle_as_privileged():
    row = {"agent": "oracle-coverage", "episodes": 0, "episodes_coverage_ge_90": 0}
    for m in TABLE_METRICS:
        row |= {f"{m.key}_mean": 0.0, f"{m.key}_ci95": 0.0, f"{m.key}_n": 0}
    assert PRIVILEGED_NOTE not in results_markdown([row | {"privileged": False}])
    table = results_markdown([row | {"privileged": True}])
    assert "| oracle-coverage † |" in table and PRIVILEGED_NOTE in table
    results = {
        "agent": "oracle-coverage",
        "protocol": "benchmark-v1",
        "split": "test",
        "package_version": "0",
        "agent_seed": 0,
        "protocol_sha256": "0" * 64,
        "summary": {},
    }
    assert PRIVILEGED_NOTE not in benchmark_markdown(results | {"privileged": False})
    assert PRIVILEGED_NOTE in benchmark_markdown(results | {"privileged": True})


def test_an_evaluation_and_a_benchmark_record_and_mark_an_oracle(tmp_path):
    short = {"max_steps": 20}
    result = evaluate(
        ["frontier", "oracle-coverage"],
        1,
        out=tmp_path / "ev",
        env_id="SfW-ExploreSmall-v0",
        env_kwargs=short,
        workers=1,
        progress=False,
    )
    assert {r["agent"]: r["privileged"] for r in result["records"]} == {
        "frontier": False,
        "oracle-coverage": True,
    }
    table = (tmp_path / "ev" / "results.md").read_text(encoding="utf-8")
    assert "| oracle-coverage † |" in table and "| frontier |" in table
    assert PRIVILEGED_NOTE in table
    protocol = yaml.safe_load(data_path("envs", "benchmark-v1.yml").read_text(encoding="utf-8"))
    protocol["envs"] = [{**protocol["envs"][0], "kwargs": short}]
    path = tmp_path / "short.yml"
    path.write_text(yaml.safe_dump(protocol), encoding="utf-8")
    for name, privileged in (("oracle-coverage", True), ("random", False)):
        results = bm.run_benchmark(
            name, protocol=path, out=tmp_path / name, episodes=1, progress=False
        )
        assert results["privileged"] is privileged
        assert (PRIVILEGED_NOTE in (tmp_path / name / "results.md").read_text()) is privileged


def test_coverage_and_bits_per_metre_at_a_budget_read_the_last_sample_at_or_before_it():
    study = script_module("studies/regions_study.py")
    curve = [
        [0, 0.0, 0.0, 0.0, 100.0],
        [10, 0.2, 0.0, 1.0, 90.0],
        [20, 0.5, 0.0, 2.0, 70.0],
        [25, 0.6, 0.0, 2.5, 60.0],
    ]
    assert study.curve_at(curve, 10) == (0.2, 10.0)
    assert study.curve_at(curve, 19) == (0.2, 10.0)
    assert study.curve_at(curve, 1000) == (0.6, 16.0)  # ended earlier: its final values
    old = [row[:4] for row in curve]  # a record from before issue 46: no entropy
    assert study.curve_at(old, 20)[0] == 0.5 and np.isnan(study.curve_at(old, 20)[1])


# ------------------------------------------------------------------------- the coverage oracle
def oracle_on_two_rooms(router_xy, **params):
    """The coverage oracle reset on the two rooms with one router."""
    env = gym.make("SfW-Explore-v0", n_routers=1)
    env.reset(seed=0, options={"floorplan": two_rooms(), "routers": [router_xy]})
    agent = make_agent("oracle-coverage", **params)
    agent.reset(env, seed=0)
    return env, agent


def hand_view(env, unknown_xy):
    """The robot's view with a belief that is free everywhere but at ``unknown_xy`` (log-odds
    0 there: one bit each)."""
    view = env.unwrapped.robot_view()
    belief = np.full(view.belief_u8.shape, U8_FREE, np.uint8)
    log_odds = np.full(view.log_odds.shape, -4.0, np.float32)
    for rc in view.grid.world_to_cell(np.asarray(unknown_xy, np.float64)):
        belief[tuple(rc)], log_odds[tuple(rc)] = U8_UNKNOWN, 0.0
    return type(view)(**{**vars(view), "belief_u8": belief, "log_odds": log_odds})


def cell(env, xy):
    return env.unwrapped.grid.world_to_cell(np.asarray(xy, np.float64))


def test_gain_counts_the_unknown_cells_on_the_ray_to_a_router_in_sight():
    env, oracle = oracle_on_two_rooms((0.55, 2.05))
    at = cell(env, (3.05, 2.05))[None]
    # one unknown cell on the ray, halfway: one bit; two: two bits; one off the ray: none
    assert oracle.gains(hand_view(env, [(1.85, 2.05)]), at)[0] == pytest.approx(1.0)
    two = [(1.85, 2.05), (2.45, 2.05)]
    assert oracle.gains(hand_view(env, two), at)[0] == pytest.approx(2.0)
    assert oracle.gains(hand_view(env, [(1.85, 3.05)]), at)[0] == 0.0
    # beyond the router (the ray ends there) and behind the robot: none
    assert oracle.gains(hand_view(env, [(0.25, 2.05), (3.65, 2.05)]), at)[0] == 0.0
    # in the robot's footprint: one bit
    assert oracle.gains(hand_view(env, [(3.15, 2.05)]), at)[0] == pytest.approx(1.0)


def test_a_wall_between_cell_and_router_weighs_its_free_stretch_and_ends_it():
    env, oracle = oracle_on_two_rooms((0.55, 3.05), blocked_ray_weight=0.25)
    at = cell(env, (6.05, 3.05))[None]  # the wall at x 4.0-4.2 stands between
    near, far = (5.05, 3.05), (2.05, 3.05)  # the free stretch on this side; beyond the wall
    assert oracle.gains(hand_view(env, [near]), at)[0] == pytest.approx(0.25)
    assert oracle.gains(hand_view(env, [far]), at)[0] == 0.0
    assert oracle.gains(hand_view(env, [(6.15, 3.05)]), at)[0] == pytest.approx(1.0)  # footprint


def test_the_coverage_oracle_covers_a_small_plan_within_its_budget():
    for seed in (1, 2):  # on seed 2 the tour goes round again
        env = gym.make("SfW-Explore-v0", max_steps=1500)
        obs, info = env.reset(seed=seed, options={"floorplan": two_rooms()})
        target = env.unwrapped.config.reward.coverage_target
        agent = make_agent("oracle-coverage")
        agent.reset(env, seed=seed)
        terminated = truncated = False
        while not (terminated or truncated):
            obs, _, terminated, truncated, info = env.step(agent.act(obs))
        assert terminated and info["coverage"] >= target, (seed, info["coverage"])
        assert agent.stop_reason is None
        # every target is logged, and each lies in the true free space
        assert len(agent.decisions) == agent.n_plans
        truth = env.unwrapped.ground_truth().truth_u8
        assert all(truth[d.target_rc] == U8_FREE for d in agent.decisions)


def test_the_shipped_region_actor_reads_no_true_plan():
    """No learned agent reads an oracle's input: on the privileged regions env (its observation
    holds the true plan, for the critic), the shipped actor's logits are the same whatever true
    plan the observation carries."""
    torch = pytest.importorskip("torch")
    from sfw_gym.rl.agent import RegionsPPOAgent

    policy = RegionsPPOAgent().model.policy
    assert "true_map" not in policy.actor_keys
    env = gym.make("SfW-ExploreRegions-v0", privileged=True)
    obs, _ = env.reset(seed=2_000_000)
    other, _ = gym.make("SfW-ExploreRegions-v0", privileged=True).reset(seed=2_000_001)
    assert not np.array_equal(obs["true_map"], other["true_map"])
    for _ in range(3):
        with torch.no_grad():
            logits = [
                policy.actor_logits({k: torch.as_tensor(o[k])[None] for k in o})
                for o in (obs, {**obs, "true_map": other["true_map"]})
            ]
        assert torch.equal(*logits)
        obs, *_ = env.step(env.unwrapped.teacher_action())


def test_its_settings_shape_where_it_goes():
    """Targets keep ``margin_m`` clear of true walls beyond the radius and lie on the
    ``candidate_stride_cells`` lattice; the follower takes ``lookahead_m``; it replans at least
    ``replan_every_steps`` steps (one more after a target chosen on arrival, mid-step)."""
    env = gym.make("SfW-Explore-v0", max_steps=200)
    obs, _ = env.reset(seed=1, options={"floorplan": two_rooms()})
    params = {"margin_m": 0.2, "candidate_stride_cells": 3, "lookahead_m": 0.7}
    agent = make_agent("oracle-coverage", replan_every_steps=4, **params)
    agent.reset(env, seed=1)
    for _ in range(200):
        obs, *_ = env.step(agent.act(obs))
    truth = env.unwrapped.ground_truth()
    clear = wall_distance_m(truth.truth_u8 < U8_FREE, truth.grid.resolution_m)
    targets = np.array([d.target_rc for d in agent.decisions])
    assert (clear[targets[:, 0], targets[:, 1]] > 0.17 + 0.2).all()
    assert (targets % 3 == 0).all()
    assert agent.follower.lookahead_m == 0.7
    assert agent.n_plans >= 200 / 4
    steps = np.diff([d.step for d in agent.decisions])
    assert steps.max() <= 4 + 1


def two_cells_with_bits(bits):
    """A stand-in for the oracle's gains: ``bits`` at those cells, none elsewhere."""
    return lambda view, cells: np.array([bits.get(tuple(c), 0.0) for c in cells])


def test_it_chooses_by_bits_per_metre_with_the_offset(monkeypatch):
    """Two cells with something to gain: a near one with 1 bit and a far one with 3. Without
    an offset the near one has more bits per metre; with a large offset the far one does."""
    env, _ = oracle_on_two_rooms((0.55, 2.05))
    start = env.unwrapped.ground_truth().pose
    at = tuple(cell(env, start[:2]))
    near, far = (at[0], at[1] + 5), (at[0], at[1] - 25)
    chosen = {}
    for offset in (0.01, 100.0):
        oracle = make_agent("oracle-coverage", distance_offset_m=offset, candidate_stride_cells=1)
        oracle.reset(env, seed=0)
        monkeypatch.setattr(oracle, "gains", two_cells_with_bits({near: 1.0, far: 3.0}))
        oracle.plan(env.unwrapped.robot_view(), start)
        chosen[offset] = oracle.target_rc
    assert chosen == {0.01: near, 100.0: far}


# ------------------------------------------------- the variants: where the ceiling lives
def test_each_variant_gives_up_one_piece_of_knowledge():
    """Each variant differs from the coverage oracle in its one setting, and is an oracle."""
    for name, (field, value) in {
        "oracle-belief-paths": ("plan_on", "belief"),
        "oracle-frontier-targets": ("targets_from", "frontiers"),
        "oracle-belief-gain": ("gain_from", "belief"),
    }.items():
        settings = vars(make_agent(name).settings)
        base = vars(make_agent("oracle-coverage").settings)
        assert {k for k in base if base[k] != settings[k]} == {field} and settings[field] == value
        assert is_privileged(name)


def test_the_belief_gain_runs_to_the_router_past_a_wall_the_belief_does_not_hold():
    """The true gain stops at the true wall between the cell and the router; counted on a
    belief that holds no wall there, the ray runs on to the router, at full weight."""
    gains = {}
    for name in ("oracle-coverage", "oracle-belief-gain"):
        env = gym.make("SfW-Explore-v0", n_routers=1)
        env.reset(seed=0, options={"floorplan": two_rooms(), "routers": [(0.55, 3.05)]})
        oracle = make_agent(name, blocked_ray_weight=0.25)
        oracle.reset(env, seed=0)
        at = cell(env, (6.05, 3.05))[None]
        gains[name] = [
            oracle.gains(hand_view(env, [xy]), at)[0] for xy in [(5.05, 3.05), (2.05, 3.05)]
        ]
    assert gains["oracle-coverage"] == pytest.approx([0.25, 0.0])
    assert gains["oracle-belief-gain"] == pytest.approx([1.0, 1.0])


def test_frontier_targets_are_the_belief_s_frontier_cells():
    env = gym.make("SfW-Explore-v0", n_routers=1)
    env.reset(seed=0, options={"floorplan": two_rooms(), "routers": [(0.55, 3.05)]})
    oracle = make_agent("oracle-frontier-targets")
    oracle.reset(env, seed=0)
    view = hand_view(env, [(2.05, 2.05)])
    (r, c) = cell(env, (2.05, 2.05))
    targets = {tuple(t) for t in oracle._candidate_cells(view)}
    assert targets == {(r, c)}  # the one unknown cell, beside believed-free ones
    truth = make_agent("oracle-coverage")
    truth.reset(env, seed=0)
    assert len(truth._candidate_cells(view)) > 100 * len(targets)  # every cell the robot fits on


def test_belief_paths_go_round_a_wall_the_belief_holds():
    """A believed wall across the left room with a gap at its top: the path planned on the
    belief goes through the gap, the true path (no wall there) straight across."""
    env = gym.make("SfW-Explore-v0", n_routers=1)
    env.reset(seed=0, options={"floorplan": two_rooms(), "routers": [(0.55, 3.05)]})
    view = env.unwrapped.robot_view()
    grid = view.grid
    belief = np.full(view.belief_u8.shape, U8_FREE, np.uint8)
    wall = grid.world_to_cell(np.array([[2.05, y] for y in np.arange(0.05, 3.0, 0.1)]))
    belief[wall[:, 0], wall[:, 1]] = 0
    view = type(view)(**{**vars(view), "belief_u8": belief})
    start, goal = tuple(cell(env, (1.05, 1.05))), tuple(cell(env, (3.05, 1.05)))
    rows = {}
    for name in ("oracle-coverage", "oracle-belief-paths"):
        oracle = make_agent(name)
        oracle.reset(env, seed=0)
        true_paths = cost_field(oracle._cost, start, 0.1)
        path = oracle._driven_paths(view, start, true_paths).path(goal)
        rows[name] = max(grid.cell_to_world(np.asarray(path))[:, 1])
    assert rows["oracle-coverage"] < 1.5 and rows["oracle-belief-paths"] > 3.0


def test_the_study_labels_oracles_and_variants_by_their_settings():
    study = script_module("studies/regions_study.py")
    entry = "sfw_gym.rl.predict_explore:RolloutExploreAgent"
    agents, params, label = study.resolve_agents(
        ["frontier", "oracle-rollout", entry], {entry: {"horizon_steps": 60, "menu": "x"}}
    )
    assert agents == ["frontier", "oracle-rollout", entry]
    assert label["frontier"] == "frontier" and label["oracle-rollout"] == "oracle-rollout †"
    assert label[entry] == f"{entry} (horizon_steps=60, menu=x)"
    assert params == {entry: {"horizon_steps": 60, "menu": "x"}}

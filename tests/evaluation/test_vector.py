"""``sfw-gym evaluate --vector-envs N``: the episodes on the native vector env in this process,
each sub-env running one episode after another (reset with that episode's own seed and plan),
one agent per sub-env acting on its robot view, give the records of the sequential runner."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest

from sfw_gym import evaluation as ev
from sfw_gym.cli import main
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation.vector import SubEnvInfo

SMALL = "SfW-ExploreSmall-v0"


def _records(folder):
    """Each episode's record without its timing, by key, as the checkpoint holds it."""
    lines = (folder / ev.CHECKPOINT).read_text().splitlines()
    return {r["key"]: {k: v for k, v in r.items() if k != "wall_s"} for r in map(json.loads, lines)}


def _same_npz(a_folder, b_folder):
    """Every episode's ``.npz`` holds the same arrays in both runs (the final maps, the
    trajectory, the decision log)."""
    names = sorted(p.name for p in (a_folder / "episodes").glob("*.npz"))
    assert names == sorted(p.name for p in (b_folder / "episodes").glob("*.npz"))
    for name in names:
        a, b = np.load(a_folder / "episodes" / name), np.load(b_folder / "episodes" / name)
        assert a.files == b.files
        for k in a.files:
            assert np.array_equal(a[k], b[k], equal_nan=a[k].dtype.kind == "f"), (name, k)
    return names


@pytest.mark.episode
def test_frontier_and_cross_pass_on_two_vector_envs_give_the_sequential_records(tmp_path, capsys):
    # 6 episodes on 2 sub-envs: each sub-env runs three in a row; a low coverage target ends
    # them at different steps (44 to 80), so the sub-envs start their next episodes out of step
    argv = ["evaluate", "--agents", "frontier,cross-pass", "--episodes", "3", "--seed", "4"]
    argv += ["--env", SMALL, "--no-progress"]
    argv += ["--env-kwargs", '{"max_steps": 80, "coverage_target": 0.06}']
    assert main([*argv, "--workers", "1", "--out", str(tmp_path / "seq")]) == 0
    assert main([*argv, "--vector-envs", "2", "--out", str(tmp_path / "vec")]) == 0
    sequential, vector = _records(tmp_path / "seq"), _records(tmp_path / "vec")
    assert len(sequential) == 6 and vector == sequential
    assert len({r["steps"] for r in vector.values()}) > 2  # the episodes end out of step
    assert any(r["terminated"] for r in vector.values())
    assert len({r["floorplan"] for r in vector.values()}) == 3  # each its own seed's plan
    assert len(_same_npz(tmp_path / "seq", tmp_path / "vec")) == 6
    capsys.readouterr()


@pytest.mark.episode
def test_an_idle_sub_env_stands_by_on_a_discrete_env(tmp_path):
    # 3 episodes on 2 sub-envs: the second idles (turning on the spot) through the third episode
    run = dict(env_id=SMALL, env_kwargs={"max_steps": 30, "action_type": "discrete"})
    run |= dict(progress=False)
    ev.evaluate(["frontier"], 3, seed=1, out=tmp_path / "seq", workers=1, **run)
    ev.evaluate(["frontier"], 3, seed=1, out=tmp_path / "vec", vector_envs=2, **run)
    assert _records(tmp_path / "vec") == _records(tmp_path / "seq")
    _same_npz(tmp_path / "seq", tmp_path / "vec")


@pytest.mark.slow
def test_mixed_agents_and_plan_files_on_vector_envs_match_too(tmp_path):
    from sfw_gym.world.generator import generate_floorplan

    plans = tmp_path / "plans"
    for s in (1, 2):
        generate_floorplan(s, area_m2=45.0).save(plans / f"plan{s}.json")
    run = dict(env_id=SMALL, env_kwargs={"max_steps": 40}, floorplans=plans, progress=False)
    agents = ["frontier", "random"]
    ev.evaluate(agents, 2, seed=9, out=tmp_path / "seq", workers=1, **run)
    ev.evaluate(agents, 2, seed=9, out=tmp_path / "vec", vector_envs=3, **run)
    vector = _records(tmp_path / "vec")
    assert vector == _records(tmp_path / "seq") and len(vector) == 4
    assert {r["floorplan_file"].rsplit("/", 1)[-1] for r in vector.values()} == {
        "plan1.json",
        "plan2.json",
    }


def test_a_sub_envs_info_holds_only_what_its_masks_mark():
    batched = {
        "coverage": np.array([0.1, 0.2]),
        "_coverage": np.array([True, True]),
        "summary": {"steps": np.array([0, 7]), "_steps": np.array([False, True])},
        "_summary": np.array([False, True]),
        "_private": np.array([1, 2]),  # an info key that starts with "_", with its own mask
        "__private": np.array([True, False]),
    }
    first, second = SubEnvInfo(batched, 0), SubEnvInfo(batched, 1)
    assert dict(first) == {"coverage": 0.1, "_private": 1} and "summary" not in first
    assert second["coverage"] == 0.2 and dict(second["summary"]) == {"steps": 7}
    assert first.get("summary", {}) == {} and len(second) == 2


def test_vector_envs_refuse_what_they_cannot_do(tmp_path):
    run = dict(env_id=SMALL, env_kwargs={"max_steps": 20}, progress=False, out=tmp_path)
    with pytest.raises(ConfigError, match="--vector-envs must be an int >= 1, got 0"):
        ev.evaluate(["random"], 1, vector_envs=0, **run)
    with pytest.raises(ConfigError, match="not with --backend ray or --gif"):
        ev.evaluate(["random"], 1, vector_envs=2, gif_episodes=1, **run)
    gym.register("SfWTest-NoNativeVector-v0", entry_point=gym.spec(SMALL).entry_point)
    try:
        with pytest.raises(ConfigError, match="SfWTest-NoNativeVector-v0 has no native vector"):
            ev.evaluate(
                ["random"], 1, vector_envs=2, **(run | {"env_id": "SfWTest-NoNativeVector-v0"})
            )
    finally:
        gym.registry.pop("SfWTest-NoNativeVector-v0")

"""``sfw-gym evaluate --vector-envs N``: the episodes on a gymnasium vector env, each sub-env
reset with its own episode's seed and plan, the agents acting on ``info["robot_view"]``, give the
records of the sequential runner."""

from __future__ import annotations

import json

import numpy as np
import pytest

from sfw_gym import evaluation as ev
from sfw_gym.cli import main
from sfw_gym.core.errors import ConfigError

SMALL = "SfW-ExploreSmall-v0"


def _records(folder):
    """Each episode's record without its timing, by key, as the checkpoint holds it."""
    lines = (folder / ev.CHECKPOINT).read_text().splitlines()
    return {r["key"]: {k: v for k, v in r.items() if k != "wall_s"} for r in map(json.loads, lines)}


@pytest.mark.episode
def test_frontier_on_two_vector_envs_gives_the_sequential_records(tmp_path, capsys):
    # 3 episodes on 2 sub-envs: one sub-env runs two episodes in a row, the other idles at the end
    argv = ["evaluate", "--agents", "frontier", "--episodes", "3", "--seed", "4", "--env", SMALL]
    argv += ["--env-kwargs", '{"max_steps": 60}', "--no-progress"]
    assert main([*argv, "--workers", "1", "--out", str(tmp_path / "seq")]) == 0
    assert main([*argv, "--vector-envs", "2", "--out", str(tmp_path / "vec")]) == 0
    sequential, vector = _records(tmp_path / "seq"), _records(tmp_path / "vec")
    assert len(sequential) == 3 and vector == sequential
    assert len({r["floorplan"] for r in vector.values()}) == 3  # each its own seed's plan
    for name in ("frontier_0000.npz", "frontier_0002.npz"):  # the final maps too
        a, b = (np.load(tmp_path / run / "episodes" / name) for run in ("seq", "vec"))
        assert all(np.array_equal(a[k], b[k], equal_nan=a[k].dtype.kind == "f") for k in a.files)
    capsys.readouterr()


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


def test_vector_envs_refuse_what_they_cannot_do(tmp_path):
    run = dict(env_id=SMALL, env_kwargs={"max_steps": 20}, progress=False, out=tmp_path)
    with pytest.raises(ConfigError, match="--vector-envs must be an int >= 1, got 0"):
        ev.evaluate(["random"], 1, vector_envs=0, **run)
    with pytest.raises(ConfigError, match="not with --backend ray or --gif"):
        ev.evaluate(["random"], 1, vector_envs=2, gif_episodes=1, **run)

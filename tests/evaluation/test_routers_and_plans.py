"""Your building through ``evaluate`` and ``benchmark run``: the routers each episode used
(``--routers``, else the plan's own, else the env's k-means placement) and the plans it ran on
(a folder of JSON plans and ROS map YAMLs), read back from the records."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest
from PIL import Image
from shapely.geometry import Polygon

import sfw_gym  # noqa: F401  (registration)
from sfw_gym import evaluation as ev
from sfw_gym.cli import main
from sfw_gym.core.errors import ConfigError, FloorplanError
from sfw_gym.envs.explore import unwrap_sfw
from sfw_gym.evaluation import benchmark as bm
from sfw_gym.world import floorplan_from_polygon

SMALL = "SfW-ExploreSmall-v0"
TINY = {"env_id": SMALL, "env_kwargs": {"max_steps": 20}, "workers": 1, "progress": False}
#: Routers the plan ``hall_r.json`` stores.
STORED = [[3.0, 3.0], [9.0, 5.0]]


def write_plans(folder: Path) -> Path:
    """``hall.json`` (no routers), ``hall_r.json`` (routers :data:`STORED`), ``office.yaml``
    (a ROS map, its ``office.pgm`` beside it) in ``folder``."""
    folder.mkdir(exist_ok=True)
    hall = floorplan_from_polygon(Polygon([(0, 0), (12, 0), (12, 8), (0, 8)]), name="hall")
    hall.save(folder / "hall.json")
    stored = hall.to_dict() | {"name": "hall-r", "routers": STORED}
    (folder / "hall_r.json").write_text(json.dumps(stored))
    image = np.zeros((120, 200), np.uint8)  # 10 m x 6 m at 5 cm: a free room, a half wall
    image[10:110, 10:190] = 254
    image[10:80, 98:102] = 0
    Image.fromarray(image).save(folder / "office.pgm")
    (folder / "office.yaml").write_text(
        "image: office.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        "occupied_thresh: 0.65\nfree_thresh: 0.196\n"
    )
    return folder


def records(out: Path) -> list[dict]:
    lines = (out / "episodes.jsonl").read_text(encoding="utf-8").splitlines()
    return sorted((json.loads(line) for line in lines), key=lambda r: r["episode"])


def kmeans_routers(plan: str, seed: int) -> list[list[float]]:
    """The routers the env places itself on ``plan`` reset with ``seed``."""
    env = gym.make(SMALL)
    env.reset(seed=seed, options={"floorplan": plan})
    routers = np.asarray(unwrap_sfw(env).ground_truth().radio.routers).tolist()
    env.close()
    return routers


@pytest.mark.episode
def test_a_folder_of_json_plans_and_ros_maps_runs_each_with_its_routers(tmp_path):
    plans = write_plans(tmp_path / "plans")
    result = ev.evaluate(["random"], 3, 7, out=tmp_path / "run", floorplans=plans, **TINY)
    runs = records(tmp_path / "run")
    names = [Path(r["floorplan_file"]).name for r in runs]
    assert names == ["hall.json", "hall_r.json", "office.yaml"]
    assert [r["floorplan"] for r in runs] == ["hall", "hall-r", "office"]
    hall, stored, office = (r["routers"] for r in runs)
    assert stored == STORED  # the plan's own routers
    assert hall == kmeans_routers(str(plans / "hall.json"), runs[0]["seed"])  # k-means
    assert office == kmeans_routers(str(plans / "office.yaml"), runs[2]["seed"])
    assert hall != STORED and len(result["records"]) == 3
    with np.load(tmp_path / "run" / "episodes" / "random_0001.npz") as npz:
        assert npz["routers"].tolist() == STORED


@pytest.mark.episode
def test_routers_given_place_every_episode_s_over_the_plan_s_own(tmp_path, capsys):
    plans = write_plans(tmp_path / "plans")
    argv = ["evaluate", "--agents", "random", "--episodes", "2", "--env", SMALL]
    argv += ["--env-kwargs", '{"max_steps": 20}', "--workers", "1", "--no-progress"]
    argv += ["--floorplans", str(plans / "hall_r.json"), "--out", str(tmp_path / "fixed")]
    assert main([*argv, "--routers", "2,2;10,6"]) == 0
    assert [r["routers"] for r in records(tmp_path / "fixed")] == [[[2.0, 2.0], [10.0, 6.0]]] * 2
    config = json.loads((tmp_path / "fixed" / "config.json").read_text())
    assert config["routers"] == [[2.0, 2.0], [10.0, 6.0]]
    # a count: placed by k-means, over the plan's own too
    argv[argv.index("--out") + 1] = str(tmp_path / "count")
    assert main([*argv, "--routers", "1"]) == 0
    assert [len(r["routers"]) for r in records(tmp_path / "count")] == [1, 1]
    # the same folder with other routers: refused, its records ran with these
    capsys.readouterr()
    assert main([*argv, "--routers", "2"]) == 2
    assert "ran with routers 1, this run asks for 2" in capsys.readouterr().err


@pytest.mark.episode
def test_routers_reach_the_vector_env_s_episodes(tmp_path):
    plans = write_plans(tmp_path / "plans")
    run = dict(TINY, floorplans=plans / "hall.json", vector_envs=2)
    ev.evaluate(["random"], 2, out=tmp_path / "v", routers=np.array([[2.0, 2.0]]), **run)
    assert [r["routers"] for r in records(tmp_path / "v")] == [[[2.0, 2.0]]] * 2


def test_routers_the_env_refuses_and_folders_with_no_plan_are_one_line_errors(tmp_path):
    plans = write_plans(tmp_path / "plans")
    hall, out = plans / "hall.json", tmp_path / "a"
    with pytest.raises(ConfigError, match=r"--routers: router 1 at \(13\.000, 6\.000\) is outside"):
        ev.evaluate(["random"], 1, out=out, floorplans=hall, routers=[[2, 2], [13, 6]], **TINY)
    with pytest.raises(ConfigError, match="--routers: routers: 3 positions given"):
        ev.evaluate(["random"], 1, out=out, floorplans=hall, routers=[[2, 2]] * 3, **TINY)
    images = tmp_path / "images"
    images.mkdir()
    (images / "office.pgm").write_bytes((plans / "office.pgm").read_bytes())
    for folder in (images, tmp_path / "missing"):
        with pytest.raises(ConfigError, match=rf"--floorplans {folder}: no floorplan files there"):
            ev.evaluate(["random"], 1, out=tmp_path / "a", floorplans=folder, **TINY)


def test_a_malformed_plan_in_the_folder_fails_before_any_episode(tmp_path):
    plans = write_plans(tmp_path / "plans")
    (plans / "office.yaml").write_text("image: gone.pgm\nresolution: 0.05\n")
    with pytest.raises(FloorplanError, match=r"office\.yaml"):
        ev.evaluate(["random"], 3, out=tmp_path / "a", floorplans=plans, **TINY)
    assert not (tmp_path / "a" / "episodes.jsonl").exists()


@pytest.mark.episode
def test_benchmark_run_takes_ros_maps_the_plans_routers_and_routers(tmp_path):
    plans = write_plans(tmp_path / "plans")
    protocol = yaml_protocol(tmp_path / "tiny.yml")
    common = ["benchmark", "run", "--agent", "random", "--protocol", str(protocol)]
    common += ["--split", "test", "--plans", str(plans), "--workers", "1", "--no-progress"]
    assert main([*common, "--out", str(tmp_path / "own")]) == 0
    runs = {Path(r["floorplan_file"] or "procedural").name: r for r in records(tmp_path / "own")}
    assert sorted(runs) == ["hall.json", "hall_r.json", "office.yaml", "procedural"]
    assert runs["hall_r.json"]["routers"] == STORED
    hall = runs["hall.json"]
    assert hall["routers"] == kmeans_routers(str(plans / "hall.json"), hall["seed"])
    assert "routers" not in json.loads((tmp_path / "own" / "results.json").read_text())
    assert main([*common, "--routers", "1", "--out", str(tmp_path / "one")]) == 0
    assert [len(r["routers"]) for r in records(tmp_path / "one")] == [1, 1, 1, 1]
    assert json.loads((tmp_path / "one" / "results.json").read_text())["routers"] == 1


def yaml_protocol(path: Path) -> Path:
    """benchmark-v1 on the small env at 20 steps, one procedural episode, every plan in test."""
    import yaml

    protocol = yaml.safe_load(bm.data_path("envs", "benchmark-v1.yml").read_text())
    protocol["envs"] = [
        {
            "id": SMALL,
            "kwargs": {"max_steps": 20},
            "episodes": {"train": 1, "validation": 1, "test": 1},
        }
    ]
    protocol["splits"]["plan_files"] = {"train": [], "validation": [], "test": list(range(10))}
    path.write_text(yaml.safe_dump(protocol))
    return path


def test_the_env_itself_takes_a_plan_s_routers_and_a_folder_s_ros_maps(tmp_path):
    plans = write_plans(tmp_path / "plans")
    env = gym.make(SMALL, floorplan=str(plans))
    seen = set()
    for seed in range(12):  # a folder: each episode one of its plans, the ROS map among them
        env.reset(seed=seed)
        scene = unwrap_sfw(env).ground_truth()
        seen.add(scene.floorplan.name)
        routers = np.asarray(scene.radio.routers).tolist()
        assert (routers == STORED) == (scene.floorplan.name == "hall-r"), scene.floorplan.name
    assert seen == {"hall", "hall-r", "office"}
    env.reset(seed=0, options={"floorplan": str(plans / "hall_r.json"), "routers": [[6.0, 4.0]]})
    assert np.asarray(unwrap_sfw(env).ground_truth().radio.routers).tolist() == [[6.0, 4.0]]
    env.close()
    (tmp_path / "empty").mkdir()
    with pytest.raises(ConfigError, match=r"floorplan folder .*empty holds no plan file"):
        gym.make(SMALL, floorplan=str(tmp_path / "empty"))

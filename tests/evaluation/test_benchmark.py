"""``sfw-gym benchmark``: the protocol's splits, reproducible results files, the paired
comparison and its refusals, the guide's example agent as written, and the shipped models'
training never touching the test split."""

from __future__ import annotations

import csv
import functools
import itertools
import json
import re
import shlex
from pathlib import Path

import gymnasium as gym
import pytest
import yaml

from sfw_gym.cli import main
from sfw_gym.core.data import data_path
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation import benchmark as bm

REPO = Path(__file__).resolve().parents[2]
GUIDE = REPO / "docs" / "benchmark.md"
HOUSEEXPO = REPO.parent / "shared" / "floorplans" / "houseexpo"


def _without_timing(path: Path) -> dict:
    results = json.loads(path.read_text())
    results.pop("timing")
    return results


def test_the_shipped_protocol_has_disjoint_seed_and_plan_splits():
    protocol = bm.load_protocol("benchmark-v1")
    ranges = [bm.split_seeds(protocol, s) for s in bm.SPLITS]
    for (_, last), (first, _) in itertools.pairwise(ranges):
        assert last < first
    if HOUSEEXPO.is_dir():
        parts = [set(bm.split_plan_files(protocol, HOUSEEXPO, s)) for s in bm.SPLITS]
        assert not (parts[0] & parts[1] or parts[0] & parts[2] or parts[1] & parts[2])
        assert set().union(*parts) == set(HOUSEEXPO.glob("*.json"))
    with pytest.raises(ConfigError, match="--split must be one of"):
        bm.split_seeds(protocol, "holdout")
    with pytest.raises(ConfigError, match="--protocol benchmark-v9: cannot read"):
        bm.load_protocol("benchmark-v9")


@pytest.mark.episode
def test_running_the_benchmark_twice_gives_the_same_results_files(tmp_path):
    options = ["--agent", "random", "--split", "validation", "--episodes", "1"]
    # `benchmark run`, and the bare form kept from before the subcommands
    for run, argv in (("a", ["benchmark", "run", *options]), ("b", ["benchmark", *options])):
        out = tmp_path / run
        assert main([*argv, "--out", str(out), "--workers", "1", "--no-progress"]) == 0
    assert _without_timing(tmp_path / "a" / "results.json") == _without_timing(
        tmp_path / "b" / "results.json"
    )
    a_text = (tmp_path / "a" / "results.json").read_text()
    b_text = (tmp_path / "b" / "results.json").read_text()
    strip = re.compile(r'"timing": \{[^}]*\}')
    assert strip.sub("", a_text) == strip.sub("", b_text)  # byte for byte but the timing
    assert (tmp_path / "a" / "results.md").read_bytes() == (
        tmp_path / "b" / "results.md"
    ).read_bytes()
    results = json.loads(a_text)
    assert results["protocol"] == "benchmark-v1" and results["protocol_version"] == 1
    assert {r["env_id"] for r in results["episodes"]} == {"SfW-Explore-v0", "SfW-ExploreDrift-v0"}
    assert [r["seed"] for r in results["episodes"]] == [1_000_000, 1_000_000]


@pytest.mark.slow
def test_compare_pairs_episodes_and_refuses_other_protocols(tmp_path, capsys):
    common = ["--split", "validation", "--episodes", "1", "--workers", "1", "--no-progress"]
    for agent in ("frontier", "random"):
        out = tmp_path / agent
        assert main(["benchmark", "--agent", agent, *common, "--out", str(out)]) == 0
    capsys.readouterr()
    a, b = tmp_path / "frontier" / "results.json", tmp_path / "random" / "results.json"
    assert main(["benchmark", "compare", str(a), str(b)]) == 0
    table = capsys.readouterr().out
    assert "random − frontier" in table
    row = next(line for line in table.splitlines() if "SfW-Explore-v0 | coverage" in line)
    cells = [c.strip() for c in row.strip("|").split("|")]
    first, second, diff = float(cells[3]), float(cells[4]), float(cells[5].split()[0])
    assert diff == pytest.approx(second - first, abs=2e-3)
    other = json.loads(b.read_text())
    other["protocol_version"] = 2
    changed = tmp_path / "v2.json"
    changed.write_text(json.dumps(other))
    assert main(["benchmark", "compare", str(a), str(changed)]) == 2
    assert "different protocol versions: 1 vs 2" in capsys.readouterr().err


def test_a_folder_of_another_run_is_refused(tmp_path, capsys):
    common = ["--split", "validation", "--episodes", "1", "--workers", "1", "--no-progress"]
    out = ["--out", str(tmp_path)]
    assert main(["benchmark", "--agent", "random", *common, *out]) == 0
    capsys.readouterr()
    # the run's files: one episode per env of the protocol, a table per env
    results = bm.load_results(tmp_path / "results.json")
    assert [r["env_id"] for r in results["episodes"]] == ["SfW-Explore-v0", "SfW-ExploreDrift-v0"]
    table = (tmp_path / "results.md").read_text(encoding="utf-8")
    assert "\n## SfW-ExploreDrift-v0 (1 episodes)\n\n| metric | value |\n|---|---:|\n" in table
    params = ["--agent-params", '{"hold_steps": 2}']
    assert main(["benchmark", "--agent", "random", *common, *out, *params]) == 2
    assert "holds another benchmark run (different agent_params)" in capsys.readouterr().err


def _guide_blocks(language: str) -> list[str]:
    return re.findall(rf"```{language}\n(.*?)```", GUIDE.read_text(encoding="utf-8"), re.S)


@pytest.mark.slow
def test_the_guides_example_agent_runs_through_the_benchmark_as_written(
    tmp_path, monkeypatch, capsys
):
    (code,) = _guide_blocks("python")
    assert len(code.strip().splitlines()) <= 25  # a short example
    (tmp_path / "my_agent.py").write_text(code)
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))  # what the command does for the spawned workers
    (commands,) = _guide_blocks("bash")
    for line in commands.strip().splitlines():
        argv = shlex.split(line)
        assert argv[0] == "sfw-gym"
        assert main(argv[1:]) == 0, line
    results = json.loads((tmp_path / "bench" / "mine" / "results.json").read_text())
    assert results["agent"] == "my_agent:BumpAndTurn"
    assert "paired by episode" in capsys.readouterr().out  # the compare line ran


def _trained_plans(folder: Path) -> set[str]:
    plans = set()
    for monitor in folder.glob("*.monitor.csv"):
        lines = monitor.read_text(encoding="utf-8").splitlines()[1:]  # a JSON header first
        plans |= {row["floorplan"] for row in csv.DictReader(lines)}
    return plans


@pytest.mark.parametrize("model", ["ppo/SfW-Explore-v0_1", "ppo_mask/SfW-ExploreGoals-v0_1"])
def test_the_shipped_models_never_trained_on_the_test_split(model):
    import yaml

    folder = data_path("agents", *model.split("/"))
    config = yaml.safe_load((folder / "config.yml").read_text(encoding="utf-8"))
    protocol = bm.load_protocol("benchmark-v1")
    first, last = bm.split_seeds(protocol, "test")
    n_envs = int(config.get("n_envs", 1))
    # the training workers were reset with seeds seed … seed + n_envs - 1
    train_first, train_last = bm.split_seeds(protocol, "train")
    assert train_first <= config["seed"] and config["seed"] + n_envs - 1 <= train_last
    trained = _trained_plans(folder)
    assert len(trained) > 10
    tested = _test_split_plans()
    assert first + len(tested) <= last
    assert not trained & tested


@functools.cache
def _test_split_plans() -> frozenset[str]:
    """The plans the benchmark's test episodes reset to (the same for every model)."""
    protocol = bm.load_protocol("benchmark-v1")
    first, _ = bm.split_seeds(protocol, "test")
    env = gym.make("SfW-Explore-v0")
    return frozenset(
        env.reset(seed=first + i)[1]["floorplan"]
        for env_spec in protocol["envs"]
        for i in range(env_spec["episodes"]["test"])
    )


def test_unreached_90_percent_counts_as_the_budget_and_all_zero_metrics_are_left_out():
    protocol = bm.load_protocol("benchmark-v1")
    record = {
        "env_id": "SfW-Explore-v0",
        "seed": 5,
        "floorplan": "gen-5",
        "steps": 3000,
        "max_steps": 3000,
        "steps_to_coverage_90": -1,  # never got there
        **{m: 0.5 for m in ("coverage", "info_gain_per_m", "path_length_m", "free_iou")},
        **{m: 0.5 for m in ("wall_precision", "interior_wall_recall")},
        "ate_m": 0.0,  # no drift: no pose error to report
    }
    row = bm._episode_row(record, protocol)
    assert row["steps_to_coverage_90"] == 3001
    reached = bm._episode_row({**record, "seed": 6, "steps_to_coverage_90": 1200}, protocol)
    summary = bm.summarize_results({"episodes": [row, reached]}, protocol)["SfW-Explore-v0"]
    assert summary["steps_to_coverage_90"]["mean"] == pytest.approx(2100.5)
    assert "ate_m" not in summary and summary["coverage"]["n"] == 2


@pytest.mark.episode
def test_another_agent_seed_runs_its_own_episodes(tmp_path):
    argv = ["benchmark", "--agent", "random", "--split", "validation", "--episodes", "1"]
    common = ["--workers", "1", "--no-progress"]
    for seed in ("0", "1"):
        out = ["--out", str(tmp_path / seed)]
        assert main([*argv, "--seed", seed, *common, *out]) == 0
    a = json.loads((tmp_path / "0" / "results.json").read_text())
    b = json.loads((tmp_path / "1" / "results.json").read_text())
    assert a["agent_seed"] == 0 and b["agent_seed"] == 1
    assert [r["coverage"] for r in a["episodes"]] != [r["coverage"] for r in b["episodes"]]


def test_a_protocol_file_of_ones_own_runs_with_its_env_kwargs(tmp_path, capsys):
    protocol = yaml.safe_load(data_path("envs", "benchmark-v1.yml").read_text(encoding="utf-8"))
    protocol["envs"] = [{**protocol["envs"][0], "kwargs": {"max_steps": 7}}]
    path = tmp_path / "short.yml"
    path.write_text(yaml.safe_dump(protocol), encoding="utf-8")
    results = bm.run_benchmark("random", protocol=path, out=tmp_path / "out", episodes=1)
    assert [r["steps"] for r in results["episodes"]] == [7]  # the env's budget from kwargs
    bar = capsys.readouterr().err  # the progress bar, on by default
    assert "episodes" in bar and "1/1" in bar

"""Every ``sfw-gym`` command through its entry point, in one table: good input exits 0 and writes
its outputs; bad input exits 2 with one error line that names the offending argument (argparse's
usage lines may come first), never a traceback.

``demo``'s good run (three agents on full-size plans) is too slow for this table; it is covered by
``tests/cli/test_demo.py``. ``train``'s good case here is a single 32-step PPO rollout.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from sfw_gym.cli import EXAMPLES, build_parser, main
from sfw_gym.core.errors import ConfigError

SMALL = "SfW-ExploreSmall-v0"
TINY_PPO = f"""{SMALL}:
  policy: 'MultiInputPolicy'
  n_envs: 1
  n_steps: 32
  batch_size: 32
  n_epochs: 1
  policy_kwargs: "dict(net_arch=dict(pi=[8], vf=[8]))"
"""
#: Input files, written to tmp_path by the ``inputs`` fixture; "{tmp}" in argv is tmp_path.
INPUTS = {
    "log.csv": "x,y,r1\n0,0,-40\n1,0,-45\n1,1,-50\n0,1,-47\n",
    "log2.csv": "x,y,a,b\n0,0,-40,-60\n1,0,-45,-55\n1,1,-50,-50\n0,1,-47,-58\n",
    "badlog.csv": "x,y,r1\n0,0,-40\n1,0,-4O\n",  # a letter O
    "notjson.json": "{not json",
    "badplan.json": '{"verts": [[0, 0], [1, 0]]}',  # JSON, but no polygon: a FloorplanError
    "badplans/plan.json": '{"verts": [[0, 0], [1, 0]]}',
    "ppo.yml": TINY_PPO,
    "bad.yml": "a: [\n",  # PyYAML's message spans several lines
    "afile": "",
}

WORLD = ["world", "--out", "{tmp}/w.png", "--resolution", "0.5"]
MAP = ["map", "{tmp}/log.csv", "--routers", "0.5,0.5", "--out", "{tmp}/m.png"]
BENCH = ["speed", "--env", SMALL, "--steps", "20", "--resets", "1"]
EVALUATE = ["evaluate", "--agents", "random", "--episodes", "1", "--env", SMALL, "--workers", "1"]
EVALUATE += ["--no-progress", "--out", "{tmp}/ev", "--env-kwargs", '{"max_steps": 30}']
TRAIN = ["train", "ppo", "--env", SMALL, "--timesteps", "32", "--n-envs", "1", "--no-progress"]
TRAIN += ["--hyperparams", "{tmp}/ppo.yml", "--out", "{tmp}/run", "--eval-every", "1000000"]
DEMO = ["demo", "--out", "{tmp}/demo", "--episodes", "1", "--workers", "1", "--no-progress"]


def ok(argv: list[str], *outputs: str, id: str, marks=()):
    return pytest.param(argv, 0, None, outputs, id=id, marks=marks)


def bad(argv: list[str], error: str, id: str):
    """A later option overrides the same option earlier in argv (argparse keeps the last)."""
    return pytest.param(argv, 2, error, (), id=id)


CASES = [
    # -- world
    ok(
        ["world", "--seed", "3", "--out", "{tmp}/out/w.png", "--resolution", "0.3"],
        "out/w.png",
        id="world",
    ),
    bad([*WORLD, "--seed", "-1"], r"argument --seed: .*'-1'", id="world-seed-negative"),
    bad([*WORLD, "--resolution", "0"], r"argument --resolution: .*'0'", id="world-resolution-0"),
    bad([*WORLD, "--resolution", "nan"], r"argument --resolution", id="world-resolution-nan"),
    bad([*WORLD, "--routers", "0"], r"--routers: .*'0'", id="world-routers-0"),
    bad([*WORLD, "--routers", "1,2;3"], r"--routers: .*'1,2;3'", id="world-routers-malformed"),
    bad(
        [*WORLD, "--preset", "nope"],
        r"argument --preset: invalid choice: 'nope'",
        id="world-preset-unknown",
    ),
    bad([*WORLD, "--band", "7"], r"argument --band: invalid choice: '7'", id="world-band-unknown"),
    bad(
        [*WORLD, "--floorplan", "{tmp}/missing.json"],
        r"missing\.json: cannot read",
        id="world-floorplan-missing",
    ),
    bad(
        [*WORLD, "--floorplan", "{tmp}/notjson.json"],
        r"notjson\.json: not valid JSON",
        id="world-floorplan-not-json",
    ),
    bad(
        [*WORLD, "--floorplan", "{tmp}/badplan.json"],
        r"badplan\.json: .*at least 3",
        id="world-floorplan-malformed",
    ),
    bad(
        [*WORLD, "--seed", "1", "--floorplan", "{tmp}/badplan.json"],
        r"argument --floorplan: not allowed with argument --seed",
        id="world-seed-and-floorplan",
    ),
    # -- map
    ok(MAP, "m.png", "m.npy", "m.json", id="map"),
    bad(
        ["map", "{tmp}/missing.csv", "--routers", "1,1"],
        r"missing\.csv: no such file",
        id="map-log-missing",
    ),
    bad(
        ["map", "{tmp}/badlog.csv", "--routers", "1,1"],
        r"badlog\.csv:3: column 'r1'",
        id="map-log-malformed",
    ),
    bad(["map", "{tmp}", "--routers", "1,1"], r"is a directory", id="map-log-directory"),
    bad([*MAP, "--scale", "-1"], r"argument --scale: .*'-1'", id="map-scale-negative"),
    bad([*MAP, "--scale", "0"], r"argument --scale: .*'0'", id="map-scale-0"),
    bad([*MAP, "--resolution", "0"], r"argument --resolution: .*'0'", id="map-resolution-0"),
    bad([*MAP, "--margin", "-1"], r"argument --margin: .*'-1'", id="map-margin-negative"),
    bad([*MAP, "--routers", "2"], r"--routers: .*not a count", id="map-routers-count"),
    bad([*MAP, "--routers", "1,nan"], r"--routers: .*'1,nan'", id="map-routers-nan"),
    bad([*MAP, "--routers", "1,1;2,2"], r"2 router positions given", id="map-routers-too-many"),
    bad([*MAP, "--rssi-column", "7"], r"--rssi-column '7': no column", id="map-column-unknown"),
    bad([*MAP, "--scale", "1", "--px-per-m", "87"], r"not allowed with", id="map-two-units"),
    bad([*MAP, "--policy", "nope"], r"argument --policy: invalid choice", id="map-policy-unknown"),
    bad([*MAP, "--out", "{tmp}/m.jpg"], r"--out must be a \.png", id="map-out-not-png"),
    # -- bench
    ok(BENCH, id="bench"),
    bad([*BENCH, "--steps", "0"], r"argument --steps: .*'0'", id="bench-steps-0"),
    bad([*BENCH, "--steps", "-5"], r"argument --steps: .*'-5'", id="bench-steps-negative"),
    bad([*BENCH, "--steps", "ten"], r"argument --steps: .*'ten'", id="bench-steps-not-int"),
    bad([*BENCH, "--resets", "0"], r"argument --resets: .*'0'", id="bench-resets-0"),
    bad(
        [*BENCH, "--memory-steps", "-1"],
        r"argument --memory-steps: .*'-1'",
        id="bench-memory-steps-negative",
    ),
    bad([*BENCH, "--env", "Nope-v0"], r"--env Nope-v0: .*doesn't exist", id="bench-env-unknown"),
    bad(
        [*BENCH, "--agent-params", '{"random": 3}'],
        r"unrecognized arguments: --agent-params",
        id="bench-agent-params-unknown-option",
    ),
    # -- evaluate
    ok(EVALUATE, "ev/results.md", "ev/results.csv", "ev/coverage_vs_steps.png", id="evaluate"),
    bad([*EVALUATE, "--episodes", "0"], r"argument --episodes: .*'0'", id="evaluate-episodes-0"),
    bad([*EVALUATE, "--workers", "0"], r"argument --workers: .*'0'", id="evaluate-workers-0"),
    bad([*EVALUATE, "--seed", "-1"], r"argument --seed: .*'-1'", id="evaluate-seed-negative"),
    bad(
        [*EVALUATE, "--gif-episodes", "-1"],
        r"argument --gif-episodes: .*'-1'",
        id="evaluate-gif-episodes-negative",
    ),
    bad(
        [*EVALUATE, "--vector-envs", "0"],
        r"argument --vector-envs: .*'0'",
        id="evaluate-vector-envs-0",
    ),
    bad(
        [*EVALUATE, "--vector-envs", "two"],
        r"argument --vector-envs: .*'two'",
        id="evaluate-vector-envs-not-int",
    ),
    bad(
        [*EVALUATE, "--vector-envs", "2", "--gif"],
        r"--vector-envs .*not with --backend ray or --gif",
        id="evaluate-vector-envs-gif",
    ),
    bad(
        [*EVALUATE, "--agents", "random,nope"],
        r"--agents: unknown agent 'nope'; known: frontier, .*; or a 'module:Class' of your own",
        id="evaluate-agent-unknown",
    ),
    bad([*EVALUATE, "--agents", ","], r"--agents: give at least one", id="evaluate-agents-none"),
    bad(
        [*EVALUATE, "--routers", "1,2;3"], r"--routers: .*'1,2;3'", id="evaluate-routers-malformed"
    ),
    bad(
        ["benchmark", "run", "--agent", "random", "--routers", "0", "--out", "{tmp}/b"],
        r"--routers: .*'0'",
        id="benchmark-routers-0",
    ),
    bad(
        [*EVALUATE, "--env", "Nope-v0"],
        r"--env Nope-v0: .*doesn't exist",
        id="evaluate-env-unknown",
    ),
    bad(
        [*EVALUATE, "--env-kwargs", "{bad"],
        r"--env-kwargs: not valid JSON",
        id="evaluate-env-kwargs-bad-json",
    ),
    bad(
        [*EVALUATE, "--env-kwargs", "[1]"],
        r"--env-kwargs: expected a JSON object",
        id="evaluate-env-kwargs-not-object",
    ),
    bad(
        [*EVALUATE, "--env-kwargs", '{"nope": 1}'],
        r"--env-kwargs: .*'nope'",
        id="evaluate-env-kwargs-unknown-key",
    ),
    bad(
        [*EVALUATE, "--env-kwargs", '{"max_steps": -1}'],
        r"--env-kwargs: max_steps",
        id="evaluate-env-kwargs-bad-value",
    ),
    bad(
        [*EVALUATE, "--agent-params", "{bad"],
        r"--agent-params: not valid JSON",
        id="evaluate-agent-params-bad-json",
    ),
    bad(
        [*EVALUATE, "--agent-params", '{"random": 3}'],
        r"--agent-params: 'random': expected",
        id="evaluate-agent-params-not-object",
    ),
    bad(
        [*EVALUATE, "--agent-params", '{"random": {"nope": 1}}'],
        r"--agent-params: .*'nope'",
        id="evaluate-agent-params-unknown-parameter",
    ),
    bad(
        [*EVALUATE, "--agent-params", '{"nope": {}}'],
        r"--agent-params: unknown agent 'nope'",
        id="evaluate-agent-params-unknown-agent",
    ),
    bad(
        [*EVALUATE, "--floorplans", "{tmp}/missing"],
        r"--floorplans .*missing: no floorplan files there \(\.json, \.yaml, \.yml\)",
        id="evaluate-floorplans-missing",
    ),
    bad(
        [*EVALUATE, "--floorplans", "{tmp}/badplans"],
        r"plan\.json: .*at least 3",
        id="evaluate-floorplans-malformed",
    ),
    bad(
        [*EVALUATE, "--out", "{tmp}/afile"], r"argument --out: .*afile", id="evaluate-out-is-a-file"
    ),
    # -- train
    ok(
        TRAIN,
        "run/SfW-ExploreSmall-v0.zip",
        "run/SfW-ExploreSmall-v0/args.yml",
        "run/config.yml",
        id="train",
        marks=pytest.mark.episode,
    ),
    bad([*TRAIN, "--timesteps", "0"], r"argument --timesteps: .*'0'", id="train-timesteps-0"),
    bad([*TRAIN, "--n-envs", "0"], r"argument --n-envs: .*'0'", id="train-n-envs-0"),
    bad([*TRAIN, "--n-envs", "-1"], r"argument --n-envs: .*'-1'", id="train-n-envs-negative"),
    bad([*TRAIN, "--seed", "-1"], r"argument --seed: .*'-1'", id="train-seed-negative"),
    bad([*TRAIN, "--num-threads", "-1"], r"argument --num-threads: .*'-1'", id="train-threads-neg"),
    bad(
        [*TRAIN, "--checkpoint-every", "0"],
        r"argument --checkpoint-every: .*'0'",
        id="train-checkpoint-every-0",
    ),
    bad([*TRAIN, "--eval-every", "0"], r"argument --eval-every: .*'0'", id="train-eval-every-0"),
    bad(
        [*TRAIN, "--eval-episodes", "0"],
        r"argument --eval-episodes: .*'0'",
        id="train-eval-episodes-0",
    ),
    bad([*TRAIN, "--env", "Nope-v0"], r"--env Nope-v0: .*doesn't exist", id="train-env-unknown"),
    bad(
        [*TRAIN, "--env", "CartPole-v1"],
        r"no hyperparameters for 'CartPole-v1'",
        id="train-env-without-hyperparams",
    ),
    bad(
        [*TRAIN, "--hyperparams", "{tmp}/missing.yml"],
        r"missing\.yml: cannot read",
        id="train-hyperparams-missing",
    ),
    bad(
        [*TRAIN, "--hyperparams", "{tmp}/bad.yml"],
        r"bad\.yml: cannot read",
        id="train-hyperparams-malformed",
    ),
    bad([*TRAIN, "--out", "{tmp}/afile"], r"argument --out: .*afile", id="train-out-is-a-file"),
    bad(["train", "a2c"], r"argument algo: invalid choice: 'a2c'", id="train-algo-unknown"),
    # -- demo (its good run: tests/cli/test_demo.py)
    bad([*DEMO, "--episodes", "0"], r"argument --episodes: .*'0'", id="demo-episodes-0"),
    bad([*DEMO, "--workers", "0"], r"argument --workers: .*'0'", id="demo-workers-0"),
    bad([*DEMO, "--seed", "-1"], r"argument --seed: .*'-1'", id="demo-seed-negative"),
    bad([*DEMO, "--out", "{tmp}/afile"], r"argument --out: .*afile", id="demo-out-is-a-file"),
    # -- no command
    bad(["nope"], r"argument command: invalid choice: 'nope'", id="command-unknown"),
]


@pytest.fixture
def inputs(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """tmp_path with the input files, and the working directory (nothing lands in the repo)."""
    for name, text in INPUTS.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def assert_one_error_line(stderr: str, command: str, error: str) -> None:
    """No traceback; argparse's usage lines at most, then one error line matching ``error``."""
    assert "Traceback" not in stderr, stderr
    *usage, last = stderr.strip().splitlines()
    assert all(line.startswith(("usage:", " ")) for line in usage), stderr
    assert last.startswith((f"sfw-gym {command}: error: ", "sfw-gym: error: ")), stderr
    assert re.search(error, last), f"{error!r} not in {last!r}"


@pytest.mark.parametrize(("argv", "code", "error", "outputs"), CASES)
def test_cli(argv, code, error, outputs, inputs, capsys):
    argv = [arg.replace("{tmp}", str(inputs)) for arg in argv]
    try:
        got = main(argv)
    except SystemExit as exc:  # argparse's own errors
        got = exc.code
    captured = capsys.readouterr()
    assert got == code, captured.err
    if code == 0:
        assert captured.out and "Traceback" not in captured.err
        for name in outputs:
            assert (inputs / name).stat().st_size > 0, name
    else:
        assert_one_error_line(captured.err, argv[0], error)


@pytest.mark.episode
def test_console_script_reports_bad_input_in_one_line(tmp_path):
    """The installed ``sfw-gym`` executable (catches a broken entry point)."""
    exe = shutil.which("sfw-gym", path=str(Path(sys.executable).parent)) or shutil.which("sfw-gym")
    if exe is None:
        pytest.fail("no sfw-gym executable: install the package (pip install -e .)")
    proc = subprocess.run(
        [exe, "map", "missing.csv", "--routers", "1,1"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2, proc.stderr
    assert re.fullmatch(r"sfw-gym map: error: \S*missing\.csv: no such file\n", proc.stderr), (
        proc.stderr
    )


def run_cli(argv: list[str], capsys: pytest.CaptureFixture) -> str:
    assert main(argv) == 0
    return capsys.readouterr().out


@pytest.mark.episode
def test_world_is_reproducible_from_its_seed(inputs, capsys):
    """The same --seed draws the same plan and routers (printed with their positions)."""
    argv = ["world", "--seed", "5", "--out", "w.png", "--resolution", "0.5", "--routers", "3"]
    first = run_cli(argv, capsys).splitlines()[0]
    assert first == run_cli(argv, capsys).splitlines()[0]
    assert first != run_cli([*argv[:2], "6", *argv[3:]], capsys).splitlines()[0]
    assert first.count("[") == 4  # three router positions in a list


def test_world_draws_the_plan_s_own_routers_unless_told_others(inputs, capsys):
    from sfw_gym.world import load_floorplan

    square = load_floorplan({"verts": [[0, 0], [6, 0], [6, 4], [0, 4]]})
    hall = square.to_dict() | {"routers": [[1, 1], [5, 3]]}  # a plan with its routers
    Path(inputs, "hall.json").write_text(json.dumps(hall))
    argv = ["world", "--floorplan", "hall.json", "--out", "w.png", "--resolution", "0.5"]
    assert "routers at [[1.0, 1.0], [5.0, 3.0]]" in run_cli(argv, capsys)
    assert "routers at [[2.0, 2.0]]" in run_cli([*argv, "--routers", "2,2"], capsys)
    line = run_cli([*argv, "--routers", "1"], capsys).splitlines()[0]
    assert line.count("[") == 2  # one router, placed by k-means


def test_map_reports_which_columns_feed_which_router(inputs, capsys):
    out = run_cli([arg.replace("{tmp}", str(inputs)) for arg in MAP], capsys)
    assert "4 samples, 0 rows skipped" in out and "routers <- columns r1" in out
    out = run_cli(["map", "log2.csv", "--routers", "0.5,0.5;1.5,0.5", "--out", "m2.png"], capsys)
    assert "routers <- columns a, b" in out


def test_bench_memory_option_reports_rss(inputs, capsys):
    out = run_cli([*BENCH, "--memory-steps", "30"], capsys)
    assert re.search(r"memory: RSS .* MiB before, .* MiB after 30 steps", out)
    assert "SfW-ExploreSmall-v0" in out and "CartPole-v1" in out and "load average" in out
    # the native vector env beside one env (issue 33)
    assert re.search(r"SfW-ExploreSmall-v0 × 16 in one process .*: [\d,]+ env steps/s = ", out)


def test_a_failure_is_one_line_and_status_1_and_debug_shows_the_traceback(monkeypatch, capsys):
    from sfw_gym import bench

    def broken(*args, **kwargs):
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(bench, "main_bench", broken)
    assert main(["speed", "--steps", "1"]) == 1
    err = capsys.readouterr().err
    assert err.strip() == (
        "sfw-gym speed: error: failed: RuntimeError: disk on fire (run with --debug for the "
        "traceback)"
    )
    with pytest.raises(RuntimeError, match="disk on fire"):
        main(["--debug", "speed", "--steps", "1"])
    with pytest.raises(ConfigError):  # bad input too, with --debug
        main(["--debug", "map", "nope.csv", "--routers", "1,1"])


@pytest.mark.parametrize("command", sorted(EXAMPLES))
def test_every_subcommand_shows_an_example_that_parses(command):
    """(That every default shows, in one format: tests/cli/test_help_unchanged.py.)"""
    import argparse
    import shlex

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert set(sub.choices) == {*EXAMPLES, "bench"}  # one example per subcommand (bench: speed)
    help_text = " ".join(sub.choices[command].format_help().split())
    assert f"example: {EXAMPLES[command]}" in help_text
    args = parser.parse_args(shlex.split(EXAMPLES[command])[1:])
    assert args.command == command
    assert sub.choices["bench"] is sub.choices["speed"]  # the old name still works


def test_verbose_shows_the_librarys_log_and_quiet_hides_it(tmp_path, capfd):
    log = tmp_path / "walk.csv"
    assert main(["-v", "record", str(log), "--routers", "1"]) == 0
    err = capfd.readouterr().err
    assert f"INFO sfw_gym.evaluation.logs: {log}: " in err
    assert main(["-q", "record", str(log), "--routers", "1"]) == 0
    assert capfd.readouterr().err == ""
    assert main(["record", str(log), "--routers", "1"]) == 0  # the default: warnings and up
    assert "INFO" not in capfd.readouterr().err

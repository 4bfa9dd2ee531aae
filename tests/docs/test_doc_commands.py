"""Every command the README and the documentation's pages show runs, at smoke size.

Each page runs in a workspace of its own that looks like the checkout (``agents/``, ``envs/``,
``scripts/``, ``docs/`` and ``../shared`` where it exists), its blocks in order: ``python``
blocks in one namespace, each line of a ``bash`` block as a command, ``json`` plans loaded. The
commands are run as written but smaller (:data:`SMOKE`): fewer episodes, steps and timesteps;
nothing else is changed, so a renamed option, a missing file or a wrong agent name fails here.
``text`` blocks are shown, not run (a download, an install elsewhere).
"""

from __future__ import annotations

import json
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from tests.docs.pages import ROOT, SHARED, blocks, commands, rel, runnable_pages, saved_as

BIN = Path(sys.executable).parent
#: Parts of a command line that set a machine up: CI's own install (``.ci/run``) runs them.
SET_UP = ("python3 -m venv", ". .venv/bin/activate", "pip install")
#: Commands another test runs: the suite itself, and the site's build (test_docs_build.py).
NOT_HERE = ("pytest", ".venv/bin/python -m pytest", "sphinx-build")
#: Options made smaller, by command: (pattern, replacement) on the command line, then the
#: options added when the command does not set them already.
SMOKE: dict[str, tuple[list[tuple[str, str]], list[tuple[str, str | None]]]] = {
    "demo": ([(r"--episodes \d+", "--episodes 1")], [("--episodes", "1"), ("--no-progress", None)]),
    "evaluate": (
        [(r"--episodes \d+", "--episodes 1")],
        [
            ("--episodes", "1"),
            ("--env-kwargs", '{"max_steps": 60}'),
            ("--workers", "1"),
            ("--no-progress", None),
        ],
    ),
    "benchmark run": (
        [(r"--episodes \d+", "--episodes 1")],
        [("--episodes", "1"), ("--no-progress", None)],
    ),
    "train": (
        [(r"--timesteps \d+", "--timesteps 32")],
        [
            ("--timesteps", "32"),
            ("--n-envs", "1"),
            ("--eval-episodes", "1"),
            ("--no-progress", None),
        ],
    ),
    "localize": (
        [(r"--plans \d+", "--plans 1")],
        [
            ("--plans", "1"),
            ("--runs", "1"),
            ("--survey-steps", "150"),
            ("--test-steps", "30"),
            ("--particles", "100"),
            ("--no-direct", None),
            ("--workers", "1"),
            ("--no-progress", None),
        ],
    ),
}


def smoke_hyperparams(folder: Path) -> Path:
    """The shipped YAMLs with one small env and tiny rollouts, cloning and fine-tuning: the
    same keys, so a doc command that trains still reads a real file of the shipped shape."""
    from sfw_gym.core.data import DEFAULT_HYPERPARAMS

    folder.mkdir(exist_ok=True)
    for name in ("ppo", "ppo_mask"):
        data = yaml.safe_load((DEFAULT_HYPERPARAMS.parent / f"{name}.yml").read_text())
        for env_id, block in data.items():
            if env_id == "sfw_gym":
                for project in block.values():
                    if "behaviour_cloning" in project:
                        project["behaviour_cloning"].update(
                            episodes=1, epochs=1, dagger_rounds=0, dagger_episodes=1
                        )
                continue
            block.update(n_envs=1, n_steps=16, batch_size=16, n_epochs=1)
            block["env_kwargs"] = {**(block.get("env_kwargs") or {}), "max_steps": 60}
        (folder / f"{name}.yml").write_text(yaml.safe_dump(data))
    return folder


def smoke(argv: list[str], workspace: Path) -> list[str]:
    """``argv`` (an ``sfw-gym`` command) made smaller as :data:`SMOKE` says."""
    command = " ".join(argv[1:3]) if " ".join(argv[1:3]) in SMOKE else " ".join(argv[1:2])
    if command not in SMOKE:
        return argv
    line = shlex.join(argv)
    replacements, defaults = SMOKE[command]
    for pattern, replacement in replacements:
        line = re.sub(pattern, replacement, line)
    argv = shlex.split(line)
    for option, value in defaults:
        if option not in argv:
            argv += [option] if value is None else [option, value]
    if command == "train" and "--hyperparams" not in argv:
        algo = next(a for a in argv[2:] if not a.startswith("-"))
        argv += ["--hyperparams", str(smoke_hyperparams(workspace / ".smoke") / f"{algo}.yml")]
    return argv


def workspace_for(tmp_path: Path) -> Path:
    """A folder that looks like the checkout to a relative path, writes landing in tmp."""
    work = tmp_path / "repo"
    work.mkdir()
    for name in ("agents", "envs", "scripts", "docs", "sfw_gym"):
        (work / name).symlink_to(ROOT / name)
    if SHARED.is_dir():
        (tmp_path / "shared").symlink_to(SHARED)
    return work


def run_command(line: str, workspace: Path) -> None:
    parts = [p.strip() for p in line.split("&&")]
    for part in parts:
        if part.startswith(SET_UP) or part.startswith(NOT_HERE):
            continue
        if "../shared" in part and not SHARED.is_dir():
            pytest.skip(f"{part!r} needs ../shared")
        argv = shlex.split(part)
        if argv[0] in ("sfw-gym", "python", "python3"):
            argv[0] = str(BIN / argv[0]) if (BIN / argv[0]).exists() else sys.executable
        argv = smoke(argv, workspace) if argv[0].endswith("sfw-gym") else argv
        done = subprocess.run(
            argv, cwd=workspace, capture_output=True, text=True, timeout=900,
            env={**os.environ, "MPLBACKEND": "Agg"},
        )  # fmt: skip
        assert done.returncode == 0, (
            f"{shlex.join(argv)} exited {done.returncode}:\n{done.stdout[-2000:]}\n"
            f"{done.stderr[-3000:]}"
        )


def run_page(page: Path, workspace: Path, monkeypatch: pytest.MonkeyPatch) -> int:
    """Run a page's blocks in order in ``workspace``; returns how many ran."""
    from sfw_gym.world import load_floorplan

    monkeypatch.chdir(workspace)
    monkeypatch.setenv("MPLBACKEND", "Agg")
    namespace: dict = {"__name__": "__main__"}
    files, ran = saved_as(page), 0
    for i, (language, text) in enumerate(blocks(page)):
        if i in files:
            (workspace / files[i]).write_text(text, encoding="utf-8")
        elif language == "python":
            exec(compile(text, f"{rel(page)} block {i}", "exec"), namespace)
        elif language == "bash":
            for line in commands(text):
                run_command(line, workspace)
        elif language == "json" and '"format": "sfw_gym.floorplan"' in text:
            load_floorplan(json.loads(text))
        else:
            continue
        ran += 1
    return ran


def episode_records(folder: Path) -> list[dict]:
    """An evaluation folder's episode records, by episode."""
    lines = (folder / "episodes.jsonl").read_text(encoding="utf-8").splitlines()
    return sorted(map(json.loads, lines), key=lambda r: r["episode"])


def own_building_did_what_it_says(workspace: Path) -> None:
    """The own-building page's evaluations ran with the routers and plans the page names."""
    hall = episode_records(workspace / "runs" / "hall")
    assert hall and all(r["routers"] == [[2.0, 2.0], [10.0, 6.0]] for r in hall)
    assert {r["floorplan_file"] for r in hall} == {"hall.json"}
    plans = episode_records(workspace / "runs" / "plans")
    assert plans[0]["floorplan_file"] == "plans/hall.json"  # the folder's first plan
    assert json.loads((workspace / "runs" / "plans" / "config.json").read_text())["routers"] is None


#: What a page's commands must have done, checked after they ran, by page.
PAGE_CHECKS = {"docs/guide/own-building.md": own_building_did_what_it_says}


@pytest.mark.episode
@pytest.mark.parametrize("page", runnable_pages(), ids=rel)
def test_every_command_of_the_page_runs(page, tmp_path, monkeypatch):
    workspace = workspace_for(tmp_path)
    assert run_page(page, workspace, monkeypatch) > 0
    PAGE_CHECKS.get(rel(page), lambda _: None)(workspace)


def test_smoke_makes_commands_smaller_and_keeps_the_rest(tmp_path):
    argv = smoke(["sfw-gym", "evaluate", "--agents", "frontier", "--episodes", "50"], tmp_path)
    assert argv[:4] == ["sfw-gym", "evaluate", "--agents", "frontier"]
    assert argv[argv.index("--episodes") + 1] == "1" and "--env-kwargs" in argv
    train = smoke(["sfw-gym", "train", "ppo_mask", "--env", "SfW-ExploreRegions-v0"], tmp_path)
    assert train[train.index("--timesteps") + 1] == "32"
    fitted = yaml.safe_load(Path(train[train.index("--hyperparams") + 1]).read_text())
    assert fitted["SfW-ExploreRegions-v0"]["env_kwargs"] == {"privileged": True, "max_steps": 60}
    assert fitted["sfw_gym"]["SfW-ExploreRegions-v0"]["behaviour_cloning"]["episodes"] == 1
    world = ["sfw-gym", "world", "--seed", "3"]
    assert smoke(world, tmp_path) == world


def test_a_broken_command_fails_the_page(tmp_path):
    with pytest.raises(AssertionError, match="exited 2"):
        run_command("sfw-gym evaluate --agents no-such-agent", workspace_for(tmp_path))


def test_the_readme_and_the_user_paths_are_run():
    names = {rel(p) for p in runnable_pages()}
    assert "README.md" in names and "docs/benchmark.md" in names
    assert {f"docs/guide/{n}.md" for n in ("install", "first-env", "train-and-compare",
            "train-default-agent", "own-building", "own-survey")} <= names  # fmt: skip


def test_the_readme_s_two_commands_set_up_run_the_demo_and_test_on_every_core():
    first, second = commands(blocks(ROOT / "README.md")[0][1])
    assert first.startswith("python3 -m venv") and first.endswith("sfw-gym demo")
    assert "pip install torch==2.13.0" in first  # the CPU build here, before anything pulls CUDA
    assert " -n auto" in second and "pytest" in second
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert second in ci  # CI runs the README's own test command

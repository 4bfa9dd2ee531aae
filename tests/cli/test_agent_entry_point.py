"""An agent of an installed package, by the name its ``sfw_gym.agents`` entry point gives it,
end to end through ``sfw-gym evaluate`` in a fresh process (and its worker processes)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.agents.test_registry import AGENT_MODULE

BIN = Path(sys.executable).parent
PYPROJECT = """\
[build-system]
requires = ["setuptools"]
build-backend = "setuptools.build_meta"

[project]
name = "mine-agents"
version = "0.1"

[project.entry-points."sfw_gym.agents"]
mine = "mine_agents:Mine"
"""


@pytest.mark.episode
def test_an_installed_package_s_agent_runs_through_evaluate_by_its_name(tmp_path):
    source = tmp_path / "mine-agents"
    (source / "mine_agents").mkdir(parents=True)
    (source / "pyproject.toml").write_text(PYPROJECT)
    (source / "mine_agents" / "__init__.py").write_text(AGENT_MODULE)
    target = tmp_path / "site"  # installed there, not into the venv the other tests share
    pip = [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--no-build-isolation"]
    subprocess.run([*pip, "--target", str(target), str(source)], check=True, timeout=300)
    assert (target / "mine_agents-0.1.dist-info" / "entry_points.txt").is_file()
    env = {**os.environ, "PYTHONPATH": str(target), "MPLBACKEND": "Agg"}
    out = tmp_path / "run"
    argv = [str(BIN / "sfw-gym"), "evaluate", "--agents", "random,mine", "--episodes", "2"]
    argv += ["--env", "SfW-ExploreSmall-v0", "--env-kwargs", '{"max_steps": 20}']
    argv += ["--workers", "2", "--no-progress", "--out", str(out)]
    done = subprocess.run(argv, env=env, cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    assert "| mine | 2 |" in done.stdout  # its row of the table
    lines = (out / "episodes.jsonl").read_text().splitlines()
    mine = [r for r in map(json.loads, lines) if r["agent"] == "mine"]
    assert sorted(r["episode"] for r in mine) == [0, 1] and all(r["steps"] > 0 for r in mine)
    listed = subprocess.run(
        [str(BIN / "sfw-gym"), "evaluate", "--help"], env=env, capture_output=True, text=True
    )
    assert ", mine; or package.module:Class" in " ".join(listed.stdout.split())

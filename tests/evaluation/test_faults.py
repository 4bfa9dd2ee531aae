"""An evaluation survives being killed: it resumes to the same results, refuses to mix runs,
leaves no temp file and no orphan worker."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import numpy as np
import pytest

from sfw_gym import evaluation as ev
from sfw_gym.core.errors import ConfigError

SMALL = "SfW-ExploreSmall-v0"
TINY = {"env_id": SMALL, "env_kwargs": {"max_steps": 40}, "workers": 1, "progress": False}
ARGV = [
    sys.executable, "-m", "sfw_gym.cli", "evaluate", "--agents", "frontier,random",
    "--episodes", "8", "--seed", "7", "--env", SMALL, "--env-kwargs", '{"max_steps": 200}',
    "--workers", "2", "--no-progress",
]  # fmt: skip


def test_resuming_with_other_settings_is_refused(tmp_path):
    ev.evaluate(["random"], 1, seed=5, out=tmp_path, **TINY)
    with pytest.raises(ConfigError, match=r"ran with env_kwargs \{'max_steps': 40\}"):
        ev.evaluate(["random"], 1, seed=5, out=tmp_path, **{**TINY, "env_kwargs": {"max_steps": 9}})
    with pytest.raises(ConfigError, match=r"recorded 'random' episodes ran with parameters \{\}"):
        ev.evaluate(["random"], 1, out=tmp_path, agent_params={"random": {"hold_steps": 3}}, **TINY)
    more = ev.evaluate(["random", "frontier"], 2, seed=5, out=tmp_path, **TINY)  # extends the run
    assert len(more["records"]) == 4
    assert json.loads((tmp_path / "config.json").read_text())["agents"] == ["random", "frontier"]
    ev.evaluate(["frontier"], 2, seed=5, out=tmp_path, **TINY)  # all ran: the manifest keeps both
    config = json.loads((tmp_path / "config.json").read_text())
    assert config["seed"] == 5 and config["agent_params"] == {"random": {}, "frontier": {}}


def test_the_checkpoint_key_of_an_episode_is_the_one_earlier_runs_wrote():
    """Resume finds an earlier run's records by these keys: they must not change."""
    spec = ev.EpisodeSpec(agent="random", episode=3, seed=8, env_id=SMALL)
    assert spec.key == "random|3|8|SfW-ExploreSmall-v0|None"
    seeded = ev.EpisodeSpec(agent="random", episode=0, seed=2, floorplan="p.json", agent_seed=9)
    assert seeded.key == "random|0|2|SfW-Explore-v0|p.json|9"


def test_temp_files_of_a_killed_write_are_removed(tmp_path):
    (tmp_path / "episodes").mkdir()
    stale = [tmp_path / ".episodes.abc123.tmp.jsonl", tmp_path / "episodes" / ".x_0000.q.tmp.npz"]
    for path in stale:
        path.write_text("half")
    ev.evaluate(["random"], 1, seed=5, out=tmp_path, **TINY)
    assert not any(p.exists() for p in stale)
    assert not list(tmp_path.rglob("*.tmp*"))


def _records(folder):
    lines = (folder / "episodes.jsonl").read_text().splitlines()
    out = {}
    for line in lines:
        r = json.loads(line)
        out[r["key"]] = {k: v for k, v in r.items() if k != "wall_s"}
    return out


def _done(ckpt) -> int:
    return len(ckpt.read_text().splitlines()) if ckpt.exists() else 0


def _alive(pgid: int) -> bool:
    try:
        os.killpg(pgid, 0)
    except ProcessLookupError:
        return False
    return True


@pytest.mark.slow
def test_killed_five_times_then_resumed_equals_an_uninterrupted_run(tmp_path):
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    subprocess.run([*ARGV, "--out", str(whole)], check=True, capture_output=True)
    rng = np.random.default_rng(0)
    ckpt = killed / "episodes.jsonl"
    partial = []
    for target in sorted(rng.integers(1, 15, size=5)):  # kill once this many episodes are done
        proc = subprocess.Popen(
            [*ARGV, "--out", str(killed)], start_new_session=True,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        deadline = time.monotonic() + 120
        while _done(ckpt) < target and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        time.sleep(float(rng.uniform(0.0, 0.5)))  # and somewhere within the next episodes
        proc.kill()  # SIGKILL to the parent only: its workers must follow
        proc.wait()
        deadline = time.monotonic() + 10
        while _alive(proc.pid) and time.monotonic() < deadline:
            time.sleep(0.2)
        assert not _alive(proc.pid), "a worker outlived its killed evaluation"
        partial.append(_done(ckpt))
    assert any(0 < n < 16 for n in partial), partial  # killed mid-run, not before or after
    subprocess.run([*ARGV, "--out", str(killed)], check=True, capture_output=True)
    assert _records(killed) == _records(whole)
    assert (killed / "results.md").read_text() == (whole / "results.md").read_text()
    assert not list(killed.rglob("*.tmp*"))

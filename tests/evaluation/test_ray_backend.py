"""``sfw-gym evaluate --backend ray``: the same records as the local backend (where Ray is
installed: ``pip install "sfw-gym[ray]"``), and a clear error where it is not."""

from __future__ import annotations

import importlib.util
import json
import os
import signal
import threading
import time
from pathlib import Path

import pytest

from sfw_gym.cli import main
from sfw_gym.evaluation import evaluate
from sfw_gym.evaluation.runner import CHECKPOINT

HAS_RAY = importlib.util.find_spec("ray") is not None
RUN = dict(env_id="SfW-ExploreSmall-v0", env_kwargs={"max_steps": 60}, progress=False)


@pytest.mark.skipif(HAS_RAY, reason="Ray is installed here")
def test_without_ray_the_backend_is_one_line_naming_the_extra(tmp_path, capsys):
    argv = ["evaluate", "--agents", "frontier", "--episodes", "1", "--backend", "ray"]
    assert main([*argv, "--out", str(tmp_path)]) == 2
    assert "pip install 'sfw-gym[ray]'" in capsys.readouterr().err


def keyed(result):
    """Each episode's record without its timing fields, by episode key."""
    return {
        r["key"]: json.dumps({k: v for k, v in r.items() if k not in ("wall_s", "steps_per_s")})
        for r in result["records"]
    }


@pytest.mark.skipif(not HAS_RAY, reason="needs Ray (pip install 'sfw-gym[ray]')")
def test_ray_gives_the_local_backends_records(tmp_path):
    local = evaluate(["frontier", "random"], 3, 7, out=tmp_path / "local", workers=2, **RUN)
    ray = evaluate(
        ["frontier", "random"], 3, 7, out=tmp_path / "ray", workers=2, backend="ray", **RUN
    )

    assert keyed(ray) == keyed(local)
    assert (tmp_path / "ray" / "results.md").read_text() == (
        tmp_path / "local" / "results.md"
    ).read_text()


def _episode_task_pids() -> list[int]:
    """Processes running a Ray task of the evaluation (Ray names them ``ray::run_episode``)."""
    pids = []
    for proc in Path("/proc").iterdir():
        try:
            if proc.name.isdigit() and (proc / "cmdline").read_bytes().startswith(
                b"ray::run_episode"
            ):
                pids.append(int(proc.name))
        except OSError:
            continue
    return pids


@pytest.mark.skipif(not HAS_RAY, reason="needs Ray (pip install 'sfw-gym[ray]')")
def test_a_ray_worker_killed_mid_evaluation_loses_no_episode_and_runs_none_twice(tmp_path):
    run = dict(env_id="SfW-ExploreSmall-v0", progress=False)  # whole 300-step episodes
    out = tmp_path / "ray"
    killed: list[int] = []
    stop = threading.Event()

    def kill_one_worker_after_the_first_record() -> None:
        while not stop.is_set() and not killed:
            checkpoint = out / CHECKPOINT
            if checkpoint.is_file() and checkpoint.read_text().strip():
                for pid in _episode_task_pids():
                    os.kill(pid, signal.SIGKILL)
                    killed.append(pid)
                    break
            time.sleep(0.02)

    killer = threading.Thread(target=kill_one_worker_after_the_first_record)
    killer.start()
    try:
        ray = evaluate(["frontier", "random"], 3, 7, out=out, workers=2, backend="ray", **run)
    finally:
        stop.set()
        killer.join()
    assert killed, "no Ray worker was running an episode to kill"
    lines = (out / CHECKPOINT).read_text().splitlines()
    keys = [json.loads(line)["key"] for line in lines]
    assert len(keys) == len(set(keys)) == 6
    local = evaluate(["frontier", "random"], 3, 7, out=tmp_path / "local", workers=1, **run)
    assert keyed(ray) == keyed(local)

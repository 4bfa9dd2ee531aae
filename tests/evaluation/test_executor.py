"""The executor: one interface that runs jobs in this process or in worker processes (Ray: in
CI's Ray venv, ``test_ray_backend.py``) with one progress bar; the localisation study runs its
plans on it."""

from __future__ import annotations

import importlib.util
import time

import pytest

from sfw_gym.cli import main
from sfw_gym.core.errors import ConfigError
from sfw_gym.evaluation import localization
from sfw_gym.evaluation.executor import Bar, Executor


def square(x: int) -> int:
    time.sleep(0.05 * (x % 3 == 0))  # jobs 0, 3, 6 finish after the ones started beside them
    return x * x


def fail_on_three(x: int) -> int:
    if x == 3:
        raise ValueError("job 3 failed")
    return x


@pytest.mark.parametrize("workers", [1, pytest.param(2, marks=pytest.mark.episode)])
def test_map_gives_every_result_in_the_order_of_the_jobs(workers):
    jobs = list(range(7))
    assert Executor(workers=workers, progress=False).map(square, jobs, Bar("t")) == [
        j * j for j in jobs
    ]


@pytest.mark.parametrize("workers", [1, pytest.param(2, marks=pytest.mark.episode)])
def test_a_failing_job_raises_in_the_caller(workers):
    with pytest.raises(ValueError, match="job 3 failed"):
        Executor(workers=workers, progress=False).map(fail_on_three, list(range(6)), Bar("t"))


def test_run_hands_each_result_with_its_index_and_the_bar_counts_jobs_done_before(capsys):
    seen: list[tuple[int, int]] = []
    Executor(workers=1).run(
        square,
        [2, 3],
        lambda i, result: seen.append((i, result)),
        Bar("episodes", "ep", done=5, postfix=lambda result: f"last {result}"),
    )
    assert seen == [(0, 4), (1, 9)]
    bar = capsys.readouterr().err
    assert "episodes" in bar and "7/7" in bar and "last 9" in bar
    Executor(workers=1, progress=False).map(square, [1], Bar("quiet"))
    assert "quiet" not in capsys.readouterr().err


def test_consume_hands_on_results_made_elsewhere_and_stops_their_producer_on_an_error(capsys):
    closed: list[bool] = []

    def produce():  # as a vector env yields its episodes' records
        try:
            yield from [(1, "b"), (0, "a"), (2, "c")]
        finally:
            closed.append(True)

    seen: list[tuple[int, str]] = []
    Executor().consume(produce(), 3, lambda i, r: seen.append((i, r)), Bar("vector", done=1))
    assert seen == [(1, "b"), (0, "a"), (2, "c")] and closed == [True]
    bar = capsys.readouterr().err  # the same bar, counting the one done before
    assert "vector" in bar and "4/4" in bar

    def interrupted(i, result):
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        Executor(progress=False).consume(produce(), 3, interrupted, Bar("x"))
    assert closed == [True, True]  # the producer (a vector env's processes) shut at once


def test_bad_settings_are_one_line_errors():
    with pytest.raises(ConfigError, match="--workers must be an int >= 1, got 0"):
        Executor(workers=0)
    with pytest.raises(ConfigError, match=r"--backend must be one of \['local', 'ray'\]"):
        Executor(backend="dask")
    if importlib.util.find_spec("ray") is None:
        with pytest.raises(ConfigError, match=r"pip install 'sfw-gym\[ray\]'"):
            Executor(backend="ray")


class _Stop(Exception):
    pass


def test_the_localisation_study_runs_its_plans_on_the_executor(tmp_path, monkeypatch):
    seen = {}

    def record_and_stop(self, fn, jobs, bar):
        seen.update(executor=self, fn=fn, seeds=[job["seed"] for job in jobs], unit=bar.unit)
        raise _Stop

    monkeypatch.setattr(Executor, "map", record_and_stop)
    with pytest.raises(_Stop):
        localization.run_localization_study(tmp_path, plans=3, workers=2, progress=False)
    assert seen["executor"] == Executor(workers=2, progress=False)
    assert seen["fn"] is localization.study_plan and seen["unit"] == "plan"
    assert seen["seeds"] == [localization.FIRST_SEED + i for i in range(3)]


def test_localize_takes_the_executors_options(tmp_path, monkeypatch, capsys):
    given = {}

    def fake_study(out, **kwargs):
        given.update(kwargs)
        return {"markdown": "tables\n"}

    monkeypatch.setattr(localization, "run_localization_study", fake_study)
    argv = ["localize", "--out", str(tmp_path), "--workers", "3", "--no-progress"]
    assert main(argv) == 0
    assert (given["workers"], given["backend"], given["progress"]) == (3, "local", False)
    assert main(["localize", "--out", str(tmp_path)]) == 0
    assert given["progress"] is True and given["address"] is None

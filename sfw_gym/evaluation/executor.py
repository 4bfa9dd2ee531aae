"""Where jobs run: in this process, in local worker processes or as Ray tasks, behind one
interface (:class:`Executor`) with one progress bar. The evaluation's episodes and the
localisation study's plans run through it; a job is a picklable function of one picklable
argument, and its result comes back to this process as each job finishes."""

from __future__ import annotations

import multiprocessing as mp
import os
from collections.abc import Callable, Generator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from contextlib import closing
from dataclasses import dataclass
from typing import Any

from sfw_gym.core.errors import ConfigError
from sfw_gym.core.processes import die_with_parent

#: Where jobs run.
BACKENDS = ("local", "ray")
#: A Ray task whose worker died runs again this many times (nothing lost, nothing twice: the
#: caller takes each job's result once, when its task returns).
RAY_RETRIES = 3


def require_ray() -> Any:
    """The ``ray`` module, or a ConfigError naming the extra that installs it."""
    try:
        import ray
    except ImportError:
        raise ConfigError("--backend ray needs Ray: pip install 'sfw-gym[ray]'") from None
    return ray


@dataclass(frozen=True)
class Bar:
    """What the progress bar shows.

    Attributes:
        desc: Its label.
        unit: What it counts.
        done: Jobs finished before (a resumed run), counted from the start.
        postfix: Describes the last result beside the bar.
    """

    desc: str
    unit: str = "job"
    done: int = 0
    postfix: Callable[[Any], str] | None = None


@dataclass(frozen=True)
class Executor:
    """Runs jobs at most ``workers`` at a time.

    Attributes:
        workers: Jobs in flight at once; with the local backend, 1 runs them in this process
            and more in as many ``spawn``-ed worker processes (forking a process that has run
            numba's OpenMP kernels is unsafe), each of which dies with this one.
        backend: ``"local"`` or ``"ray"`` (each job a Ray task; a task whose worker dies runs
            again, :data:`RAY_RETRIES` times).
        address: With Ray: a cluster's address (``"auto"``: a running one); None starts a local
            Ray with ``workers`` CPUs (and shuts it down after).
        progress: Show a tqdm progress bar.
    """

    workers: int = 1
    backend: str = "local"
    address: str | None = None
    progress: bool = True

    def __post_init__(self) -> None:
        if isinstance(self.workers, bool) or not isinstance(self.workers, int) or self.workers < 1:
            raise ConfigError(f"--workers must be an int >= 1, got {self.workers!r}")
        if self.backend not in BACKENDS:
            raise ConfigError(f"--backend must be one of {list(BACKENDS)}, got {self.backend!r}")
        if self.backend == "ray":
            require_ray()

    def run(
        self,
        fn: Callable[[Any], Any],
        jobs: Sequence[Any],
        on_result: Callable[[int, Any], None],
        bar: Bar,
    ) -> None:
        """``fn(job)`` for every job; ``on_result(i, result)`` in this process as job ``i``
        finishes (in the order they finish), counted on the progress ``bar``. On an error or an
        interrupt the jobs not started are dropped and the running ones cancelled."""

        def run_all(finish: Callable[[int, Any], None]) -> None:
            if self.backend == "ray":
                self._run_on_ray(fn, jobs, finish)
            elif self.workers == 1:
                for i, job in enumerate(jobs):
                    finish(i, fn(job))
            else:
                self._run_in_pool(fn, jobs, finish)

        self._with_bar(run_all, len(jobs), on_result, bar)

    def consume(
        self,
        results: Generator[tuple[int, Any], None, None],
        total: int,
        on_result: Callable[[int, Any], None],
        bar: Bar,
    ) -> None:
        """Results that run elsewhere (a vector env's episodes: ``(i, result)`` pairs, ``total``
        of them) handed to ``on_result`` as they come, on :meth:`run`'s progress bar."""

        def run_all(finish: Callable[[int, Any], None]) -> None:
            with closing(results):  # stopped early: the producer cleans up at once
                for i, result in results:
                    finish(i, result)

        self._with_bar(run_all, total, on_result, bar)

    def map(self, fn: Callable[[Any], Any], jobs: Sequence[Any], bar: Bar) -> list[Any]:
        """``[fn(job) for job in jobs]``, run as :meth:`run` runs them."""
        results: list[Any] = [None] * len(jobs)

        def keep(i: int, result: Any) -> None:
            results[i] = result

        self.run(fn, jobs, keep, bar)
        return results

    def _with_bar(
        self,
        run_all: Callable[[Callable[[int, Any], None]], None],
        total: int,
        on_result: Callable[[int, Any], None],
        bar: Bar,
    ) -> None:
        from tqdm.auto import tqdm

        shown = tqdm(
            total=bar.done + total,
            initial=bar.done,
            desc=bar.desc,
            unit=bar.unit,
            disable=not self.progress,
        )

        def finish(i: int, result: Any) -> None:
            on_result(i, result)
            if bar.postfix is not None:
                shown.set_postfix_str(bar.postfix(result))
            shown.update(1)

        try:
            run_all(finish)
        finally:
            shown.close()

    def _run_in_pool(
        self, fn: Callable[[Any], Any], jobs: Sequence[Any], finish: Callable[[int, Any], None]
    ) -> None:
        pool = ProcessPoolExecutor(
            max_workers=self.workers,
            mp_context=mp.get_context("spawn"),
            initializer=die_with_parent,  # a killed run leaves no worker behind
            initargs=(os.getpid(),),
        )
        try:
            self._schedule(
                jobs,
                {},
                lambda job: pool.submit(fn, job),
                lambda futures: wait(futures, return_when=FIRST_COMPLETED)[0],
                lambda future: future.result(),
                finish,
            )
        finally:  # on an interrupt, drop the queued jobs (a checkpoint holds the done ones)
            pool.shutdown(wait=False, cancel_futures=True)

    def _run_on_ray(
        self, fn: Callable[[Any], Any], jobs: Sequence[Any], finish: Callable[[int, Any], None]
    ) -> None:
        ray = require_ray()
        started = not ray.is_initialized()
        if started:
            ray.init(
                address=self.address,
                num_cpus=self.workers if self.address is None else None,
                include_dashboard=False,
                log_to_driver=False,
            )
        task = ray.remote(max_retries=RAY_RETRIES)(fn)  # Ray names it ray::<fn's name>
        pending: dict[Any, int] = {}
        try:
            self._schedule(
                jobs,
                pending,
                task.remote,
                lambda refs: ray.wait(refs, num_returns=1)[0],
                ray.get,
                finish,
            )
        finally:  # on an interrupt, drop the queued jobs; cancel the running ones
            for ref in pending:
                ray.cancel(ref, force=True)
            if started:
                ray.shutdown()

    def _schedule(
        self,
        jobs: Sequence[Any],
        pending: dict[Any, int],
        submit: Callable[[Any], Any],
        wait_some: Callable[[list[Any]], Any],
        result: Callable[[Any], Any],
        finish: Callable[[int, Any], None],
    ) -> None:
        """At most ``workers`` jobs in flight: ``submit(job)`` gives a handle (kept in
        ``pending``, with its job's index, until it finishes), ``wait_some(handles)`` the
        finished ones, ``result(handle)`` a finished job's result."""
        queue = list(enumerate(jobs))
        while queue or pending:
            while queue and len(pending) < self.workers:
                i, job = queue.pop(0)
                pending[submit(job)] = i
            for handle in wait_some(list(pending)):
                finish(pending.pop(handle), result(handle))

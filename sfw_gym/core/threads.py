"""Keep OpenMP single-threaded around scikit-learn calls.

scikit-learn's KMeans starts a GNU OpenMP thread pool; a process that forks after that (Gymnasium's
AsyncVectorEnv, SB3's SubprocVecEnv with "fork") hangs in the child. Our k-means problems are tiny
(1-D RSSI levels, a few hundred router candidates), so one thread costs nothing and keeps fork safe.
"""

from __future__ import annotations

from contextlib import AbstractContextManager
from functools import cache

from threadpoolctl import ThreadpoolController


@cache
def _controller() -> ThreadpoolController:
    return ThreadpoolController()


def single_threaded_openmp() -> AbstractContextManager:
    """A context in which OpenMP runs one thread (cheap: ~15 µs to enter)."""
    return _controller().limit(limits=1, user_api="openmp")

"""Child processes die with their parent: no worker outlives a killed evaluation."""

from __future__ import annotations

import os
import signal
import sys
import threading
import time


def die_with_parent(parent_pid: int, poll_s: float = 1.0) -> None:
    """Make this (worker) process exit when ``parent_pid`` dies, however it dies (SIGKILL
    included): Linux's parent-death signal where there is one, and a watchdog thread that
    notices the re-parenting everywhere. Call first thing in the child (a pool initializer)."""
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # pragma: no cover (no libc prctl)
            pass
    if os.getppid() != parent_pid:  # the parent died before the signal was armed
        os._exit(1)

    def watch() -> None:
        while os.getppid() == parent_pid:
            time.sleep(poll_s)
        os._exit(1)

    threading.Thread(target=watch, name="die-with-parent", daemon=True).start()

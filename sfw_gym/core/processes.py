"""Child processes die with their parent: no worker outlives a killed evaluation or training."""

from __future__ import annotations

import os
import signal
import sys
import threading
import time


def die_with_parent(parent_pid: int, poll_s: float = 1.0) -> None:
    """Make this (worker) process exit when process ``parent_pid`` dies, however it dies (SIGKILL
    included): Linux's parent-death signal where ``parent_pid`` is the direct parent, and a
    watchdog thread that polls it everywhere (a forkserver's children have the forkserver as
    their parent, not the process they work for). Call first thing in the child."""
    if sys.platform.startswith("linux") and os.getppid() == parent_pid:
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # pragma: no cover (no libc prctl)
            pass
    if not _alive(parent_pid):  # it died before the signal was armed
        os._exit(1)

    def watch() -> None:
        while _alive(parent_pid):
            time.sleep(poll_s)
        os._exit(1)

    threading.Thread(target=watch, name="die-with-parent", daemon=True).start()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # pragma: no cover (alive, another user's)
        return True
    return True

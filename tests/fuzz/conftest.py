"""The fuzz suite's harness: every case ends in a valid result or one clean ``SfwGymError``.

``outcome(category, fn)`` runs one case under a 10 s alarm and tallies it: ``valid`` (it
returned), ``clean error`` (an :class:`~sfw_gym.SfwGymError` with a one-line message, naming the
input where the case says which), anything else fails the test (a traceback, an unclear or
multi-line message, a hang). The tally is printed after the run (the table in
docs/results/testing.md).

Profiles: ``ci`` (the default, bounded so CI stays quick) and ``long``::

    pytest tests/fuzz --hypothesis-profile long
"""

from __future__ import annotations

import collections
import signal
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import HealthCheck, settings

from sfw_gym.core.errors import SfwGymError

TIME_LIMIT_S = 10
_QUIET = [HealthCheck.too_slow, HealthCheck.function_scoped_fixture]
# CI's profile is derandomized (the same cases every run: a red CI means a change broke one);
# the long profile explores new ones each time.
settings.register_profile(
    "ci", max_examples=30, deadline=None, suppress_health_check=_QUIET, derandomize=True
)
settings.register_profile("long", max_examples=400, deadline=None, suppress_health_check=_QUIET)
settings.load_profile("ci")

TALLY: collections.Counter[tuple[str, str]] = collections.Counter()


class Hang(Exception):
    """A case ran past :data:`TIME_LIMIT_S`."""


def _alarm(signum: int, frame: Any) -> None:
    raise Hang(f"no result within {TIME_LIMIT_S} s")


def outcome(category: str, fn: Callable[[], Any], names: str | None = None) -> str:
    """Run one case; ``names``: text the error message must contain (the input's name)."""
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(TIME_LIMIT_S)
    try:
        fn()
    except SfwGymError as exc:
        message = str(exc)
        assert message and "\n" not in message, f"{category}: not one line: {message!r}"
        assert names is None or names in message, f"{category}: {message!r} names no {names!r}"
        result = "clean error"
    else:
        result = "valid"
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    TALLY[(category, result)] += 1
    return result


def pytest_terminal_summary(terminalreporter: Any) -> None:
    if not TALLY:
        return
    categories = sorted({c for c, _ in TALLY})
    terminalreporter.section("fuzz cases per category")
    terminalreporter.write_line("| category | cases | clean errors | valid results |")
    terminalreporter.write_line("|---|---:|---:|---:|")
    for c in categories:
        clean, valid = TALLY[(c, "clean error")], TALLY[(c, "valid")]
        terminalreporter.write_line(f"| {c} | {clean + valid} | {clean} | {valid} |")


@pytest.fixture
def case() -> Callable[..., str]:
    return outcome

"""Fixtures shared by the evaluation tests."""

from __future__ import annotations

from types import ModuleType

import pytest


@pytest.fixture
def short_demo(monkeypatch: pytest.MonkeyPatch) -> ModuleType:
    """:mod:`sfw_gym.demo` running its own flow on 40-step episodes (``run_demo`` imports
    ``sfw_gym.evaluation.evaluate`` when it runs, so that is what is shortened)."""
    from sfw_gym import demo, evaluation

    evaluate = evaluation.evaluate

    def short(*args, **kwargs):
        return evaluate(*args, **kwargs, env_kwargs={"max_steps": 40})

    monkeypatch.setattr(evaluation, "evaluate", short)
    return demo

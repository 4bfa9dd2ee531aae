"""GoalDriver's bump rules: a wall ahead is remembered and backed off; so is every third slide."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from sfw_gym.core.constants import U8_UNKNOWN
from sfw_gym.navigation.goal_driver import BACK_OFF, GoalDriver


class Finder:
    goal_tolerance_m, step = 0.2, 0

    def __init__(self) -> None:
        self.bumps = 0

    def mark_bump(self, view) -> None:
        self.bumps += 1


def bumped_view(moved_m: float, action_type: str = "continuous") -> SimpleNamespace:
    """A view one step after a full-speed forward command (0.1 m wanted), moved ``moved_m``."""
    return SimpleNamespace(
        bumped=True,
        max_linear_speed_m_s=1.0,
        control_period_s=0.1,
        xy=np.array([moved_m, 0.0]),
        action_type=action_type,
        belief_u8=np.full((4, 4), U8_UNKNOWN, np.uint8),  # the target stays unresolved
    )


def contact(driver: GoalDriver, view: SimpleNamespace):
    """The driver's command after a step driving forward that ended in ``view``."""
    driver._driving, driver._last, driver.steps = True, (1.0, np.zeros(2)), 1
    return driver.command(view)


def test_a_wall_ahead_is_remembered_and_backed_off_at_once():
    finder = Finder()
    driver = GoalDriver(finder, max_steps=80)
    driver.reset()
    assert contact(driver, bumped_view(0.0)) == BACK_OFF
    assert finder.bumps == 1


def test_every_third_slide_along_a_wall_backs_off():
    finder = Finder()
    driver = GoalDriver(finder, max_steps=80)
    driver.reset()
    sliding = bumped_view(0.08)  # moved most of the way: a slide, no wall ahead
    commands = [contact(driver, sliding) for _ in range(6)]
    assert commands == [None, None, BACK_OFF, None, None, BACK_OFF]
    assert finder.bumps == 0
    # a wall ahead starts the count again
    assert contact(driver, sliding) is None
    assert contact(driver, bumped_view(0.0)) == BACK_OFF
    assert [contact(driver, sliding) for _ in range(3)] == [None, None, BACK_OFF]


def test_discrete_actions_never_reverse():
    driver = GoalDriver(Finder(), max_steps=80)
    driver.reset()
    assert contact(driver, bumped_view(0.0, "discrete")) is None
    assert [contact(driver, bumped_view(0.08, "discrete")) for _ in range(3)] == [None] * 3

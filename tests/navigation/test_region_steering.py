"""RegionSteering on hand-made corridors: the anchor pulls the micro choice towards the region, a
chosen goal is driven rather than chosen again, and with nothing to explore it turns."""

from __future__ import annotations

import numpy as np

from sfw_gym.core.constants import U8_FREE, U8_UNKNOWN, U8_WALL
from sfw_gym.mapping.grid import GridSpec
from sfw_gym.navigation.candidates import GoalFinder
from sfw_gym.navigation.goal_driver import TURN, GoalDriver
from sfw_gym.navigation.regions import RegionSteering
from sfw_gym.navigation.view import RobotView

RES = 0.1


def corridor_with_two_ends() -> np.ndarray:
    """A 1.2 m wide corridor (rows 1-12) along x, unknown at both ends: columns 0-4 and 45-59."""
    b = np.full((14, 60), U8_FREE, np.uint8)
    b[0, :] = b[13, :] = U8_WALL
    b[1:13, :5] = U8_UNKNOWN
    b[1:13, 45:] = U8_UNKNOWN
    return b


def steering_on(belief: np.ndarray, xy: tuple[float, float], anchor_cost_per_m: float = 1.0):
    grid = GridSpec((0.0, 0.0), RES, belief.shape)
    view = RobotView.hand_made(belief, grid, (xy[0], xy[1], 0.0), np.array([[0.05, 0.65]]))
    finder = GoalFinder()
    finder.reset(view)
    driver = GoalDriver(finder, max_steps=40)
    driver.reset()
    steering = RegionSteering(finder, driver, anchor_cost_per_m)
    steering.reset()
    return steering, driver, view


def test_the_anchor_pulls_the_choice_to_the_far_end():
    """The robot stands nearer the left end: alone, explore_lite drives there; with the region
    anchored at the right end it drives right."""
    for anchor, side in ((None, "left"), ((6, 55), "right")):
        steering, driver, view = steering_on(corridor_with_two_ends(), (1.95, 0.65))
        steering.start(anchor, steps=5)
        assert steering.command(view, 0) is not None
        assert (driver.target[1] < 19) == (side == "left"), (anchor, driver.target)
        assert steering.micro_decisions == 1


def test_a_chosen_goal_is_driven_not_chosen_again():
    steering, _, view = steering_on(corridor_with_two_ends(), (1.95, 0.65))
    steering.start(None, steps=4)
    commands = [steering.command(view, step) for step in range(4)]
    assert all(c is not None for c in commands)
    assert steering.micro_decisions == 1  # one choice, then driven
    assert steering.command(view, 4) is None  # the decision's steps are spent


def test_with_nothing_to_explore_it_turns_in_place():
    b = np.full((14, 60), U8_FREE, np.uint8)
    b[0, :] = b[13, :] = U8_WALL
    b[:, 0] = b[:, 59] = U8_WALL
    steering, _, view = steering_on(b, (1.95, 0.65))
    steering.start(None, steps=2)
    assert steering.command(view, 0) == TURN

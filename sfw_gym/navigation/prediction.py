"""Map prediction: what a predictor reads of the robot's view, what it returns, and two
predictors that learn nothing (the baselines a learned one must beat).

A predictor guesses, for every cell, the probability that it is truly free and that it is a wall
(the rest is outside the building), from what the robot knows: the belief's classes, where it has
been and where its routers are (:class:`PredictorInputs`). Its answer is a :class:`PredictedMap`
in which the believed cells keep their belief. The learned predictor is
:class:`sfw_gym.rl.map_predictor.LearnedMapPredictor` (torch, the ``rl`` extra).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy import ndimage

from sfw_gym.mapping.grid import GridSpec, belief_classes
from sfw_gym.navigation.view import RobotView

#: A cell's class in the belief codes (:meth:`PredictorInputs.codes`) and in the truth.
FREE, WALL, UNKNOWN = 0, 1, 2
#: In the truth, class 2 is outside the building (the truth grid's 127).
OUTSIDE = UNKNOWN
#: Bit 2 of a belief code: the robot's trajectory passed through the cell.
VISITED_BIT = 4
#: The predictor's input channels, in order (:func:`input_channels`).
INPUT_CHANNELS = ("free", "wall", "unknown", "visited", "router_proximity", "inside")
#: Distance at which a cell's router proximity falls to 1/e (m).
ROUTER_PROXIMITY_SCALE_M = 5.0


def belief_class(belief_u8: np.ndarray) -> np.ndarray:
    """The belief read by thirds, as classes ``FREE``, ``WALL``, ``UNKNOWN`` (uint8)."""
    free, wall, _ = belief_classes(belief_u8)
    out = np.full(free.shape, UNKNOWN, np.uint8)
    out[free] = FREE
    out[wall] = WALL
    return out


def truth_class(truth_u8: np.ndarray) -> np.ndarray:
    """The ground truth (0 wall, 255 free, 127 outside) as classes ``FREE``, ``WALL``,
    ``OUTSIDE`` (uint8)."""
    t = np.asarray(truth_u8)
    out = np.full(t.shape, OUTSIDE, np.uint8)
    out[t == 255] = FREE
    out[t == 0] = WALL
    return out


def router_proximity(grid: GridSpec, routers_xy: np.ndarray) -> np.ndarray:
    """Per cell, ``exp(-d / ROUTER_PROXIMITY_SCALE_M)`` with ``d`` the distance to the nearest
    router (float32): where the mapper's rays converge."""
    x, y = grid.cell_centres()
    routers = np.asarray(routers_xy, np.float64).reshape(-1, 2)
    d = np.hypot(x[..., None] - routers[:, 0], y[..., None] - routers[:, 1]).min(axis=-1)
    return np.exp(-d / ROUTER_PROXIMITY_SCALE_M).astype(np.float32)


def input_channels(codes: np.ndarray, proximity: np.ndarray) -> np.ndarray:
    """The predictor's input ``(len(INPUT_CHANNELS), H, W)`` float32 from belief ``codes`` and
    :func:`router_proximity` (the same for one cell or a batch ``(..., H, W)``)."""
    cls = codes & 3
    stack = [
        cls == FREE,
        cls == WALL,
        cls == UNKNOWN,
        (codes & VISITED_BIT) > 0,
        np.broadcast_to(proximity, codes.shape),
        np.ones(codes.shape, bool),
    ]
    return np.stack(stack, axis=-3).astype(np.float32)


class PredictorInputs:
    """What a predictor reads of the robot's view, kept up to date along an episode (the
    trajectory's cells are folded in as the view's odometry trajectory grows)."""

    def __init__(self, view: RobotView) -> None:
        self.grid = view.grid
        self.visited = np.zeros(view.grid.shape, bool)
        self.proximity = router_proximity(view.grid, view.routers_xy)
        self._n = 0

    def codes(self, view: RobotView) -> np.ndarray:
        """Per cell: the belief's class, plus ``VISITED_BIT`` where the trajectory passed."""
        traj = view.odometry_trajectory
        if len(traj) > self._n:
            rc = self.grid.world_to_cell(np.asarray(traj[self._n :], np.float64))
            h, w = self.visited.shape
            ok = (rc[:, 0] >= 0) & (rc[:, 0] < h) & (rc[:, 1] >= 0) & (rc[:, 1] < w)
            self.visited[rc[ok, 0], rc[ok, 1]] = True
            self._n = len(traj)
        return belief_class(view.belief_u8) | (self.visited.astype(np.uint8) * VISITED_BIT)

    def channels(self, view: RobotView) -> np.ndarray:
        """:func:`input_channels` of the view now."""
        return input_channels(self.codes(view), self.proximity)


@dataclass(frozen=True)
class PredictedMap:
    """A predictor's answer over the whole map (float32 ``(H, W)`` each).

    Attributes:
        p_free: Probability that the cell is truly free (1 where the belief says free).
        p_wall: Probability that it is a wall (1 where the belief says wall).
        spread: Disagreement about ``p_free`` (the ensemble's standard deviation; 0 where
            known or where the predictor has no ensemble).
    """

    p_free: np.ndarray
    p_wall: np.ndarray
    spread: np.ndarray

    @classmethod
    def with_belief(
        cls, codes: np.ndarray, p_free: np.ndarray, p_wall: np.ndarray, spread: np.ndarray
    ) -> PredictedMap:
        """The prediction with the believed cells set to their belief."""
        cls_ = codes & 3
        free, wall = cls_ == FREE, cls_ == WALL
        known = free | wall
        return cls(
            np.where(free, 1.0, np.where(wall, 0.0, p_free)).astype(np.float32),
            np.where(wall, 1.0, np.where(free, 0.0, p_wall)).astype(np.float32),
            np.where(known, 0.0, spread).astype(np.float32),
        )


class MapPredictor(Protocol):
    """Anything that predicts a map from belief codes and router proximity."""

    def predict_codes(self, codes: np.ndarray, proximity: np.ndarray) -> PredictedMap: ...


class FreePriorPredictor:
    """Every unknown cell at the training set's class frequencies (learns nothing)."""

    def __init__(self, p_free: float = 0.6, p_wall: float = 0.15) -> None:
        self.p_free, self.p_wall = float(p_free), float(p_wall)

    def predict_codes(self, codes: np.ndarray, proximity: np.ndarray) -> PredictedMap:
        full = np.ones(codes.shape, np.float32)
        return PredictedMap.with_belief(
            codes, full * self.p_free, full * self.p_wall, np.zeros_like(full)
        )


class NearestKnownPredictor:
    """Every unknown cell takes the class of the nearest believed cell (learns nothing)."""

    def predict_codes(self, codes: np.ndarray, proximity: np.ndarray) -> PredictedMap:
        cls_ = codes & 3
        unknown = cls_ == UNKNOWN
        if unknown.all():
            return FreePriorPredictor().predict_codes(codes, proximity)
        _, (r, c) = ndimage.distance_transform_edt(unknown, return_indices=True)
        nearest = cls_[r, c]
        zeros = np.zeros(codes.shape, np.float32)
        return PredictedMap.with_belief(
            codes, (nearest == FREE).astype(np.float32), (nearest == WALL).astype(np.float32), zeros
        )


def predict_view(predictor: MapPredictor, inputs: PredictorInputs, view: RobotView) -> PredictedMap:
    """``predictor``'s map for ``view`` (``inputs`` tracks the episode's trajectory)."""
    return predictor.predict_codes(inputs.codes(view), inputs.proximity)

"""The candidate menu and the choices made on it.

:class:`CandidateGoals` is a menu of K candidate goals (:mod:`sfw_gym.navigation.candidates`
builds it): targets, goal cells, sources (:data:`SOURCES`), features (:data:`FEATURES`) and a
validity mask. The choices on a menu live here: explore_lite's utility of a frontier cluster
(:func:`explore_lite_utilities`, :func:`explore_lite_choice`, and the proof that a bounded
search chose as a whole-map one would), the greedy agent's bits per metre
(:func:`bits_per_metre`, :func:`greedy_choice`), and the teachers of the learned explorers
(:data:`TEACHERS`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from sfw_gym.navigation.planning import CostField

#: Columns of :attr:`CandidateGoals.features`, units in the names.
FEATURES = (
    "path_cost_m",  # planner cost of the path to the goal cell (metres on free cells; inf: none)
    "distance_m",  # straight line from the robot to the target
    "cluster_size_m",  # frontier cluster length (cells × resolution); 0 for other sources
    "expected_gain_bits",  # entropy of the cells the mapper would update with the robot there
    "unknown_area_m2",  # unknown area within near_radius_m of the target
    "heading_change_rad",  # |bearing to the target − heading|, in [0, π]
    "times_tried",  # goals chosen near this target so far in the episode
    "times_blacklisted",  # goals given up near this target so far
    "is_hidden_room",  # 1.0 for a hidden-room target, else 0.0
    "strongest_rssi_dbm",  # strongest router heard within near_radius_m (NOT_HEARD_DBM: never)
)
SOURCES = ("frontier", "hidden_room", "info_gain")
_F = {name: i for i, name in enumerate(FEATURES)}


#: explore_lite's utility of a frontier cluster: GAIN_SCALE × size (m) − POTENTIAL_SCALE × cost
#: (m), the cost being the path plus TURN_COST_M_PER_RAD × the heading change (rad).
GAIN_SCALE, POTENTIAL_SCALE, TURN_COST_M_PER_RAD = 1.0, 3.0, 0.3


@dataclass(frozen=True)
class CandidateGoals:
    """A menu of goals (K rows). Deterministic for the same view and memory.

    Attributes:
        target_rc: ``(K, 2)`` the cell each candidate means to resolve.
        goal_rc: ``(K, 2)`` where the robot drives: the cheapest reachable cell whose footprint
            covers the target (the target itself when none is reachable).
        source: ``(K,)`` index into :data:`SOURCES`.
        features: ``(K, len(FEATURES))`` float64, columns named by :data:`FEATURES`.
        valid: ``(K,)`` whether the goal is reachable on the belief map.
        clusters: Per candidate, the ``(N, 2)`` cells of its frontier cluster (empty otherwise).
        paths: The shortest-path field the costs come from; ``paths.path(goal_rc[i])``.
        walled_off_rc: ``(M, 2)`` frontier cells (not excluded) that no path reaches.
    """

    target_rc: np.ndarray
    goal_rc: np.ndarray
    source: np.ndarray
    features: np.ndarray
    valid: np.ndarray
    clusters: Sequence[np.ndarray]
    paths: CostField
    walled_off_rc: np.ndarray

    def __len__(self) -> int:
        return len(self.target_rc)

    def feature(self, name: str) -> np.ndarray:
        """The column ``name`` of :attr:`features`."""
        return self.features[:, _F[name]]

    def of(self, source: str) -> np.ndarray:
        """Indices of the candidates from ``source``."""
        return np.flatnonzero(self.source == SOURCES.index(source))

    def path(self, i: int) -> np.ndarray:
        """``(N, 2)`` cells from the robot to candidate ``i``'s goal cell (empty if invalid)."""
        return self.paths.path(tuple(self.goal_rc[i]))


def explore_lite_utilities(
    menu: CandidateGoals,
    anchor_rc: tuple[int, int] | None = None,
    anchor_cost_per_m: float = 0.0,
    resolution_m: float = 1.0,
) -> np.ndarray:
    """explore_lite's utility of each of the menu's candidates (with the frontier agent's
    default scales; ``-inf`` for those that are no reachable frontier candidate).

    With ``anchor_rc`` (a region chosen higher up: :mod:`sfw_gym.navigation.regions`), each
    candidate's utility also loses ``anchor_cost_per_m`` per metre between its target and the
    anchor cell (cells of ``resolution_m``)."""
    f = menu.feature
    cost = f("path_cost_m") + TURN_COST_M_PER_RAD * f("heading_change_rad")
    utility = GAIN_SCALE * f("cluster_size_m") - POTENTIAL_SCALE * cost
    if np.isnan(utility[menu.valid]).any():
        raise ValueError(
            "explore_lite_choice needs the menu's path_cost_m, heading_change_rad and "
            "cluster_size_m features (GoalFinder.find(features=...) left one out)"
        )
    if anchor_rc is not None and anchor_cost_per_m > 0 and len(menu):
        offset_m = (menu.target_rc - np.asarray(anchor_rc)) * resolution_m
        utility = utility - anchor_cost_per_m * np.hypot(offset_m[:, 0], offset_m[:, 1])
    ok = menu.valid & (menu.source == SOURCES.index("frontier"))
    return np.where(ok, utility, -np.inf)


def explore_lite_choice(
    menu: CandidateGoals,
    anchor_rc: tuple[int, int] | None = None,
    anchor_cost_per_m: float = 0.0,
    resolution_m: float = 1.0,
) -> int | None:
    """The index of the menu's frontier candidate of best explore_lite utility (the first of
    equal ones; None when no frontier candidate is reachable): the frontier agent's choice on
    a K-candidate menu, the teacher of the learned explorer. The arguments are those of
    :func:`explore_lite_utilities`."""
    utility = explore_lite_utilities(menu, anchor_rc, anchor_cost_per_m, resolution_m)
    return int(np.argmax(utility)) if np.isfinite(utility).any() else None


def proven_on_bounded_paths(menu: CandidateGoals, utility: np.ndarray) -> bool:
    """Whether the best of ``utility`` (:func:`explore_lite_utilities` of a menu of frontier
    clusters built on a bounded :func:`cost_field`) is the choice a search of the whole map
    would make: a cluster whose cost counted in the utility (path, turn and anchor terms: the
    cluster's size less its utility, over ``POTENTIAL_SCALE``) lies within the bound has that
    exact cost (each cell beyond costs at least the bound), and any other cluster has a utility
    below its size less ``POTENTIAL_SCALE`` × the bound. The best exact one must beat those."""
    paths = menu.paths
    if paths.complete:
        return True
    size = menu.feature("cluster_size_m")
    cost = (GAIN_SCALE * size - utility) / POTENTIAL_SCALE
    exact = cost <= paths.max_cost_m
    best = utility[exact].max(initial=-np.inf)
    beyond = (GAIN_SCALE * size - POTENTIAL_SCALE * paths.max_cost_m)[~exact]
    return bool(np.isfinite(best) and best > beyond.max(initial=-np.inf))


def bits_per_metre(menu: CandidateGoals, distance_offset_m: float = 1.0) -> np.ndarray:
    """The greedy agent's score of each candidate: expected gain (bits) ÷ (path cost +
    ``distance_offset_m``)."""
    return menu.feature("expected_gain_bits") / (menu.feature("path_cost_m") + distance_offset_m)


#: The tuned greedy agent's distance offset (DESIGN.md's sweep): the greedy teacher's.
GREEDY_OFFSET_M = 0.3


def greedy_choice(menu: CandidateGoals, distance_offset_m: float = GREEDY_OFFSET_M) -> int | None:
    """The index of the valid candidate with the most expected bits per metre
    (:func:`bits_per_metre`; the tuned greedy agent's offset), None when none is valid."""
    score = np.where(menu.valid, bits_per_metre(menu, distance_offset_m), -np.inf)
    return int(np.argmax(score)) if menu.valid.any() else None


#: Teachers on a full menu (every feature computed), by name: each returns a candidate or None.
TEACHERS: dict[str, Callable[[CandidateGoals], int | None]] = {
    "explore_lite": explore_lite_choice,
    "greedy": greedy_choice,
}

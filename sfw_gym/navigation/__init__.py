"""Map analysis and motion on the robot's belief map: candidate goals, frontiers and hidden
rooms, router zones, cost fields and paths, pure pursuit, and the waypoint driver. Reads maps,
never the world.
"""

from __future__ import annotations

from sfw_gym.navigation.candidates import CandidateSettings, GoalFinder, candidate_goals
from sfw_gym.navigation.frontiers import Frontier, find_frontiers, frontier_mask, hidden_rooms
from sfw_gym.navigation.menu import FEATURES, SOURCES, CandidateGoals
from sfw_gym.navigation.path_gain import (
    best_prefix_rate,
    path_totals,
    readings_along,
    walls_crossed,
)
from sfw_gym.navigation.planning import (
    CostField,
    PurePursuit,
    cost_field,
    to_discrete,
    traversal_costs,
)
from sfw_gym.navigation.radio_zones import dominance_bands, router_scores
from sfw_gym.navigation.waypoints import (
    BLOCK_FEATURES,
    WaypointDriver,
    block_features,
    plan_path,
    waypoint_goal_xy,
)

__all__ = [
    "BLOCK_FEATURES",
    "FEATURES",
    "SOURCES",
    "CandidateGoals",
    "CandidateSettings",
    "CostField",
    "Frontier",
    "GoalFinder",
    "PurePursuit",
    "WaypointDriver",
    "best_prefix_rate",
    "block_features",
    "candidate_goals",
    "cost_field",
    "dominance_bands",
    "find_frontiers",
    "frontier_mask",
    "hidden_rooms",
    "path_totals",
    "plan_path",
    "readings_along",
    "router_scores",
    "to_discrete",
    "traversal_costs",
    "walls_crossed",
    "waypoint_goal_xy",
]

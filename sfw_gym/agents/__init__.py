"""Baseline agents that drive SfW-Explore using only the robot's view (never the ground truth)."""

from __future__ import annotations

from sfw_gym.agents.base import STOP_REASONS, Agent, RobotView, RobotViewHandle
from sfw_gym.agents.frontier import FrontierAgent, find_frontiers, frontier_mask

__all__ = [
    "STOP_REASONS",
    "Agent",
    "FrontierAgent",
    "RobotView",
    "RobotViewHandle",
    "find_frontiers",
    "frontier_mask",
]

"""Baseline agents that drive SfW-Explore using only the robot's view (never the ground truth).

Every agent is built with keyword parameters (all optional), bound to an episode with
``agent.reset(env)`` and asked for actions with ``agent.act(obs)``; see :mod:`sfw_gym.agents.base`.
``make_agent("frontier", **params)`` builds one by its command-line name.
"""

from __future__ import annotations

from typing import Any

from sfw_gym.agents.base import STOP_REASONS, Agent, RobotView, RobotViewHandle
from sfw_gym.agents.cross_pass import CrossPassAgent, dominance_bands, router_scores
from sfw_gym.agents.frontier import FrontierAgent, find_frontiers, frontier_mask, hidden_rooms
from sfw_gym.agents.greedy import GreedyInfoGainAgent
from sfw_gym.agents.ppo import PPOAgent
from sfw_gym.agents.random_agent import RandomAgent
from sfw_gym.errors import ConfigError

#: Agents by their command-line name.
AGENTS: dict[str, type[Agent]] = {
    cls.name: cls
    for cls in (FrontierAgent, CrossPassAgent, GreedyInfoGainAgent, RandomAgent, PPOAgent)
}


def make_agent(name: str, **params: Any) -> Agent:
    """Build the agent registered as ``name`` (see :data:`AGENTS`) with ``params``."""
    if name not in AGENTS:
        raise ConfigError(f"unknown agent {name!r}; known: {sorted(AGENTS)}")
    try:
        return AGENTS[name](**params)
    except TypeError as exc:
        raise ConfigError(f"agent {name!r}: {exc}") from None


__all__ = [
    "AGENTS",
    "STOP_REASONS",
    "Agent",
    "CrossPassAgent",
    "FrontierAgent",
    "GreedyInfoGainAgent",
    "PPOAgent",
    "RandomAgent",
    "RobotView",
    "RobotViewHandle",
    "dominance_bands",
    "find_frontiers",
    "frontier_mask",
    "hidden_rooms",
    "make_agent",
    "router_scores",
]

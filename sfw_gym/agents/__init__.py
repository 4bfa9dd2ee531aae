"""Baseline agents that drive SfW-Explore using only the robot's view (never the ground truth).

Every agent is built with keyword parameters (all optional), bound to an episode with
``agent.reset(env)`` and asked for actions with ``agent.act(obs)``; see :mod:`sfw_gym.agents.base`.
``make_agent("frontier", **params)`` builds one by its command-line name: a name of
:data:`AGENTS`, one an installed package adds through the :data:`ENTRY_POINT_GROUP` entry points,
or a ``"module:Class"`` (:func:`agent_class`, the one place every command resolves a name).
"""

from __future__ import annotations

import importlib
import warnings
from typing import Any

from sfw_gym.agents.base import STOP_REASONS, Agent, RobotView, RobotViewHandle
from sfw_gym.agents.cross_pass import CrossPassAgent
from sfw_gym.agents.frontier import FrontierAgent
from sfw_gym.agents.greedy import GreedyInfoGainAgent
from sfw_gym.agents.random_agent import RandomAgent
from sfw_gym.agents.regions import RegionAgent
from sfw_gym.core.errors import ConfigError

#: Agents by their command-line name, as ``"module:Class"`` entry points imported on first use
#: (like Gymnasium's env registry): the learned agent lives in :mod:`sfw_gym.rl` and needs the
#: ``[rl]`` extra (torch, stable-baselines3), which the classical agents do not.
AGENTS: dict[str, str] = {
    "frontier": "sfw_gym.agents.frontier:FrontierAgent",
    "cross-pass": "sfw_gym.agents.cross_pass:CrossPassAgent",
    "greedy": "sfw_gym.agents.greedy:GreedyInfoGainAgent",
    "random": "sfw_gym.agents.random_agent:RandomAgent",
    "region-teacher": "sfw_gym.agents.regions:RegionAgent",
    # the learned agents, named by what trains them (sfw-gym train ppo_mask / train ppo)
    "regions-ppo": "sfw_gym.rl.agent:RegionsPPOAgent",
    "goals-ppo": "sfw_gym.rl.agent:PPOAgent",
    "wheels-ppo": "sfw_gym.rl.wheels_agent:WheelsPPOAgent",
    "waypoint-ppo": "sfw_gym.rl.waypoint_agent:WaypointPPOAgent",
    # greedy bits per metre on the learned map predictor's map
    "predict-explore": "sfw_gym.rl.predict_explore:PredictExploreAgent",
    # predict-explore's candidates ranked by the mapper's update run dry along their paths
    "rollout-explore": "sfw_gym.rl.predict_explore:RolloutExploreAgent",
    # privileged: they read the ground truth (sfw_gym.agents.oracles); run only when named
    "oracle-coverage": "sfw_gym.agents.coverage_oracle:CoverageOracle",
    "oracle-regions": "sfw_gym.agents.region_oracle:RegionOracle",
    # the candidate of rollout-explore's menu that truly gains most: the ceiling of its ranking
    "oracle-rollout": "sfw_gym.rl.predict_explore:RolloutOracleAgent",
    # the coverage oracle less one piece of its knowledge each: where the ceiling lives
    "oracle-belief-paths": "sfw_gym.agents.coverage_oracle:BeliefPathsOracle",
    "oracle-frontier-targets": "sfw_gym.agents.coverage_oracle:FrontierTargetsOracle",
    "oracle-belief-gain": "sfw_gym.agents.coverage_oracle:BeliefGainOracle",
}
#: Names deprecated in 0.2.0, removed in 0.3.0 (CHANGELOG.md): each warns (FutureWarning) and
#: builds the agent it names now.
DEPRECATED_AGENTS: dict[str, str] = {
    "ppo": "regions-ppo",
    "ppo-goals": "goals-ppo",
    "ppo-waypoint": "waypoint-ppo",
}


#: The entry-point group through which an installed package adds agents by name, for every
#: command that takes one: in its pyproject.toml,
#: ``[project.entry-points."sfw_gym.agents"]`` ``mine = "pkg.mod:MyAgent"``.
ENTRY_POINT_GROUP = "sfw_gym.agents"


def installed_agents() -> dict[str, str]:
    """The agents installed packages add (:data:`ENTRY_POINT_GROUP`), name → ``"module:Class"``.
    A name the package has already (:data:`AGENTS`, :data:`DEPRECATED_AGENTS`) stays the
    built-in's, with a warning."""
    from importlib.metadata import entry_points

    found: dict[str, str] = {}
    for point in entry_points(group=ENTRY_POINT_GROUP):
        if point.name in AGENTS or point.name in DEPRECATED_AGENTS:
            warnings.warn(
                f"entry point {point.name} = {point.value!r} ({ENTRY_POINT_GROUP}) is ignored: "
                f"{point.name!r} is a built-in agent's name; run yours as {point.value!r}",
                stacklevel=2,
            )
            continue
        found.setdefault(point.name, point.value)
    return found


def agent_names() -> list[str]:
    """Every agent name the commands take: :data:`AGENTS`', then :func:`installed_agents`'
    (deprecated names work, with a warning, but are not listed)."""
    return [*AGENTS, *installed_agents()]


def unknown_agents_error(names: list[str]) -> ConfigError:
    """The one-line error for agent names that are none of :func:`agent_names`."""
    which = f"agent {names[0]!r}" if len(names) == 1 else f"agent(s) {names}"
    return ConfigError(
        f"unknown {which}; known: {', '.join(agent_names())}; or a 'module:Class' of your own"
    )


def register_agent(name: str, entry_point: str) -> None:
    """Make ``make_agent(name)`` build your agent, in this process only (the evaluation's
    worker processes and a command line reach it by ``"module:Class"`` or an installed
    package's :data:`ENTRY_POINT_GROUP` entry point)."""
    if ":" not in entry_point:
        raise ConfigError(
            f"agent {name!r}: entry point must be 'module:Class', got {entry_point!r}"
        )
    AGENTS[name] = entry_point


def known_agent(name: str) -> bool:
    """Whether ``name`` is registered, installed (:func:`installed_agents`) or a deprecated
    name of a registered agent."""
    return name in AGENTS or name in DEPRECATED_AGENTS or name in installed_agents()


def agent_class(name: str) -> type[Agent]:
    """The class registered as ``name``, installed as ``name`` (:func:`installed_agents`), or
    named by a ``"module:Class"`` (both also reach the evaluation's worker processes, where a
    :func:`register_agent` call made in the parent is unknown). A deprecated name warns and
    resolves to its new one."""
    if name in DEPRECATED_AGENTS and name not in AGENTS:
        new = DEPRECATED_AGENTS[name]
        warnings.warn(
            f"agent name {name!r} is deprecated: use {new!r} (the old name goes in sfw_gym 0.3)",
            FutureWarning,
            stacklevel=3,
        )
        name = new
    installed = installed_agents()  # read here, so that a clash with a built-in warns
    entry_point = AGENTS.get(name) or installed.get(name)
    module, _, cls = (entry_point or (name if ":" in name else "")).partition(":")
    if not (module and cls):
        raise unknown_agents_error([name])
    entry_point = f"{module}:{cls}"
    try:
        found = getattr(importlib.import_module(module), cls)
    except ImportError as exc:
        raise ConfigError(
            f"agent {name!r} needs {exc.name!r}: pip install 'sfw-gym[rl]'"
            if exc.name in ("torch", "stable_baselines3", "sb3_contrib")
            else f"agent {name!r}: cannot import {entry_point} ({exc})"
        ) from None
    except AttributeError:
        raise ConfigError(f"agent {name!r}: module {module!r} has no {cls!r}") from None
    except (ValueError, TypeError) as exc:  # e.g. a relative module name
        raise ConfigError(f"agent {name!r}: cannot import {entry_point} ({exc})") from None
    if not (isinstance(found, type) and issubclass(found, Agent)):
        raise ConfigError(f"agent {name!r}: {entry_point} is not an sfw_gym Agent subclass")
    return found


def is_privileged(name: str) -> bool:
    """Whether the agent ``name`` reads the ground truth: an oracle
    (:mod:`sfw_gym.agents.oracles`), which runs only where it is named."""
    return agent_class(name).privileged


def make_agent(name: str, **params: Any) -> Agent:
    """Build the agent registered as ``name`` (see :data:`AGENTS`) with ``params``."""
    cls = agent_class(name)
    try:
        return cls(**params)
    except TypeError as exc:
        raise ConfigError(f"agent {name!r}: {exc}") from None


__all__ = [
    "AGENTS",
    "DEPRECATED_AGENTS",
    "ENTRY_POINT_GROUP",
    "STOP_REASONS",
    "Agent",
    "CrossPassAgent",
    "FrontierAgent",
    "GreedyInfoGainAgent",
    "RandomAgent",
    "RegionAgent",
    "RobotView",
    "RobotViewHandle",
    "agent_class",
    "agent_names",
    "installed_agents",
    "is_privileged",
    "known_agent",
    "make_agent",
    "register_agent",
    "unknown_agents_error",
]

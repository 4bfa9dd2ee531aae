"""The agent interface and the robot's view, the only door from an agent to the environment.

An agent is built with keyword parameters only (every one has a default), bound to an episode with
:meth:`Agent.reset`, then asked for one action per step with :meth:`Agent.act`::

    env = gym.make("SfW-Explore-v0")
    agent = FrontierAgent()
    obs, info = env.reset(seed=0)
    agent.reset(env, seed=0)
    while True:
        obs, reward, terminated, truncated, info = env.step(agent.act(obs))
        if terminated or truncated:
            break

:meth:`Agent.reset` keeps a :class:`RobotViewHandle` and nothing else of the environment: the
handle can call ``env.unwrapped.robot_view()`` (the robot's belief map, odometry pose, router
positions, RSSI history, bump flag) and nothing more. Ground truth (the floorplan, the true pose,
the true k-values) stays out of reach.

Without the env at hand (a ``gymnasium.vector`` env, another process, RLlib), an agent acts on
what the env returns: wrap it in :class:`~sfw_gym.envs.robot_view_info.RobotViewInInfo`, then
``agent.reset(info=info, seed=0)`` and ``agent.act(obs, info)`` read ``info["robot_view"]``.
"""

from __future__ import annotations

import inspect
from abc import ABC, abstractmethod
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError
from sfw_gym.navigation.menu import FEATURES, CandidateGoals
from sfw_gym.navigation.view import RobotView

#: Why an exploring agent stopped looking for goals.
STOP_REASONS = ("no_frontiers", "all_blacklisted", "max_steps")


@dataclass(frozen=True)
class Decision:
    """One choice of a goal among the candidate menu, as every menu-choosing agent (frontier,
    greedy, the learned explorer) logs it in :attr:`Agent.decisions`.

    Attributes:
        step: The agent's step count when it chose.
        target_rc: The chosen candidate's target cell.
        n_candidates: How many candidates the menu held.
        features: The chosen candidate's :data:`~sfw_gym.navigation.menu.FEATURES`
            (NaN where that agent's menu does not compute one).
    """

    step: int
    target_rc: tuple[int, int]
    n_candidates: int
    features: np.ndarray


def decision_arrays(decisions: list[Decision]) -> dict[str, np.ndarray]:
    """A decision log as arrays (for an episode's ``.npz``): ``decision_step`` ``(N,)``,
    ``decision_target_rc`` ``(N, 2)``, ``decision_n_candidates`` ``(N,)``,
    ``decision_features`` ``(N, F)`` and ``decision_feature_names`` ``(F,)``."""
    return {
        "decision_step": np.array([d.step for d in decisions], np.int64),
        "decision_target_rc": np.array([d.target_rc for d in decisions], np.int64).reshape(-1, 2),
        "decision_n_candidates": np.array([d.n_candidates for d in decisions], np.int64),
        "decision_features": np.array([d.features for d in decisions], np.float64).reshape(
            -1, len(FEATURES)
        ),
        "decision_feature_names": np.array(FEATURES),
    }


class RobotViewHandle:
    """A callable that returns the robot's view and exposes nothing else of the environment.

    It keeps only the bound ``robot_view`` method (no attribute names the env), so an agent sees
    exactly what the robot knows: a :class:`~sfw_gym.navigation.view.RobotView`.

    Args:
        env: A Gymnasium env (wrapped or not) whose ``unwrapped`` has ``robot_view()``.

    Raises:
        ConfigError: If the env has no ``robot_view`` method.
    """

    __slots__ = ("_fn",)

    def __init__(self, env: Any) -> None:
        fn = getattr(getattr(env, "unwrapped", env), "robot_view", None)
        if not callable(fn):
            raise ConfigError(
                f"env {type(env).__name__} has no robot_view(): agents need SfW-Explore envs"
            )
        self._fn: Callable[[], RobotView] = fn

    def __call__(self) -> RobotView:
        """The robot's view now (fresh arrays)."""
        view = self._fn()
        if not isinstance(view, RobotView):
            raise TypeError(f"robot_view() must return a RobotView, got {type(view).__name__}")
        return view

    def __reduce__(self) -> Any:
        raise TypeError("a RobotViewHandle is bound to a live env and cannot be pickled")


def _view_in(info: Any, agent: str, method: str) -> RobotView:
    """``info["robot_view"]``, or a ConfigError naming the agent and the method."""
    view = info.get("robot_view") if isinstance(info, dict) else None
    if not isinstance(view, RobotView):
        got = type(info).__name__ if not isinstance(info, dict) else f"keys {sorted(info)}"
        raise ConfigError(
            f"{agent}.{method}(info=...) needs info['robot_view'] (a RobotView; wrap the env in "
            f"RobotViewInInfo), got {got}"
        )
    return view


@dataclass(frozen=True)
class AgentSettings(Config):
    """The parameters every agent has; each agent's own settings class derives from this one.

    Attributes:
        max_steps: Optional step limit of the agent (then ``stop_reason = "max_steps"``).
    """

    prefix: ClassVar[str | None] = ""  # named as the keyword arguments they are

    max_steps: int | None = setting(None, integer=True, ge=1, optional=True)


class Agent(ABC):
    """Base class of the baseline agents.

    Subclasses declare their parameters as a frozen :class:`AgentSettings` subclass (every field
    with a default and a checked range, so ``Agent()`` works and ``Agent(bad=1)`` names the
    nearest valid key), set ``name`` and ``settings_class``, and implement :meth:`_act`.
    Randomness comes from the agent's own generator, seeded in :meth:`reset`.

    Attributes:
        name: Short name used on the command line and in tables (``"frontier"``).
        settings: The parameters (an instance of ``settings_class``).
        stop_reason: ``None`` while the agent pursues goals; else why its goal search came up
            empty at its latest attempt (one of :data:`STOP_REASONS`). The baselines keep acting
            meanwhile (they fall back to sweeping), so an episode never stalls; the reason is
            cleared when a goal turns up again (``max_steps`` is final).
        steps: Actions taken since :meth:`reset`.
        decisions: This episode's choices among the candidate menu (:class:`Decision`; empty
            for agents that choose no menu goals).
    """

    name: ClassVar[str] = "agent"
    #: Whether the agent reads the ground truth (an oracle, :mod:`sfw_gym.agents.oracles`):
    #: never a default, never a robot's baseline.
    privileged: ClassVar[bool] = False
    action_types: ClassVar[tuple[str, ...]] = ("continuous", "discrete")
    #: The frozen, checked parameters: ``Agent(**params)`` builds ``settings_class(**params)``.
    settings_class: ClassVar[type[AgentSettings]] = AgentSettings

    def __init__(self, **params: Any) -> None:
        self.settings = self.settings_class.from_dict(params, f"agent {self.name!r}")
        self.stop_reason: str | None = None
        self.steps = 0
        self._view: RobotViewHandle | None = None
        self._episode_started = False
        self.rng = np.random.default_rng()
        self.action_type = "continuous"
        self.trajectory: list[tuple[float, float]] = []
        self.last_command = (0.0, 0.0)
        self.decisions: list[Decision] = []

    def reset(
        self, env: Any = None, seed: int | None = None, *, info: dict[str, Any] | None = None
    ) -> None:
        """Start an episode (call after ``env.reset``).

        Args:
            env: The environment; only its ``unwrapped.robot_view()`` is kept and used.
            seed: Seed of the agent's own random generator.
            info: Instead of ``env``: the reset's info holding ``"robot_view"``
                (:class:`~sfw_gym.envs.robot_view_info.RobotViewInInfo`); then every
                :meth:`act` needs the step's info too.
        """
        if info is not None:
            self._view = None
            view = _view_in(info, type(self).__name__, "reset")
        elif env is not None:
            self._view = RobotViewHandle(env)
            view = self._view()
        else:
            raise ConfigError(
                f"{type(self).__name__}.reset() needs the env or the reset's info "
                "(with info['robot_view']: wrap the env in RobotViewInInfo)"
            )
        if view.action_type not in self.action_types:
            raise ConfigError(
                f"{type(self).__name__} supports action types {self.action_types}, "
                f"the env uses {view.action_type!r}"
            )
        self.action_type = view.action_type
        self.rng = np.random.default_rng(seed)
        self._episode_started = True
        self.stop_reason = None
        self.steps = 0
        self.trajectory = []
        self.last_command = (0.0, 0.0)
        self.decisions = []
        self._on_reset(view)

    def act(self, obs: Any = None, info: dict[str, Any] | None = None) -> Any:
        """The next action: ``np.float32 (linear, angular)`` or a discrete action ``int``.

        ``info``: the last step's info; its ``"robot_view"`` is used when there (see
        :meth:`reset`), else the env bound at reset.
        """
        if info is not None and "robot_view" in info:
            view = _view_in(info, type(self).__name__, "act")
        elif self._view is not None:
            view = self._view()
        elif not self._episode_started:
            raise RuntimeError(f"{type(self).__name__}.act() called before reset()")
        else:
            raise ConfigError(
                f"{type(self).__name__}.act() needs info['robot_view'] (it was reset from an info)"
            )
        self.trajectory.append((float(view.odometry_pose[0]), float(view.odometry_pose[1])))
        max_steps = self.settings.max_steps
        if max_steps is not None and self.steps >= max_steps:
            self._stop("max_steps")
            linear, angular = 0.0, 0.0
        else:
            linear, angular = self._act(view, obs)
        self.steps += 1
        self.last_command = (float(linear), float(angular))
        return self._to_action(linear, angular)

    def params(self) -> dict[str, Any]:
        """The parameters (for logs and result files): :attr:`settings` as a dict, plus the
        constructor parameters of an agent written with its own ``__init__`` instead of a
        settings class (as agents were before 0.2.0), read from its attributes."""
        out = self.settings.to_dict()
        for klass in type(self).__mro__:
            init = klass.__dict__.get("__init__")
            if init is None or klass is Agent:
                continue
            for p in inspect.signature(init).parameters.values():
                plain = p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)
                if plain and p.name != "self" and p.name not in out and hasattr(self, p.name):
                    out[p.name] = getattr(self, p.name)
        return out

    # -- for subclasses -----------------------------------------------------------------------
    def _on_reset(self, view: RobotView) -> None:  # noqa: B027 (optional hook)
        """Per-episode set-up from the first view."""

    @abstractmethod
    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        """``(linear, angular)`` fractions in [-1, 1] for this step."""

    def _log_decision(self, menu: CandidateGoals, i: int) -> None:
        """Log the choice of candidate ``i`` of ``menu`` (:attr:`decisions`)."""
        target = (int(menu.target_rc[i, 0]), int(menu.target_rc[i, 1]))
        self.decisions.append(Decision(self.steps, target, len(menu), menu.features[i].copy()))

    def _stop(self, reason: str) -> None:
        """Record why the agent has no goal now (``max_steps`` is final)."""
        if self.stop_reason != "max_steps":
            self.stop_reason = reason

    def _resume(self) -> None:
        """The agent has a goal again: clear a ``no_frontiers`` / ``all_blacklisted`` reason."""
        if self.stop_reason != "max_steps":
            self.stop_reason = None

    def _to_action(self, linear: float, angular: float) -> Any:
        if self.action_type == "discrete":
            from sfw_gym.navigation.planning import to_discrete

            return to_discrete(linear, angular)
        return np.array([linear, angular], np.float32)

"""Candidate-goal actions: ``SfW-ExploreGoals-v0`` (:class:`SfWGoalsEnv`): each action picks
one of K goals from the navigation menu and the robot drives there."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sfw_gym.core.config import Config, setting
from sfw_gym.core.constants import NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.explore import SfWExploreEnv
from sfw_gym.navigation.candidates import GoalFinder
from sfw_gym.navigation.goal_driver import GoalDriver
from sfw_gym.navigation.menu import FEATURES, TEACHERS, CandidateGoals
from sfw_gym.navigation.planning import cost_field, to_discrete
from sfw_gym.navigation.view import RobotView

#: Scale of each feature column in the observation (value / scale, then clipped to [-1, 4]).
FEATURE_SCALES: dict[str, float] = {
    "path_cost_m": 10.0,
    "distance_m": 10.0,
    "cluster_size_m": 5.0,
    "expected_gain_bits": 50.0,
    "unknown_area_m2": math.pi,
    "heading_change_rad": math.pi,
    "times_tried": 5.0,
    "times_blacklisted": 5.0,
    "is_hidden_room": 1.0,
    "strongest_rssi_dbm": -float(NOT_HEARD_DBM),
}
_SCALES = np.array([FEATURE_SCALES[name] for name in FEATURES])


@dataclass(frozen=True)
class GoalsConfig(Config):
    """The menu's size (``max_candidates``), a decision's step limit and its reward (bits; see
    :class:`SfWGoalsEnv`)."""

    prefix: ClassVar[str | None] = "goals"
    max_candidates: int = setting(16, ge=2, le=128, integer=True)
    max_steps_per_goal: int = setting(80, ge=1, integer=True)
    cost_per_m_bits: float = setting(10.0, ge=0.0)
    cost_per_step_bits: float = setting(0.5, ge=0.0)
    goal_bonus_bits: float = setting(100.0, ge=0.0)
    reward_scale_bits: float = setting(100.0, gt=0.0)


class SfWGoalsEnv(gym.Env):
    """``SfW-ExploreGoals-v0``: ``Discrete(K)`` actions over the candidate-goal menu.

    Description:
        Each action picks one of K goals from the navigation menu
        (:func:`~sfw_gym.navigation.candidate_goals`: frontier goals with a path on the belief
        map) and the robot drives there, so a policy learns *where* to explore. One decision
        spans several steps of the explore env it wraps: the robot drives along the candidate's
        path (pure pursuit) until the goal is reached, the target cell is resolved, a bump,
        ``max_steps_per_goal`` steps, or the episode's end.

    Action Space:
        ``Discrete(K)``, K = ``max_candidates``: a slot of the menu. A masked action is no goal:
        the robot turns in place for one step (``info["invalid_action"]``);
        :meth:`action_masks` gives the mask to sb3-contrib's ``MaskablePPO``.

    Observation Space:
        The explore env's, plus ``candidates`` (``(K, F)`` features of
        :data:`~sfw_gym.navigation.menu.FEATURES`, each divided by its :data:`FEATURE_SCALES`
        entry; 0 for empty slots) and ``candidate_mask`` (1 where the goal is reachable).

    Rewards:
        What the decision bought, in bits: the map's information gain, minus
        ``cost_per_m_bits`` per metre driven and ``cost_per_step_bits`` per step spent (a
        contact costs the steps it wastes, no separate fine), plus ``goal_bonus_bits`` when the
        coverage target is reached; divided by ``reward_scale_bits`` so that a good decision is
        worth about one.

    Episode End:
        As the explore env's (coverage target or step budget, counted in its steps); the
        decision under way stops there.

    Args:
        goals: Overrides of :class:`GoalsConfig` (dict): the menu's size and the reward.
        render_mode: As the explore env's.
        **explore_kwargs: The explore env's keyword arguments.
    """

    metadata = SfWExploreEnv.metadata
    config_class: ClassVar[type[GoalsConfig]] = GoalsConfig

    def __init__(
        self,
        goals: dict[str, Any] | None = None,
        render_mode: str | None = None,
        **explore_kwargs: Any,
    ):
        self.config = self.config_class.from_dict(goals, self.config_class.prefix)
        self.explore = SfWExploreEnv(render_mode=render_mode, **explore_kwargs)
        self.render_mode = render_mode
        k = self.config.max_candidates
        explore_space = self.explore.observation_space
        assert isinstance(explore_space, spaces.Dict)
        self.action_space = spaces.Discrete(k)
        self.observation_space = spaces.Dict(
            {
                **explore_space.spaces,
                "candidates": spaces.Box(-1.0, 4.0, (k, len(FEATURES)), np.float32),
                "candidate_mask": spaces.Box(0, 1, (k,), np.int8),
            }
        )
        self.finder = GoalFinder()
        self.driver = GoalDriver(self.finder, self.config.max_steps_per_goal)
        self.menu: CandidateGoals | None = None

    # -- gymnasium API ---------------------------------------------------------------------------
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        obs, info = self.explore.reset(seed=seed, options=options)
        self.finder.reset(self.explore.robot_view())
        self.driver.reset()
        return self._observe(obs), info

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        i = self._action_index(action)
        assert self.menu is not None
        invalid = not self.driver.start(self.explore.robot_view(), self.menu, i)
        return self._decide(self.driver.command, invalid)

    def teacher_action(self, teacher: str = "explore_lite") -> int:
        """A teacher's choice on the current menu (:data:`~sfw_gym.navigation.candidates.
        TEACHERS`: ``explore_lite``, the frontier agent's utility, or ``greedy``, expected bits
        per metre; the first allowed action when it has none): the imitation teacher."""
        if teacher not in TEACHERS:
            raise ConfigError(f"unknown teacher {teacher!r}; known: {sorted(TEACHERS)}")
        choice = TEACHERS[teacher](self.menu) if self.menu is not None else None
        return int(np.argmax(self.action_masks())) if choice is None else choice

    def action_masks(self) -> np.ndarray:
        """Which actions pick a reachable candidate (for ``MaskablePPO``)."""
        return action_masks(self.menu, self.config.max_candidates)

    def render(self) -> Any:
        return self.explore.render()

    def close(self) -> None:
        self.explore.close()

    def config_dict(self) -> dict[str, Any]:
        """The explore env's :meth:`~sfw_gym.envs.explore.SfWExploreEnv.config_dict` plus this
        env's decisions (``goals``): ``gym.make(env_id, **config_dict())`` builds the same env."""
        name = self.config.prefix  # the kwarg that takes it: goals, regions
        assert name is not None
        return {**self.explore.config_dict(), name: self.config.to_dict()}

    def robot_view(self):
        """The explore env's :meth:`~sfw_gym.envs.explore.SfWExploreEnv.robot_view`."""
        return self.explore.robot_view()

    # -- helpers ---------------------------------------------------------------------------------
    def _action_index(self, action: Any) -> int:
        """``action`` as a candidate index, or a one-line error."""
        if self.menu is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        a = np.asarray(action)
        k = self.config.max_candidates
        if a.shape != () or a.dtype.kind not in "iu" or not 0 <= int(a) < k:
            raise ConfigError(f"goal action must be an integer in [0, {k}), got {action!r}")
        return int(a)

    def _decide(
        self, command: Callable[[RobotView], tuple[float, float] | None], invalid: bool
    ) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """Drive one decision, a ``command`` per env step until it returns None (or the
        episode ends); its reward in bits (see the module doc) ÷ ``reward_scale_bits``."""
        cfg = self.config
        start_path, start_steps = self.explore.path_length_m, self.explore.steps
        view = self.explore.robot_view()
        gain = 0.0
        while (next_command := command(view)) is not None:
            obs, _, terminated, truncated, info = self.explore.step(self._command(*next_command))
            gain += info["info_gain_bits"]
            view = self.explore.robot_view()
            if terminated or truncated:
                break
        metres = self.explore.path_length_m - start_path
        steps = self.explore.steps - start_steps
        bits = gain - cfg.cost_per_m_bits * metres - cfg.cost_per_step_bits * steps
        if terminated:
            bits += cfg.goal_bonus_bits
        info = dict(info, invalid_action=invalid, decision_steps=steps, decision_m=metres)
        return self._observe(obs), bits / cfg.reward_scale_bits, terminated, truncated, info

    def _observe(self, obs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        self.finder.set_step(self.explore.steps)
        self.menu, extra = menu_observation(
            self.finder, self.explore.robot_view(), self.config.max_candidates
        )
        return {**obs, **extra}

    def _command(self, linear: float, angular: float) -> Any:
        if self.explore.config.explore.action_type == "discrete":
            return to_discrete(linear, angular)
        return np.array([linear, angular], np.float32)


def menu_observation(
    finder: GoalFinder, view: Any, k: int
) -> tuple[CandidateGoals, dict[str, np.ndarray]]:
    """The menu of at most ``k`` candidates for ``view`` (one path search) and its observation
    entries: ``candidates`` (features / :data:`FEATURE_SCALES`, clipped; 0 for empty slots) and
    ``candidate_mask``."""
    paths = cost_field(finder.costs(view), view.cell, view.grid.resolution_m)
    menu = finder.find(view, paths, max_candidates=k)
    feats = np.zeros((k, len(FEATURES)), np.float32)
    scaled = np.nan_to_num(menu.features / _SCALES, nan=0.0, posinf=4.0, neginf=-1.0)
    feats[: len(menu)] = np.clip(scaled, -1.0, 4.0)
    mask = np.zeros(k, np.int8)
    mask[: len(menu)] = menu.valid
    return menu, {"candidates": feats, "candidate_mask": mask}


def action_masks(menu: CandidateGoals | None, k: int) -> np.ndarray:
    """Which of ``k`` actions pick a reachable candidate (all of them when none does: any
    action then turns in place)."""
    mask = np.zeros(k, np.bool_)
    if menu is not None:
        mask[: len(menu)] = menu.valid
    if not mask.any():
        mask[:] = True
    return mask

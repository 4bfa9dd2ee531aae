"""Region actions: ``SfW-ExploreRegions-v0`` (:class:`SfWRegionsEnv`), decisions that go
somewhere."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
from gymnasium import spaces

from sfw_gym.core.config import check, setting
from sfw_gym.envs.goals import GoalsConfig, SfWGoalsEnv
from sfw_gym.envs.observation import map_pixels
from sfw_gym.mapping import GridSpec
from sfw_gym.navigation.menu import CandidateGoals
from sfw_gym.navigation.regions import RegionSteering


@dataclass(frozen=True)
class RegionsConfig(GoalsConfig):
    """The goals env's menu and reward, plus how long a region decision lasts and how strongly
    the local steering keeps to the region."""

    prefix: ClassVar[str | None] = "regions"
    decision_steps: int = setting(20, ge=1, integer=True)
    anchor_cost_per_m: float = setting(1.0, ge=0.0)


class SfWRegionsEnv(SfWGoalsEnv):
    """``SfW-ExploreRegions-v0``: ``Discrete(K)`` region choices, ``decision_steps`` each.

    Description:
        An action picks one of K candidates of the navigation menu (as ``SfW-ExploreGoals-v0``'s
        do), but the candidate is a *region*, not a goal: for ``decision_steps`` env steps the
        classical local steering drives towards it and collects what lies along the way
        (:class:`~sfw_gym.navigation.regions.RegionSteering`: explore_lite's choice among
        frontier clusters, each lowered by its distance from the chosen candidate's target). 20
        steps a decision make ≤ 150 decisions in a 3,000-step episode, against ~1,600
        one-to-two-step decisions of the goals env, so a policy's credit assignment spans an
        episode. :meth:`teacher_action` is explore_lite's choice on the menu.

    Action Space:
        ``Discrete(K)``, K = ``max_candidates``. A masked action chooses no region: the local
        steering runs unanchored for the decision (``info["invalid_action"]``).

    Observation Space:
        The goals env's, plus ``candidate_px`` (each candidate's target on the ``map`` image,
        (row, col) ÷ ``map_px``), so a policy can read the whole map at each candidate; with
        ``privileged=True`` also ``true_map``, the ground-truth plan on the same image (0 wall,
        255 free, 127 outside).

    Args:
        regions: Overrides of :class:`RegionsConfig` (dict): the goals env's settings plus the
            decision's length and the steering's pull.
        privileged: Add the ground truth ``true_map`` to the observation (for training only:
            an asymmetric critic).
        render_mode: As the explore env's.
        **explore_kwargs: The explore env's keyword arguments.
    """

    config_class: ClassVar[type[GoalsConfig]] = RegionsConfig
    config: RegionsConfig

    def __init__(
        self,
        regions: dict[str, Any] | None = None,
        privileged: bool = False,
        render_mode: str | None = None,
        **explore_kwargs: Any,
    ) -> None:
        super().__init__(regions, render_mode=render_mode, **explore_kwargs)
        self.privileged = check("privileged", privileged, choices=(False, True))
        k, px = self.config.max_candidates, self.explore.config.explore.map_px
        extra: dict[str, spaces.Space] = {"candidate_px": spaces.Box(0.0, 1.0, (k, 2), np.float32)}
        if self.privileged:
            extra["true_map"] = spaces.Box(0, 255, (1, px, px), np.uint8)
        assert isinstance(self.observation_space, spaces.Dict)
        self.observation_space = spaces.Dict({**self.observation_space.spaces, **extra})
        self.steering = RegionSteering(self.finder, self.driver, self.config.anchor_cost_per_m)

    def config_dict(self) -> dict[str, Any]:
        """As the goals env's, with ``regions`` and ``privileged``."""
        return {**super().config_dict(), "privileged": self.privileged}

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        self.steering.reset()
        return super().reset(seed=seed, options=options)

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        assert self.menu is not None
        anchor = region_anchor(self.menu, self._action_index(action))
        self.steering.start(anchor, self.config.decision_steps)
        micro_before = self.steering.micro_decisions
        obs, reward, terminated, truncated, info = self._decide(
            lambda view: self.steering.command(view, self.explore.steps), anchor is None
        )
        info["micro_decisions"] = self.steering.micro_decisions - micro_before
        return obs, reward, terminated, truncated, info

    def _observe(self, obs: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        out = super()._observe(obs)
        assert self.menu is not None
        out["candidate_px"] = candidate_pixels(
            self.menu,
            self.explore.grid,
            self.config.max_candidates,
            self.explore.config.explore.map_px,
        )
        if self.privileged:
            truth = self.explore.ground_truth().truth_u8
            out["true_map"] = self.explore.obs_builder.image_of(truth)[None]
        return out


def region_anchor(menu: CandidateGoals, i: int) -> tuple[int, int] | None:
    """The cell a choice of candidate ``i`` steers towards (None: no valid candidate)."""
    if i >= len(menu) or not menu.valid[i]:
        return None
    return int(menu.target_rc[i, 0]), int(menu.target_rc[i, 1])


def candidate_pixels(menu: CandidateGoals, grid: GridSpec, k: int, map_px: int) -> np.ndarray:
    """The ``candidate_px`` observation entry: each of the ``k`` slots' target on the ``map``
    image (:func:`~sfw_gym.envs.observation.map_pixels`; 0 for empty slots)."""
    px = np.zeros((k, 2), np.float32)
    px[: len(menu)] = map_pixels(grid, map_px, menu.target_rc)
    return px

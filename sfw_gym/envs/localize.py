"""``SfW-Localize-v0`` (:class:`SfWLocalizeEnv`): find yourself on a known plan from WiFi
fingerprints (Miyagusuku et al.)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sfw_gym.core.config import Config, setting
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.episode import start_pose_in
from sfw_gym.envs.explore import SfWExploreEnv
from sfw_gym.localization import (
    MEANS,
    GaussianGridmaps,
    MclConfig,
    SignalModel,
    Survey,
    WifiMCL,
)
from sfw_gym.slam import relative_pose

#: The belief summary's spread is divided by this (and clipped to 1) in the observation.
SPREAD_SCALE_M = 10.0


@dataclass(frozen=True)
class LocalizeConfig(Config):
    """The survey, the signal model and the localiser."""

    prefix: ClassVar[str | None] = "localize"
    survey_spacing_m: float = setting(1.0, ge=0.1, le=10.0)
    per_ap: bool = setting(False, choices=(False, True))  # mGP: a model per AP, not one GP
    mean: str = setting("zero", choices=MEANS)  # the GP's mean: zero, or a path-loss curve
    resolution_m: float = setting(0.25, ge=0.05, le=10.0)  # of the gridmaps
    particles: int = setting(500, integer=True, ge=10, le=100_000)
    kidnap_step: int = setting(0, integer=True, ge=0)  # 0: never


class SfWLocalizeEnv(gym.Env):
    """``SfW-Localize-v0``: WiFi Monte-Carlo localisation on a known plan, from an unknown start.

    Description:
        At every reset the env surveys the plan (a fingerprint of the background access points
        every ``survey_spacing_m`` over the free space), fits a GP signal model to it and stores
        its Gaussian gridmaps; the robot then starts at a pose it does not know, and a WiFi
        Monte-Carlo localiser (:class:`~sfw_gym.localization.WifiMCL`) starts from its first
        fingerprint (Alg. 1). Each step the robot drives as in the explore env; the localiser
        takes the odometry increment and the new fingerprint. ``kidnap_step`` > 0 carries the
        robot to a random free pose at that step, unseen by its odometry, to test recovery.

    Observation Space:
        The explore env's plus ``belief`` (float32 (5,): the estimate's x, y scaled to [0, 1]
        over the plan, the sine and cosine of its heading, its spread / 10 m clipped to 1);
        ``info["loc_error_m"]`` (estimate to truth), ``info["loc_spread_m"]``,
        ``info["loc_estimate"]``, ``info["kidnapped"]``.

    Rewards:
        The fall of the localisation error bound (the particles' RMS spread, metres) this step.

    Starting State:
        The explore env's, with the survey's gridmaps built and the localiser's particles
        spread over the plan by the first fingerprint.

    Args:
        localize: Overrides of :class:`LocalizeConfig` (dict): the survey, the signal model and
            the localiser.
        render_mode: As the explore env's.
        **explore_kwargs: The explore env's keyword arguments (``n_background_aps`` ≥ 1
            needed).
    """

    metadata = SfWExploreEnv.metadata

    def __init__(
        self,
        localize: dict[str, Any] | None = None,
        render_mode: str | None = None,
        **explore_kwargs: Any,
    ) -> None:
        self.config = LocalizeConfig.from_dict(localize, "localize")
        explore_kwargs.setdefault("n_background_aps", 16)
        self.explore = SfWExploreEnv(render_mode=render_mode, **explore_kwargs)
        if not self.explore.config.explore.n_background_aps:
            raise ConfigError("SfW-Localize needs background access points: n_background_aps >= 1")
        self.render_mode = render_mode
        self.action_space = self.explore.action_space
        explore_space = self.explore.observation_space
        assert isinstance(explore_space, spaces.Dict)
        self.observation_space = spaces.Dict(
            {**explore_space.spaces, "belief": spaces.Box(-1.0, 1.0, (5,), np.float32)}
        )
        self.mcl: WifiMCL | None = None

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        super().reset(seed=seed)
        obs, info = self.explore.reset(seed=seed, options=options)
        truth = self.explore.ground_truth()
        self._bounds = truth.floorplan.bounds
        self.maps = self._survey_maps(truth)
        self.mcl = WifiMCL(self.maps, MclConfig(particles=self.config.particles), self.np_random)
        self.mcl.global_init(info["fingerprint"])
        self._odometry = info["odometry_pose"].copy()
        return self._observe(obs, info, kidnapped=False)

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        if self.mcl is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        kidnapped = self.explore.steps + 1 == self.config.kidnap_step
        if kidnapped:
            self._kidnap()
        obs, _, terminated, truncated, info = self.explore.step(action)
        odometry = info["odometry_pose"]
        self.mcl.predict(relative_pose(self._odometry, odometry))
        self._odometry = odometry.copy()
        self.mcl.update(info["fingerprint"])
        before = self._spread
        obs, info = self._observe(obs, info, kidnapped)
        return obs, before - self._spread, terminated, truncated, info

    def render(self) -> Any:
        return self.explore.render()

    def close(self) -> None:
        self.explore.close()

    def config_dict(self) -> dict[str, Any]:
        """The explore env's configuration plus ``localize``: ``gym.make(env_id,
        **config_dict())`` builds the same env."""
        return {**self.explore.config_dict(), "localize": self.config.to_dict()}

    def robot_view(self) -> Any:
        """The explore env's :meth:`~sfw_gym.envs.explore.SfWExploreEnv.robot_view` (for agents;
        its pose is the drifting odometry, not the localiser's estimate)."""
        return self.explore.robot_view()

    # -- helpers ---------------------------------------------------------------------------------
    def _survey_maps(self, truth: Any) -> GaussianGridmaps:
        """Fingerprints on a grid over the free space → the signal model → its gridmaps."""
        scene = self.explore.scene
        assert scene is not None and scene.background is not None
        x0, y0, x1, y1 = self._bounds
        step = self.config.survey_spacing_m
        gx, gy = np.meshgrid(np.arange(x0 + step / 2, x1, step), np.arange(y0 + step / 2, y1, step))
        points = np.column_stack([gx.ravel(), gy.ravel()])
        points = points[truth.floorplan.is_free(points)]
        readings = np.array([scene.background.measure(p) for p in points], np.float64)
        survey = Survey.from_dbm(points, readings)
        model = SignalModel(survey, per_ap=self.config.per_ap, mean=self.config.mean)
        return GaussianGridmaps.from_model(model, (x0, y0, x1, y1), self.config.resolution_m)

    def _kidnap(self) -> None:
        """Carry the robot to a random free pose; its odometry does not see the move."""
        scene = self.explore.scene
        assert scene is not None
        pose = start_pose_in(
            scene.floorplan,
            scene.truth_u8,
            scene.grid_origin,
            self.explore.config.explore.resolution_m,
            self.explore.config.robot.radius_m,
            None,
            self.np_random,
        )
        scene.robot.carry_to(pose)

    def _observe(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], kidnapped: bool
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        assert self.mcl is not None
        estimate, spread = self.mcl.estimate()
        self._spread = spread
        x0, y0, x1, y1 = self._bounds
        belief = np.array(
            [
                np.clip((estimate[0] - x0) / (x1 - x0), 0.0, 1.0),
                np.clip((estimate[1] - y0) / (y1 - y0), 0.0, 1.0),
                np.sin(estimate[2]),
                np.cos(estimate[2]),
                min(spread / SPREAD_SCALE_M, 1.0),
            ],
            np.float32,
        )
        info = dict(
            info,
            loc_error_m=float(np.hypot(*(estimate[:2] - info["true_pose"][:2]))),
            loc_spread_m=spread,
            loc_estimate=estimate,
            kidnapped=kidnapped,
        )
        return {**obs, "belief": belief}, info

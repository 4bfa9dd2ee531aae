"""SfW-Explore: map a building from WiFi RSSI alone, rewarded by the map's information gain."""

from __future__ import annotations

import dataclasses
import inspect
import math
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from sfw_gym.core.buffers import AppendOnlyArray
from sfw_gym.core.config import brief_repr, float_array, unknown_key_error
from sfw_gym.core.constants import DISCRETE_ACTION_NAMES, DISCRETE_ACTIONS, NOT_HEARD_DBM
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.config import RESET_OPTIONS, EnvConfig
from sfw_gym.envs.episode import EpisodeScene, GroundTruth, build_scene
from sfw_gym.envs.map_history import MapHistory
from sfw_gym.envs.map_tracker import MapTracker
from sfw_gym.envs.observation import (
    ObservationBuilder,
    fingerprint_observation,
    lidar_observation,
    observation_space,
)
from sfw_gym.mapping import GridSpec, SparseInverseKVisibility
from sfw_gym.navigation.view import RobotView
from sfw_gym.slam import OnlineRadioLidarSlam, OnlineRadioSlam
from sfw_gym.world import Floorplan, Pose
from sfw_gym.world.floorplan import PLAN_SUFFIXES, floorplan_files
from sfw_gym.world.lidar import Lidar


class SfWExploreEnv(gym.Env):
    """Active WiFi exploration: a robot maps walls from RSSI by sparse inverse k-visibility.

    Description:
        A differential-drive disc robot (pymunk) drives through an indoor floorplan. It has no
        camera and no LiDAR: each step it hears the RSSI of the WiFi routers (log-distance path
        loss, a loss per wall crossed, correlated shadowing, noise) and feels whether it bumped
        into a wall. From these and its odometry, a sparse inverse k-visibility mapper (Kim et
        al., arXiv:2408.07757) estimates how many walls separate it from each router and updates
        an occupancy belief map along the router–robot rays. The task: make that map complete
        and right, fast.

    Action Space:
        ``action_type="continuous"``: ``Box(-1, 1, (2,), float32)`` = (linear, angular) velocity
        as fractions of the robot's limits (0.5 m/s, 1.5 rad/s by default). Out-of-range values
        are clipped to [-1, 1]; NaN or inf raise ``ValueError``.
        ``action_type="discrete"``: ``Discrete(3)``: 0 forward, 1 turn left, 2 turn right (in
        place).

    Observation Space:
        A ``Dict`` that stable-baselines3's ``MultiInputPolicy`` takes as is:

        - ``map``: ``uint8 (3, M, M)``, M = ``map_px``: the belief map fitted to the image (0
          wall, 255 free, 127 unknown), the trajectory (128) with the robot (255), the routers
          (255);
        - ``local``: ``uint8 (1, C, C)``, C = ``crop_px``: the belief around the robot at full
          resolution (north up);
        - ``state``: ``float32 (2R + 6,)``: per router the normalised RSSI ((dBm + 100) / 80, 0
          when not heard) and a heard flag; bump; the pose estimate's x, y in [0, 1] over the
          map; sin and cos of its heading; the fraction of the map the robot believes known;
        - with ``n_background_aps`` > 0: ``fingerprint`` (each access point's normalised RSSI)
          and ``fingerprint_heard``; with a LiDAR: ``lidar`` (each beam's range ÷ its maximum).

    Rewards:
        ``reward_scale`` × the information gain of the map this step (bits; the entropy
        decrease of the belief), minus ``collision_penalty`` on a bump. With the defaults (0.01
        per bit, 0.1 m cells) the reward is about the square metres of map resolved.

    Starting State:
        A fresh procedural floorplan from the env's RNG each episode (or the ``floorplan``
        kwarg or option), the plan's own routers if it has them, else ``n_routers`` routers
        placed where a person would (k-means centres of the free space), the robot at a random
        free pose with clearance, the map unknown.

    Episode End:
        Terminated when the ground-truth coverage (fraction of free cells the map has
        classified) reaches ``coverage_target``. Truncated by the env itself after the
        episode's step budget (``info["max_steps"]``), so that the final ``info["summary"]``
        (episode metrics, steps to 50/90 % coverage) is always there: ``max_steps`` whatever
        the plan's size (the benchmark of how much a robot maps in a fixed time), or with
        ``steps_per_m2`` a budget that grows with the plan's free area, capped by
        ``max_steps``. ``gym.make(..., max_episode_steps=N)`` still works but truncates from
        outside, without the summary.

    Arguments:
        action_type: "continuous" (wheel velocities) or "discrete" (forward, left, right).
        floorplan: None: a procedural plan each episode; an int: that generator seed every
            episode; a path: a HouseExpo or sfw_gym JSON file or a ROS map YAML; a folder: one
            of its JSON files each episode.
        generator: Overrides of the procedural plans' `GeneratorConfig` (dict).
        n_routers: Routers the robot hears and maps from.
        radio_preset: The walls' losses: "default", "thick" or "residential" (per material).
        radio_band: "2.4" or "5" (GHz).
        radio: Overrides of `RadioConfig` (dict).
        robot: Overrides of `RobotConfig` (dict): size, speeds, odometry noise.
        mapper: Overrides of `MapperConfig` (dict).
        resolution_m: The map's cell size.
        map_px: Side of the ``map`` observation image.
        crop_px: Side of the ``local`` observation crop.
        coverage_target: Coverage that ends the episode.
        collision_penalty: Reward lost per bump.
        reward_scale: Reward per bit of information gain.
        max_steps: The step budget (its cap when ``steps_per_m2`` is set).
        steps_per_m2: None: the budget is ``max_steps``; a number: ``min(max_steps,
            ceil(steps_per_m2 × free area))``.
        n_background_aps: Access points beyond the routers, half in the building and half in
            its neighbourhood, whose RSSI the robot hears as a fingerprint
            (``obs["fingerprint"]``, ``obs["fingerprint_heard"]``, ``info["fingerprint"]``):
            Radio SLAM's input.
        pose_source: Where the robot believes it is, and so where it maps: "odometry";
            "radio_slam": odometry corrected by radio loop closures between background-AP
            fingerprints, solved every ``slam["solve_every"]`` steps, the map rebuilt along each
            correction; "radio_lidar": Radio+LiDAR SLAM, the same with LiDAR scan matching;
            "true": the true pose.
        slam: Overrides of `RadioSlamConfig` (dict); the odometry weights default to the
            robot's noise model.
        lidar: None: no LiDAR; a dict of `LidarConfig` overrides (``{}`` for the defaults): a
            simulated 2-D LiDAR, ``obs["lidar"]`` and ``info["lidar_ranges"]``.
        render_mode: None, "rgb_array" or "human".
        render_size: (width, height) of every frame, the plan letterboxed into it, so video
            writers work across plans; None: the plan's own size.

    ``reset(options=…)`` takes ``floorplan`` (a Floorplan, a path or a generator seed),
    ``routers`` (positions (R, 2) or a count ≤ ``n_routers``, over the plan's own) and
    ``start_pose`` ((x, y, θ)).
    """

    metadata: dict[str, Any] = {"render_modes": ["rgb_array", "human"], "render_fps": 10}  # noqa: RUF012

    def __init__(
        self,
        action_type: str = "continuous",
        floorplan: int | str | None = None,
        generator: dict[str, Any] | None = None,
        n_routers: int = 2,
        radio_preset: str = "default",
        radio_band: str = "2.4",
        radio: dict[str, Any] | None = None,
        robot: dict[str, Any] | None = None,
        mapper: dict[str, Any] | None = None,
        resolution_m: float = 0.1,
        map_px: int = 64,
        crop_px: int = 48,
        coverage_target: float = 0.95,
        collision_penalty: float = 0.1,
        reward_scale: float = 0.01,
        max_steps: int = 3000,
        steps_per_m2: float | None = None,
        n_background_aps: int = 0,
        pose_source: str = "odometry",
        slam: dict[str, Any] | None = None,
        lidar: dict[str, Any] | None = None,
        render_mode: str | None = None,
        render_size: tuple[int, int] | None = (960, 480),
        **unknown: Any,
    ) -> None:
        if unknown:
            params = inspect.signature(type(self)).parameters.values()
            valid = [p.name for p in params if p.kind is not p.VAR_KEYWORD]
            raise unknown_key_error("SfW-Explore kwargs", next(iter(unknown)), valid)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ConfigError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        self.config = EnvConfig.from_kwargs(
            action_type=action_type,
            floorplan=floorplan,
            generator=generator,
            n_routers=n_routers,
            radio_preset=radio_preset,
            radio_band=radio_band,
            radio=radio,
            robot=robot,
            mapper=mapper,
            resolution_m=resolution_m,
            map_px=map_px,
            crop_px=crop_px,
            coverage_target=coverage_target,
            collision_penalty=collision_penalty,
            reward_scale=reward_scale,
            max_steps=max_steps,
            steps_per_m2=steps_per_m2,
            n_background_aps=n_background_aps,
            pose_source=pose_source,
            slam=slam,
            lidar=lidar,
        )
        cfg = self.config.explore
        self.render_mode = render_mode
        self.render_size = _frame_size(render_size)
        self._folder_plans = _folder_plans(self.config.floorplan)
        lidar_beams = self.config.lidar.beams if self.config.lidar else 0
        self.observation_space = observation_space(
            cfg.n_routers, cfg.map_px, cfg.crop_px, cfg.n_background_aps, lidar_beams
        )
        if cfg.action_type == "continuous":
            self.action_space = spaces.Box(-1.0, 1.0, (2,), np.float32)
        else:
            self.action_space = spaces.Discrete(len(DISCRETE_ACTIONS))
        self.scene: EpisodeScene | None = None
        self._renderer: Any = None

    # ------------------------------------------------------------------------------ episode
    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Start an episode: floorplan, routers, start pose, an empty map (see the class doc)."""
        super().reset(seed=seed)
        options = dict(options or {})
        for key in options:
            if key not in RESET_OPTIONS:
                raise unknown_key_error("reset options", key, RESET_OPTIONS)
        plan = options.get("floorplan", self._default_floorplan())
        config = self.config
        explore = config.explore
        self.scene = build_scene(
            plan,
            routers=options.get("routers"),  # None: the plan's own, else n_routers by k-means
            max_routers=explore.n_routers,
            start_pose=options.get("start_pose"),
            radio_config=config.radio,
            robot_config=config.robot,
            resolution_m=explore.resolution_m,
            rng=self.np_random,
            generator_params=config.generator.to_dict(),
            n_background_aps=explore.n_background_aps,
        )
        s = self.scene
        self.grid = GridSpec(s.grid_origin, explore.resolution_m, s.truth_u8.shape)
        self._grid_bounds = self.grid.bounds
        self.mapper = SparseInverseKVisibility(self.grid, s.radio.routers, config.mapper)
        self.tracker = MapTracker(s.truth_u8)
        self.obs_builder = ObservationBuilder(
            self.grid, s.radio.routers, explore.n_routers, explore.map_px, explore.crop_px
        )
        self.episode_max_steps = explore.max_steps
        if explore.steps_per_m2 is not None:
            budget = math.ceil(explore.steps_per_m2 * s.floorplan.area_m2)
            self.episode_max_steps = max(1, min(explore.max_steps, budget))
        self.steps = 0
        self.path_length_m = 0.0
        self.collisions = 0
        self.k_correct = 0
        self.k_total = 0
        self.steps_to = {0.5: -1, 0.9: -1}
        self.rssi_history = AppendOnlyArray(len(s.radio.routers), np.int32)
        self._routers_view = np.array(s.radio.routers, np.float64)
        self._routers_view.flags.writeable = False
        self.true_path = AppendOnlyArray(2, np.float64)  # the true positions, one per reading
        self.odometry_trajectory = AppendOnlyArray(2, np.float64)  # of the pose estimate
        self.pose_estimates = AppendOnlyArray(3, np.float64)
        self.pose_estimate = s.robot.odometry_pose
        self._squared_pose_errors = 0.0
        self.lidar = None if config.lidar is None else Lidar(s.floorplan, config.lidar)
        self.slam: OnlineRadioSlam | None = None
        self.map_history: MapHistory | None = None
        if explore.pose_source == "radio_slam":
            self.slam = OnlineRadioSlam(config.slam)
        elif explore.pose_source == "radio_lidar":
            self.slam = OnlineRadioLidarSlam(config.slam)
        if self.slam is not None:
            self.map_history = MapHistory(config.slam.solve_every)
        self.last_gain_bits = 0.0
        self.last_rays: np.ndarray = np.zeros(0, np.int64)
        obs = self._sense_and_map(bumped=False)
        return obs, self._info(terminal=False)

    def step(self, action: Any) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """Drive for one control period, hear the routers, update the map, reward the gain."""
        if self.scene is None:
            raise gym.error.ResetNeeded("call reset() before step()")
        linear, angular = self._command(action)
        result = self.scene.robot.step(linear, angular)
        self.steps += 1
        self.path_length_m += result.distance_m
        self.collisions += int(result.bumped)
        obs = self._sense_and_map(bumped=result.bumped)
        paid = self.config.reward
        reward = paid.reward_scale * self.last_gain_bits - paid.collision_penalty * result.bumped
        metrics = self.tracker.metrics()
        coverage = metrics["coverage"]
        for level in self.steps_to:
            if self.steps_to[level] < 0 and coverage >= level:
                self.steps_to[level] = self.steps
        terminated = coverage >= paid.coverage_target
        truncated = not terminated and self.steps >= self.episode_max_steps
        info = self._info(terminal=terminated or truncated, metrics=metrics)
        if self.render_mode == "human":
            self.render()
        return obs, float(reward), terminated, truncated, info

    def _default_floorplan(self) -> Floorplan | int | str:
        source = self.config.floorplan
        if self._folder_plans:
            return str(self._folder_plans[int(self.np_random.integers(len(self._folder_plans)))])
        if source is None:
            return int(self.np_random.integers(2**31 - 1))
        return source

    def _command(self, action: Any) -> tuple[float, float]:
        cfg = self.config.robot
        if self.config.explore.action_type == "discrete":
            try:
                a = np.asarray(action)
            except (TypeError, ValueError):  # ragged lists
                a = np.asarray(None)
            if a.shape != () or a.dtype.kind not in "iu" or not 0 <= int(a) < len(DISCRETE_ACTIONS):
                raise ConfigError(
                    f"action must be an integer in [0, {len(DISCRETE_ACTIONS)}) "
                    f"({', '.join(DISCRETE_ACTION_NAMES)}), got {brief_repr(action)}"
                )
            lin, ang = DISCRETE_ACTIONS[int(a)]
        else:
            if type(action) is np.ndarray and action.shape == (2,) and action.dtype.kind == "f":
                lin, ang = action.tolist()  # the usual action, without a conversion
            else:
                a = float_array("action", action)
                if a.shape != (2,):
                    raise ConfigError(
                        f"action must have shape (2,) = (linear, angular), got shape {a.shape}: "
                        f"{brief_repr(action)}"
                    )
                lin, ang = a.tolist()
            if not (math.isfinite(lin) and math.isfinite(ang)):
                raise ConfigError(f"action must be finite, got {[lin, ang]}")
            lin, ang = min(max(lin, -1.0), 1.0), min(max(ang, -1.0), 1.0)
        return float(lin) * cfg.max_linear_speed_m_s, float(ang) * cfg.max_angular_speed_rad_s

    def _sense_and_map(self, *, bumped: bool) -> dict[str, np.ndarray]:
        s = self.scene
        assert s is not None
        true_pose = s.robot.pose
        rssi, true_k = s.radio.measure_at(true_pose.x, true_pose.y)
        if s.background is not None:  # the fingerprint of the access points beyond the routers
            reading, _ = s.background.measure_at(true_pose.x, true_pose.y)
            self.fingerprint = reading.astype(np.float64)
        if self.lidar is not None:
            self.lidar_ranges = self.lidar.scan(true_pose, self.np_random)
        entropy_before = self.mapper.entropy_bits
        pose = self._estimate_pose(true_pose)
        self.pose_estimate = pose
        self.rssi_history.append(rssi)
        self.true_path.append((true_pose.x, true_pose.y))
        self.odometry_trajectory.append(pose[:2])
        self.pose_estimates.append(pose)
        self._squared_pose_errors += (pose[0] - true_pose.x) ** 2 + (pose[1] - true_pose.y) ** 2
        if self.map_history is not None:
            self.map_history.record(len(self.true_path) - 1, self.mapper, bumped)
        updated, self.last_gain_bits = self._map_at(pose, rssi, bumped)
        readings = rssi.tolist()  # dBm per router, as plain numbers
        if updated:
            # k = K means "K or more walls" (sfw_gym.mapping.metrics.k_value_accuracy with max_k)
            max_k = self.config.mapper.max_k
            for dbm, est, true in zip(
                readings, self.mapper.last_k.tolist(), true_k.tolist(), strict=True
            ):
                if dbm > NOT_HEARD_DBM and est >= 0:  # a few routers: plain Python is quickest
                    self.k_total += 1
                    self.k_correct += est == min(true, max_k)
        if self.slam is not None:  # a replay moved the entropy too: the gain is the difference
            self.last_gain_bits = entropy_before - self.mapper.entropy_bits
        self.obs_builder.mark_visited(pose[0], pose[1])
        # the observation has a slot per router of the env; an episode may use fewer
        rssi_slots = readings + [NOT_HEARD_DBM] * (self.config.explore.n_routers - len(readings))
        obs = self.obs_builder.build(
            self.mapper.occupancy_u8, rssi_slots, bumped, pose, self.tracker.known_fraction
        )
        if s.background is not None:
            obs.update(fingerprint_observation(self.fingerprint))
        if self.lidar is not None:
            obs["lidar"] = lidar_observation(self.lidar_ranges, self.lidar.config.max_range_m)
        return obs

    def _estimate_pose(self, true_pose: Pose) -> Pose:
        """This step's pose estimate from the env's pose source (Radio SLAM: after a solve that
        moved past poses, the map is rebuilt along them first)."""
        assert self.scene is not None
        if self.config.explore.pose_source == "true":
            return true_pose
        odometry = self.scene.robot.odometry_pose
        if self.slam is None:
            return odometry
        scan = None if self.lidar is None else self.lidar.points((0, 0, 0), self.lidar_ranges)
        moved_from = self.slam.add(odometry, self.fingerprint, scan)
        if moved_from is not None:
            self._remap(self.slam.estimate()[:-1], moved_from)
        return Pose(*self.slam.latest().tolist())

    def _map_at(self, pose: Pose, rssi: np.ndarray, bumped: bool) -> tuple[bool, float]:
        """Fuse a reading at ``pose``: whether it was fused, and the information gain (bits).
        Nothing is fused where the estimate lies off the map (odometry drifted out of it)."""
        x0, y0, x1, y1 = self._grid_bounds
        if not (x0 <= pose[0] < x1 and y0 <= pose[1] < y1):
            return False, 0.0
        gain = self.mapper.update(
            pose[:2], rssi.astype(np.float64), bumped=bumped, heading_rad=pose[2]
        )
        self.tracker.apply(self.mapper.last_changed_cells, self.mapper.occupancy_u8)
        return True, gain

    def _remap(self, poses: np.ndarray, first: int) -> None:
        """Rebuild the map along corrected ``poses`` of the steps so far, from the last mapper
        snapshot at or before step ``first`` (the earliest pose that moved); the poses before
        that snapshot stay as the map has them."""
        assert self.map_history is not None and self.scene is not None
        self.mapper, start = self.map_history.restore(first)
        rssi, bumps = self.rssi_history.view, self.map_history.bumps
        x0, y0, x1, y1 = self._grid_bounds
        for t in range(start, len(poses)):
            self.map_history.snapshot(t, self.mapper)
            x, y, theta = poses[t]
            if x0 <= x < x1 and y0 <= y < y1:
                self.mapper.update((x, y), rssi[t].astype(np.float64), bumps[t], theta)
        self.tracker.apply(np.arange(self.mapper.occupancy_u8.size), self.mapper.occupancy_u8)
        kept = self.pose_estimates.view[:start]
        self.pose_estimates = AppendOnlyArray(3, np.float64, len(poses) + 1024)
        self.odometry_trajectory = AppendOnlyArray(2, np.float64, len(poses) + 1024)
        self.obs_builder.clear_visited()
        for x, y, theta in np.concatenate([kept, poses[start:]]).tolist():
            self.pose_estimates.append((x, y, theta))
            self.odometry_trajectory.append((x, y))
            self.obs_builder.mark_visited(x, y)
        errors = self.pose_estimates.view[:, :2] - self.true_path.view
        self._squared_pose_errors = float(np.sum(errors**2))

    def _info(self, *, terminal: bool, metrics: dict[str, float] | None = None) -> dict[str, Any]:
        s = self.scene
        assert s is not None
        t = self.tracker
        info: dict[str, Any] = {
            **(metrics or t.metrics()),
            "k_accuracy": self.k_correct / self.k_total if self.k_total else 0.0,
            "path_length_m": self.path_length_m,
            "collisions": self.collisions,
            "true_pose": np.array(s.robot.pose, np.float64),
            "odometry_pose": np.array(s.robot.odometry_pose, np.float64),
            "pose_estimate": np.array(self.pose_estimate, np.float64),  # where it maps
            "pose_error_m": math.dist(self.pose_estimate[:2], s.robot.pose[:2]),
            "ate_m": math.sqrt(self._squared_pose_errors / len(self.true_path)),
            "entropy_bits": self.mapper.entropy_bits,
            "info_gain_bits": self.last_gain_bits,
            "steps_to_coverage_50": self.steps_to[0.5],
            "steps_to_coverage_90": self.steps_to[0.9],
            "floorplan": s.floorplan.name,
            "max_steps": self.episode_max_steps,
        }
        if s.background is not None:  # dBm per background AP, NaN where not heard
            info["fingerprint"] = np.where(
                self.fingerprint > NOT_HEARD_DBM, self.fingerprint, np.nan
            )
        if self.lidar is not None:  # metres per beam, inf where nothing returned
            info["lidar_ranges"] = self.lidar_ranges.copy()
        if terminal:
            info["summary"] = {k: v for k, v in info.items() if np.isscalar(v)} | {
                "steps": self.steps,
                "map_mse": t.map_mse(self.mapper.occupancy_u8),
            }
        return info

    @property
    def trajectory(self) -> np.ndarray:
        """The true positions so far, ``(n, 2)``, one per reading (a read-only view)."""
        return self.true_path.view

    def set_max_steps(self, max_steps: int) -> None:
        """The step budget (``max_steps``) of the episodes that start from the next reset on:
        a training curriculum's stage (``sfw_gym.rl.training``); the running episode keeps its."""
        explore = dataclasses.replace(self.config.explore, max_steps=max_steps)
        self.config = dataclasses.replace(self.config, explore=explore)

    # ------------------------------------------------------------------------------ robot's view
    def robot_view(self) -> RobotView:
        """What the robot knows, for agents and planners: never the ground truth.

        O(1): the arrays are read-only views of the env's own, valid until the next ``step`` or
        ``reset`` (copy what you keep).
        """
        s = self.scene
        if s is None:
            raise gym.error.ResetNeeded("call reset() before robot_view()")
        cfg = self.config.robot
        odom_x, odom_y, odom_theta = self.pose_estimate
        return RobotView(
            belief_u8=self.mapper.occupancy_u8,
            log_odds=self.mapper.log_odds,
            grid=self.grid,
            odometry_pose=(float(odom_x), float(odom_y), float(odom_theta)),
            routers_xy=self._routers_view,
            rssi_history=self.rssi_history.view,
            odometry_trajectory=self.odometry_trajectory.view,
            bumped=bool(s.robot.bumped),
            radius_m=cfg.radius_m,
            max_linear_speed_m_s=cfg.max_linear_speed_m_s,
            max_angular_speed_rad_s=cfg.max_angular_speed_rad_s,
            control_period_s=cfg.control_period_s,
            action_type=self.config.explore.action_type,
            mapper_state=self.mapper.state(),
        )

    def ground_truth(self) -> GroundTruth:
        """The episode's ground truth, for evaluation and figures (never for agents)."""
        s = self.scene
        if s is None:
            raise gym.error.ResetNeeded("call reset() before ground_truth()")
        return GroundTruth(
            floorplan=s.floorplan,
            truth_u8=s.truth_u8,
            grid=self.grid,
            radio=s.radio,
            trajectory=self.true_path.view.copy(),
            pose=(float(s.robot.pose[0]), float(s.robot.pose[1]), float(s.robot.pose[2])),
        )

    # ------------------------------------------------------------------------------ rendering
    def render(self) -> np.ndarray | None:
        """``rgb_array``: an (H, W, 3) uint8 picture, ground truth left, belief right.
        ``human``: the same picture in a matplotlib window."""
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode to gym.make")
            return None
        if self.scene is None:
            raise gym.error.ResetNeeded("call reset() before render()")
        from sfw_gym.envs.rendering import draw_frame, show_frame

        s = self.scene
        frame = draw_frame(
            truth_u8=s.truth_u8,
            belief_u8=self.mapper.occupancy_u8,
            grid=self.grid,
            routers_xy=s.radio.routers,
            pose=s.robot.pose,
            odometry_pose=self.pose_estimate,
            trajectory=self.trajectory,
            odometry_trajectory=self.odometry_trajectory.view,
            robot_radius_m=self.config.robot.radius_m,
            size=self.render_size,
        )
        if self.render_mode == "human":
            self._renderer = show_frame(frame, self._renderer, self.metadata["render_fps"])
            return None
        return frame

    def close(self) -> None:
        """Close the human-mode window, if any."""
        if self._renderer is not None:
            from sfw_gym.envs.rendering import close_window

            close_window(self._renderer)
            self._renderer = None

    def config_dict(self) -> dict[str, Any]:
        """The effective configuration as the env's kwargs (JSON-serialisable): for logs and
        reproducibility, ``gym.make(env_id, **config_dict())`` builds the same env."""
        return self.config.to_kwargs()


def unwrap_sfw(env: gym.Env) -> SfWExploreEnv:
    """The SfW-Explore env under ``env``'s wrappers (a ConfigError if there is none)."""
    base = env.unwrapped
    if not isinstance(base, SfWExploreEnv):
        raise ConfigError(f"expected an SfW-Explore env, got {type(base).__name__}")
    return base


def _frame_size(size: Any) -> tuple[int, int] | None:
    if size is None:
        return None
    if (
        not isinstance(size, (tuple, list))
        or len(size) != 2
        or not all(isinstance(v, (int, np.integer)) and 16 <= v <= 8192 for v in size)
    ):
        raise ConfigError(
            f"render_size must be None or (width, height) in [16, 8192] px, got {size!r}"
        )
    return int(size[0]), int(size[1])


def _folder_plans(source: Any) -> list[Path]:
    if isinstance(source, str | Path) and Path(source).is_dir():
        plans = floorplan_files(source)
        if not plans:
            suffixes = ", ".join(PLAN_SUFFIXES)
            raise ConfigError(f"floorplan folder {source} holds no plan file ({suffixes})")
        return plans
    return []


__all__ = ["DISCRETE_ACTION_NAMES", "SfWExploreEnv", "unwrap_sfw"]

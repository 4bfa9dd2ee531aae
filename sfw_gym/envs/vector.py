"""A native vector env: N SfW envs stepped in this process, behind ``gym.make_vec``.

``gym.make_vec("SfW-Explore-v0", num_envs=N)`` builds it (every id registers it as its
``vector_entry_point``; ``vectorization_mode="sync"`` or ``"async"`` still give Gymnasium's).
Each sub-env is the single env with its seed, bit for bit. Autoreset is Gymnasium 1.x's
``NEXT_STEP``: the step after an episode ends resets that sub-env and returns its first
observation with reward 0. There is no process boundary and no per-step deep copy.

Sub-envs of `SfWExploreEnv` (odometry or true poses, no LiDAR, no background access points) step
together through `sfw_gym.envs.batch_step`: the robots' contact-free motion in one compiled call,
the readings, map updates, metrics and observations of all of them in another. Other env classes
step one by one in Python, as do resets, a robot's step with a wall contact (pymunk) and the
info of an episode's last step.
"""

from __future__ import annotations

import pickle
from functools import partial
from typing import Any, cast

import gymnasium as gym
import numpy as np
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space, create_empty_array, iterate
from gymnasium.wrappers import TimeLimit

from sfw_gym.core.constants import DISCRETE_ACTIONS
from sfw_gym.core.errors import ConfigError, SfwGymError
from sfw_gym.envs import batch_step
from sfw_gym.envs.batch_step import BatchStepper


class SfWVectorEnv(VectorEnv):
    """``num_envs`` envs of ``env_class`` (built with ``kwargs``), stepped in this process.

    Args:
        env_class: The single env's class, or its ``"module:Class"`` entry point.
        num_envs: How many sub-envs.
        max_episode_steps: Truncate each sub-env's episodes from outside (``TimeLimit``), as
            ``gym.make`` does; None: the env's own step budget.
        **kwargs: The single env's keyword arguments (``render_mode`` included).

    Raises:
        ConfigError: ``num_envs`` < 1, or a sub-env's bad action or option (naming the sub-env).
    """

    def __init__(
        self,
        env_class: type[gym.Env] | str,
        num_envs: int = 1,
        max_episode_steps: int | None = None,
        **kwargs: Any,
    ) -> None:
        make: Any = env_class
        if isinstance(env_class, str):
            from gymnasium.envs.registration import load_env_creator

            make = load_env_creator(env_class)
        if not isinstance(num_envs, int | np.integer) or num_envs < 1:
            raise ConfigError(f"num_envs must be an int >= 1, got {num_envs!r}")
        self.num_envs = int(num_envs)
        self._envs: list[gym.Env] = []
        for _ in range(self.num_envs):
            env = make(**kwargs)
            self._envs.append(
                env if max_episode_steps is None else TimeLimit(env, max_episode_steps)
            )
        first = self._envs[0]
        self.metadata = {**first.metadata, "autoreset_mode": AutoresetMode.NEXT_STEP}
        self.render_mode = first.render_mode
        self.single_observation_space = first.observation_space
        self.single_action_space = first.action_space
        self.observation_space = batch_space(self.single_observation_space, self.num_envs)
        self.action_space = batch_space(self.single_action_space, self.num_envs)
        self._observations: dict[str, np.ndarray] = self._empty_batch(np.zeros)
        self._layout = [(k, v.shape, v.dtype) for k, v in self._observations.items()]
        self._rewards = np.zeros(self.num_envs, np.float64)
        self._terminations = np.zeros(self.num_envs, np.bool_)
        self._truncations = np.zeros(self.num_envs, np.bool_)
        self._autoreset = np.zeros(self.num_envs, np.bool_)
        self._stepper = BatchStepper(self.num_envs)
        self._batched = all(_batches(env) for env in self._envs)
        self._plan_names = np.full(self.num_envs, None, dtype=object)
        self._can_batch = np.zeros(self.num_envs, np.bool_)  # this episode steps together
        if self._batched:  # an action's fractions of the robot's speed limits
            limits = cast(Any, first).config.robot
            self._speeds = np.array([limits.max_linear_speed_m_s, limits.max_angular_speed_rad_s])

    @property
    def envs(self) -> list[gym.Env]:
        """The sub-envs, their state up to date."""
        self._sync_all()
        return self._envs

    def reset(
        self, *, seed: int | list[int | None] | None = None, options: dict[str, Any] | None = None
    ) -> tuple[Any, dict[str, Any]]:
        """Reset every sub-env (``options["reset_mask"]``: those marked), sub-env ``i`` with
        ``seed + i`` (an int), ``seed[i]`` (a list) or its own generator (None)."""
        if seed is None or isinstance(seed, int | np.integer):
            seeds = [None if seed is None else int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ConfigError(f"seed must give {self.num_envs} seeds, got {len(seeds)}")
        options = dict(options or {})
        mask = np.asarray(options.pop("reset_mask", np.ones(self.num_envs, np.bool_)))
        if mask.shape != (self.num_envs,) or mask.dtype != np.bool_ or not mask.any():
            raise ConfigError(
                f"reset_mask must be {self.num_envs} booleans, at least one True, got {mask!r}"
            )
        # rows not reset keep their observation; a copy, so that a batch handed out stays as it was
        self._observations = {key: rows.copy() for key, rows in self._observations.items()}
        infos: list[dict[str, Any] | None] = [None] * self.num_envs
        for i in np.flatnonzero(mask).tolist():
            obs, infos[i] = self._sub(i, "reset", seed=seeds[i], options=options or None)
            self._write(i, obs)
        self._autoreset[mask] = False
        return self._batch(), batch_infos(infos)

    def step(self, actions: Any) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, dict[str, Any]]:
        """Step every sub-env with its action; a sub-env whose episode ended last step is reset
        instead (its action ignored, reward 0)."""
        n = len(actions) if hasattr(actions, "__len__") else -1
        if n != self.num_envs:
            raise ConfigError(
                f"actions must hold one action per sub-env ({self.num_envs}), got {n}"
            )
        self._observations = self._empty_batch()  # every row is written below
        infos: list[dict[str, Any] | None] = [None] * self.num_envs
        if self._batched:
            together = self._step_together(actions, infos)
        else:
            together = np.zeros(self.num_envs, np.bool_)
        one_by_one = np.flatnonzero(~together).tolist()
        rows = list(iterate(self.action_space, actions)) if one_by_one else []
        for i in one_by_one:
            action = rows[i]
            if self._autoreset[i]:
                obs, infos[i] = self._sub(i, "reset")
                reward, terminated, truncated = 0.0, False, False
            else:
                obs, reward, terminated, truncated, infos[i] = self._sub(i, "step", action)
            self._write(i, obs)
            self._rewards[i] = reward
            self._terminations[i] = terminated
            self._truncations[i] = truncated
        self._autoreset = self._terminations | self._truncations
        if together.any():
            batched = self._stepper.infos(self._plan_names)
            info = _merge_rows(batched, infos)
        else:
            info = batch_infos(infos)
        return (
            self._batch(),
            self._rewards.copy(),
            self._terminations.copy(),
            self._truncations.copy(),
            info,
        )

    def _step_together(self, actions: Any, infos: list[dict[str, Any] | None]) -> np.ndarray:
        """Step the sub-envs that can go through `batch_step` (not resetting, on a plan whose
        robot pymunk does not hold in part); returns which did. The last step of an episode
        gets its info (with the summary) from the env."""
        stepper, envs = self._stepper, cast(list[Any], self._envs)
        can = ~self._autoreset & self._can_batch
        active = np.flatnonzero(can)
        if not len(active):
            return can
        commands = self._commands(actions, active)
        stepper.make_room(active, envs)
        moved = batch_step.move_robots(
            active, commands, stepper.state, stepper.consts, stepper.parts
        )
        if not moved.all():
            for n in np.flatnonzero(~moved).tolist():  # a contact: pymunk moves the robot
                i = int(active[n])
                robot = envs[i].scene.robot
                stepper.sync(i, envs[i])
                v, w = commands[n].tolist()
                result = self._call(i, robot.step, v, w)
                stepper.load_robot(i, robot, result.distance_m)
        stepper.draw_ahead(active)
        done = np.zeros(len(active), np.int8)
        due = np.zeros(len(active), np.bool_)
        obs = self._observations
        anything = batch_step.sense_and_map(
            active, moved, stepper.state, stepper.consts, stepper.parts, obs["map"],
            obs["local"], obs["state"], self._rewards, self._terminations, self._truncations,
            stepper.synced, stepper.info_rows, done, due,
        )  # fmt: skip
        if anything:
            self._after_together(active, done, due, infos)
        return can

    def _after_together(
        self,
        active: np.ndarray,
        done: np.ndarray,
        due: np.ndarray,
        infos: list[dict[str, Any] | None],
    ) -> None:
        """The rarer ends of a batched step: k-means refits, the pose off the grid, the last
        step of an episode (its info, with the summary, from the env)."""
        envs: list[Any] = self._envs
        for i in active[due].tolist():
            envs[i].mapper.k_estimator.refit()
        if (done < 0).any():
            i = int(active[np.flatnonzero(done < 0)[0]])
            raise ConfigError(f"sub-env {i}: the pose estimate lies outside the map's grid")
        for i in active[done > 0].tolist():
            self._stepper.sync(i, envs[i])
            row = self._stepper.info_rows[i, : len(batch_step.METRICS)].tolist()
            metrics = dict(zip(batch_step.METRICS, row, strict=True))
            infos[i] = envs[i]._info(terminal=True, metrics=metrics)

    def _commands(self, actions: Any, active: np.ndarray) -> np.ndarray:
        """The ``active`` sub-envs' (linear, angular) commands, a row each, as
        `SfWExploreEnv._command` makes them (an unusual action goes through it, its error
        naming the sub-env)."""
        env: Any = self._envs[0]
        a = actions if isinstance(actions, np.ndarray) else np.asarray(actions, dtype=object)
        chosen = a if len(active) == self.num_envs else a[active]
        if env.config.explore.action_type == "discrete":
            if a.dtype.kind in "iu" and a.shape == (self.num_envs,):
                if ((chosen >= 0) & (chosen < len(DISCRETE_ACTIONS))).all():
                    return _DISCRETE_FRACTIONS[chosen] * self._speeds
        elif a.dtype.kind == "f" and a.shape == (self.num_envs, 2):
            fractions = chosen.astype(np.float64)
            if np.isfinite(fractions).all():
                return np.clip(fractions, -1.0, 1.0) * self._speeds
        rows = list(iterate(self.action_space, actions))
        envs: list[Any] = self._envs
        return np.array([self._call(i, envs[i]._command, rows[i]) for i in active.tolist()])

    def render(self) -> tuple[Any, ...] | None:
        """Each sub-env's frame (``render_mode="rgb_array"``)."""
        return tuple(env.render() for env in self.envs)

    def call(self, name: str, *args: Any, **kwargs: Any) -> tuple[Any, ...]:
        """Each sub-env's ``name(*args, **kwargs)`` (or attribute ``name``)."""
        out = []
        for env in self.envs:
            attr = env.get_wrapper_attr(name)
            out.append(attr(*args, **kwargs) if callable(attr) else attr)
        self._load_all()  # a call may change a sub-env
        return tuple(out)

    def get_attr(self, name: str) -> tuple[Any, ...]:
        """Each sub-env's attribute ``name``."""
        return tuple(env.get_wrapper_attr(name) for env in self.envs)

    def set_attr(self, name: str, values: list[Any] | tuple[Any, ...] | Any) -> None:
        """Set attribute ``name`` of each sub-env (one value each, or one for all)."""
        if not isinstance(values, list | tuple):
            values = [values] * self.num_envs
        for env, value in zip(self.envs, values, strict=True):
            env.set_wrapper_attr(name, value)
        self._load_all()

    def snapshot(self, i: int) -> bytes:
        """Sub-env ``i``'s whole state (its wrappers, the env, its generator) as bytes."""
        self._stepper.sync(i, self._envs[i])
        return pickle.dumps(self._envs[i])

    def restore(self, i: int, blob: bytes) -> None:
        """Put back a sub-env state from :meth:`snapshot` as sub-env ``i``."""
        env: Any = pickle.loads(blob)
        self._envs[i] = env
        self._autoreset[i] = False
        self._load(i, env)

    def close_extras(self, **kwargs: Any) -> None:
        for env in self.envs:
            env.close()

    def _sub(self, i: int, method: str, *args: Any, **kwargs: Any) -> Any:
        """Sub-env ``i``'s ``method`` (its state synced before and read after)."""
        env = self._envs[i]
        if not self._batched:
            return self._call(i, getattr(env, method), *args, **kwargs)
        self._stepper.sync(i, env)
        out = self._call(i, getattr(env, method), *args, **kwargs)
        self._load(i, env)
        return out

    def _load(self, i: int, env: Any) -> None:
        """Read sub-env ``i`` into the batched state, if this episode steps there."""
        self._can_batch[i] = self._batched and _episode_batches(env)
        if self._can_batch[i]:
            self._stepper.load(i, env)
            self._plan_names[i] = env.scene.floorplan.name

    @staticmethod
    def _call(i: int, fn: Any, *args: Any, **kwargs: Any) -> Any:
        """``fn(*args, **kwargs)`` of sub-env ``i``: its errors name the sub-env."""
        try:
            return fn(*args, **kwargs)
        except SfwGymError as exc:
            raise type(exc)(f"sub-env {i}: {exc}") from exc

    def _sync_all(self) -> None:
        if self._batched:
            for i, env in enumerate(self._envs):
                self._stepper.sync(i, env)

    def _load_all(self) -> None:
        for i, env in enumerate(self._envs):
            self._load(i, env)

    def _empty_batch(self, fn: Any = np.empty) -> dict[str, np.ndarray]:
        if fn is np.empty:  # every step: the layout found once
            return {key: np.empty(shape, dtype) for key, shape, dtype in self._layout}
        return create_empty_array(self.single_observation_space, self.num_envs, fn=fn)  # type: ignore[return-value]

    def _write(self, i: int, obs: dict[str, np.ndarray]) -> None:
        for key, value in obs.items():
            self._observations[key][i] = value

    def _batch(self) -> dict[str, np.ndarray]:
        """The observations as the caller keeps them: never written again (a step writes a
        new batch, a reset a copy)."""
        return dict(self._observations)


_DISCRETE_FRACTIONS = np.array(DISCRETE_ACTIONS, np.float64)


def _batches(env: gym.Env) -> bool:
    """Whether ``env`` (a sub-env, as built) can step through `batch_step`."""
    from sfw_gym.envs.explore import SfWExploreEnv

    if type(env) is not SfWExploreEnv:  # a wrapper, or another env class
        return False
    cfg = env.config
    return (
        cfg.explore.pose_source in ("odometry", "true")
        and cfg.lidar is None
        and cfg.explore.n_background_aps == 0
        and env.render_mode != "human"
    )


def _episode_batches(env: Any) -> bool:
    """Whether this episode can: reset, on a plan whose walls pymunk holds all at once."""
    if env.scene is None:
        return False
    robot = env.scene.robot
    return robot._active_walls is None and (robot._rng is env.scene.radio.rng or not robot._noisy)


def _merge_rows(batched: dict[str, Any], infos: list[dict[str, Any] | None]) -> dict[str, Any]:
    """``batched`` (every sub-env's info arrays) with the rows of the sub-envs that gave an
    info dict replaced by it; keys only those have (the summary) batched after."""
    extras: list[dict[str, Any] | None] = [None] * len(infos)
    for i, info in enumerate(infos):
        if info is None:
            continue
        rest = {}
        for key, value in info.items():
            if key in batched:
                batched[key][i] = value
            else:
                rest[key] = value
        extras[i] = rest or None
    return batched | batch_infos(extras)


def batch_infos(infos: list[dict[str, Any] | None]) -> dict[str, Any]:
    """The sub-envs' infos (None: that sub-env gave none) batched as Gymnasium's vector envs
    batch them (``VectorEnv._add_info``, applied env by env): per key an array over the
    sub-envs (typed by the first value; nested dicts recursively; anything else as objects)
    and a ``_key`` mask of the sub-envs that have it. Key by key rather than env by env: the
    same dict, without rebuilding a mask per key per sub-env."""
    n = len(infos)
    out: dict[str, Any] = {}
    keys = dict.fromkeys(key for info in infos if info for key in info)
    for key in keys:
        have = [i for i, info in enumerate(infos) if info is not None and key in info]
        first = infos[have[0]][key]  # type: ignore[index]
        array: Any
        if key != "final_obs" and isinstance(first, dict):
            array = batch_infos([info[key] if i in have else None for i, info in enumerate(infos)])  # type: ignore[index]
        else:
            if key == "final_obs":
                array = np.full(n, None, dtype=object)
            elif type(first) in (int, float, bool) or isinstance(first, np.number):
                array = np.zeros(n, dtype=type(first))
            elif isinstance(first, np.ndarray):
                array = np.zeros((n, *first.shape), dtype=first.dtype)
            else:
                array = np.full(n, None, dtype=object)
            for i in have:
                array[i] = infos[i][key]  # type: ignore[index]
        mask = np.zeros(n, dtype=np.bool_)
        mask[have] = True
        out[key], out[f"_{key}"] = array, mask
    return out


#: ``vector_entry_point`` of each env class (see ``sfw_gym.envs.register_envs``).
explore_vector_env = partial(SfWVectorEnv, "sfw_gym.envs.explore:SfWExploreEnv")
goals_vector_env = partial(SfWVectorEnv, "sfw_gym.envs.goals:SfWGoalsEnv")
regions_vector_env = partial(SfWVectorEnv, "sfw_gym.envs.regions:SfWRegionsEnv")
localize_vector_env = partial(SfWVectorEnv, "sfw_gym.envs.localize:SfWLocalizeEnv")

"""A trained PPO policy (stable-baselines3) behind the agents' interface.

The shipped policy picks waypoints (:class:`sfw_gym.envs.waypoint.WaypointWrapper`): every few
steps it looks at the observation and names a block of the map; the agent then drives there
step by step with the wrapper's own :class:`~sfw_gym.navigation.waypoints.WaypointDriver`, so it
acts exactly as in training. Policies trained on the env's own continuous actions are driven
directly.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from sfw_gym.agents.base import Agent, RobotView
from sfw_gym.core.data import DEFAULT_WAYPOINT_MODEL_DIR
from sfw_gym.core.errors import ConfigError
from sfw_gym.navigation.waypoints import WaypointDriver, block_features
from sfw_gym.rl.agent import LearnedAgentSettings, with_model_path
from sfw_gym.rl.runs import find_model
from sfw_gym.rl.training import wrapper_specs

WAYPOINT_WRAPPER = "sfw_gym.envs.waypoint.WaypointWrapper"


@functools.lru_cache(maxsize=4)
def _load_model(path: str, device: str) -> Any:
    import torch
    from stable_baselines3 import PPO

    # One env's forward pass is tiny: threads only fight the evaluation's other workers.
    torch.set_num_threads(1)
    return PPO.load(path, device=device)


def waypoint_settings(config: dict[str, Any]) -> dict[str, int] | None:
    """The WaypointWrapper's kwargs from a training ``config.yml`` (``{}``: its defaults), or
    None if the policy was trained without it."""
    for name, kwargs in wrapper_specs(config.get("hyperparameters", {}).get("env_wrapper")):
        if name == WAYPOINT_WRAPPER:
            return dict(kwargs)
    return None


@dataclass(frozen=True)
class WaypointPPOSettings(LearnedAgentSettings):
    """:class:`WaypointPPOAgent`'s parameters: by default the shipped waypoint policy."""

    path: str = str(DEFAULT_WAYPOINT_MODEL_DIR)


class WaypointPPOAgent(Agent):
    """Acts with a PPO model trained by ``sfw-gym train ppo`` (by default the shipped one).

    Its parameters are :class:`WaypointPPOSettings`' fields, given as keyword arguments.

    Args:
        path: A training output folder holding the model (``<env-id>.zip``, or ``model.zip``
            of an older run) and ``config.yml``, or that ``.zip``; by default the shipped
            policy.
        deterministic: Take the policy's most likely waypoint (or mean action), the default, so
            that an episode is a function of the env seed alone; else sample it from the policy
            as in training, with the agent's generator seeded in :meth:`reset` (never torch's
            global one), so that it is a function of the env and agent seeds. The shipped
            waypoint policy explores far better sampled (docs/results/history.md: coverage 0.446 vs
            0.148):
            its most likely waypoint can be one it cannot reach, which it then names again and
            again (nothing in the observation changes); sampling moves on.
        device: Torch device of the policy (``"cpu"`` is plenty for one env).
        max_steps: Optional step limit of the agent.
    """

    name = "waypoint-ppo"

    settings_class = WaypointPPOSettings
    settings: WaypointPPOSettings

    def __init__(self, path: str | Path | None = None, **params: Any) -> None:
        super().__init__(**with_model_path(path, params))
        path, device = self.settings.path, self.settings.device
        folder = Path(path).parent if Path(path).suffix == ".zip" else Path(path)
        config_path = folder / "config.yml"
        hint = f"train one with `sfw-gym train ppo --out {folder}` or pass path="
        if not config_path.is_file():
            raise ConfigError(f"{type(self).__name__}: {config_path} not found; {hint}")
        try:
            model_path = Path(path) if Path(path).suffix == ".zip" else find_model(folder)
        except ConfigError as exc:
            raise ConfigError(f"{type(self).__name__}: {exc}; {hint}") from None
        if not model_path.is_file():
            raise ConfigError(f"{type(self).__name__}: {model_path} not found; {hint}")
        try:
            config = yaml.safe_load(config_path.read_text(encoding="utf-8")) or {}
        except yaml.YAMLError as exc:
            raise ConfigError(
                f"{type(self).__name__}: {config_path}: not valid YAML ({exc})"
            ) from None
        self.waypoints = waypoint_settings(config)
        self._check_policy_kind(folder, config)
        self.model = _load_model(str(model_path), device)
        if self.waypoints is None:
            self.action_types = ("continuous",)  # type: ignore[misc]  # this model's only

    def _check_policy_kind(self, folder: Path, config: dict[str, Any]) -> None:
        """Refuse a model this agent cannot drive, from its run's ``config`` (any SB3 PPO model
        is fine here)."""

    def _distribution(self, obs: dict[str, np.ndarray]) -> Any:
        """The policy's action distribution for ``obs`` (a ``torch.distributions`` object)."""
        import torch

        policy = self.model.policy
        with torch.no_grad():
            tensor, _ = policy.obs_to_tensor(obs)
            return policy.get_distribution(tensor).distribution

    def _choose(self, obs: dict[str, np.ndarray]) -> int:
        """The policy's waypoint for ``obs``: its mode, or a sample drawn with ``self.rng``."""
        probs = self._distribution(obs).probs[0].cpu().numpy()
        if self.settings.deterministic:
            return int(np.argmax(probs))
        probs = probs.astype(np.float64)
        return int(self.rng.choice(len(probs), p=probs / probs.sum()))

    def _sample_action(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        """A continuous action sampled from the policy's Gaussian for ``obs`` with ``self.rng``
        (SB3's ``predict(deterministic=False)`` would draw from torch's global generator, which
        neither the env seed nor the agent seed controls)."""
        import torch

        dist = self._distribution(obs)
        if not isinstance(dist, torch.distributions.Normal):
            raise ConfigError(
                f"{type(self).__name__}: cannot sample the {type(dist).__name__} actions of "
                f"{self.settings.path} with the agent's generator; use deterministic=True"
            )
        mean = dist.loc[0].cpu().numpy().astype(np.float64)
        std = dist.scale[0].cpu().numpy().astype(np.float64)
        action = mean + std * self.rng.standard_normal(mean.shape)
        return np.tanh(action) if getattr(self.model.policy, "squash_output", False) else action

    def _on_reset(self, view: RobotView) -> None:
        if self.waypoints is not None:
            self.driver = WaypointDriver(**self.waypoints)
        self.goals: list[tuple[float, float]] = []
        self._obs_checked = False

    def _check_obs(self, obs: Any) -> None:
        """The env's observations must be those the policy was trained on."""
        trained = self.model.observation_space.spaces
        differ = {
            k: v.shape
            for k, v in trained.items()
            if k != "blocks" and np.shape(obs.get(k)) != v.shape
        }
        if differ:
            got = {k: np.shape(obs.get(k)) for k in differ}
            raise ConfigError(
                f"{type(self).__name__}: the policy in {self.settings.path} was trained on "
                f"observations {differ}; this env gives {got} (map_px, crop_px and n_routers "
                "must match)"
            )
        self._obs_checked = True

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        if not isinstance(obs, dict):
            raise ConfigError("WaypointPPOAgent.act(obs) needs the env's (Dict) observation")
        if not self._obs_checked:
            self._check_obs(obs)
        trained = self.model.observation_space.spaces  # extra keys (fingerprint, lidar) unused
        obs = {k: v for k, v in obs.items() if k in trained}
        if self.waypoints is None:
            action = (  # the Gaussian's mean, or a draw from it with self.rng
                self.model.predict(obs, deterministic=True)[0]
                if self.settings.deterministic
                else self._sample_action(obs)
            )
            linear, angular = np.clip(np.asarray(action, np.float64).ravel()[:2], -1.0, 1.0)
            return float(linear), float(angular)
        command = self.driver.command(view.odometry_pose, view.bumped)
        if command is None:  # the waypoint is over: the policy names the next one
            if "blocks" in self.model.observation_space.spaces:  # as WaypointWrapper adds it
                blocks = block_features(
                    view.belief_u8, view.grid, view.odometry_pose, self.driver.grid_cells
                )
                obs = {**obs, "blocks": blocks}
            self.driver.start(view, self._choose(obs))
            self.goals.append((float(self.driver.goal[0]), float(self.driver.goal[1])))
            command = self.driver.command(view.odometry_pose, False)
        return command if command is not None else (0.0, 0.0)

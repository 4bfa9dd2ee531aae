"""The learned menu explorers behind the agents' interface, on the explore env itself.

``regions-ppo`` (:class:`RegionsPPOAgent`, the shipped learned explorer): a model trained on
``SfW-ExploreRegions-v0`` picks a region every 20 steps and the classical steering drives, as
:class:`~sfw_gym.agents.regions.RegionAgent` does. ``goals-ppo`` (:class:`PPOAgent`): a model
trained on ``SfW-ExploreGoals-v0`` picks a candidate goal at a time, driven by the same
:class:`~sfw_gym.navigation.goal_driver.GoalDriver` as in that env. Both act exactly as in
training and run through ``sfw-gym evaluate`` beside the classical agents (``--agents
frontier,regions-ppo``; a model of one's own with ``--agent-params '{"regions-ppo": {"path":
"runs/regions"}}'``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from sfw_gym.agents.base import Agent, AgentSettings, RobotView
from sfw_gym.agents.regions import RegionAgent
from sfw_gym.core.config import setting
from sfw_gym.core.data import DEFAULT_MODEL_DIR, DEFAULT_REGIONS_MODEL_DIR
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.goals import GoalsConfig, action_masks, menu_observation
from sfw_gym.envs.regions import RegionsConfig, candidate_pixels
from sfw_gym.navigation.candidates import GoalFinder
from sfw_gym.navigation.goal_driver import GoalDriver
from sfw_gym.navigation.menu import CandidateGoals
from sfw_gym.rl.runs import find_model


@dataclass(frozen=True)
class LearnedAgentSettings(AgentSettings):
    """The parameters of an agent that acts with a trained model.

    Attributes:
        path: A training output folder holding the model, or the ``.zip`` (a ``Path`` works too).
        deterministic: Take the policy's most likely action (the default); else sample it with
            the agent's seeded generator.
        device: Torch device of the policy.
    """

    path: str = ""
    deterministic: bool = setting(True, choices=(True, False))
    device: str = "cpu"

    def validate(self) -> None:
        object.__setattr__(self, "path", str(self.path))


def with_model_path(path: str | Path | None, params: dict[str, Any]) -> dict[str, Any]:
    """A learned agent's parameters with the model ``path`` given positionally
    (``PPOAgent("runs/mine")``) folded in."""
    return params if path is None else {**params, "path": path}


@dataclass(frozen=True)
class MaskedPPOSettings(LearnedAgentSettings):
    """A MaskablePPO agent's parameters (:class:`PPOAgent`, :class:`RegionsPPOAgent`).

    Attributes:
        num_threads: PyTorch's CPU threads, set for the process (None: leave them): one is
            fastest for this small network, several contend for the cores with the envs (a
            decision took 5× longer with two threads on a busy 2-core machine).
    """

    path: str = str(DEFAULT_MODEL_DIR)
    num_threads: int | None = setting(1, integer=True, ge=1, optional=True)


@dataclass(frozen=True)
class RegionsPPOSettings(MaskedPPOSettings):
    """:class:`RegionsPPOAgent`'s parameters: by default the shipped region model."""

    path: str = str(DEFAULT_REGIONS_MODEL_DIR)


class PPOAgent(Agent):
    """Acts with a MaskablePPO model over candidate goals (``goals-ppo``: the learned explorer
    before the region one, which is now ``regions-ppo``).

    Its parameters are :class:`MaskedPPOSettings`' fields, given as keyword arguments.

    Args:
        path: A ``sfw-gym train ppo_mask`` output folder (``<env-id>.zip`` or an older run's
            ``model.zip``, ``config.yml``) or a ``.zip`` in it or in its ``checkpoints``; by
            default the shipped model.
        deterministic: Take the policy's most likely candidate (the default); else sample it
            with the agent's seeded generator.
        device: Torch device of the policy.
        num_threads: PyTorch's CPU threads, set for the process (None: leave them): one is
            fastest for this small network, several contend for the cores with the envs (a
            decision took 5× longer with two threads on a busy 2-core machine).
        max_steps: Optional step limit of the agent.
    """

    name = "goals-ppo"
    settings_class = MaskedPPOSettings
    settings: MaskedPPOSettings

    def __init__(self, path: str | Path | None = None, **params: Any) -> None:
        super().__init__(**with_model_path(path, params))
        s = self.settings
        self.model, config = load_model(s.path, s.device, s.num_threads)
        goals = (config.get("env_kwargs") or {}).get("goals")
        self.config = GoalsConfig.from_dict(goals, "goals")
        # a policy trained without masks (an ablation) chooses among all candidates
        self.use_masking = bool((config.get("hyperparameters") or {}).get("use_masking", True))

    def _on_reset(self, view: RobotView) -> None:
        self.finder = GoalFinder()
        self.finder.reset(view)
        self.driver = GoalDriver(self.finder, self.config.max_steps_per_goal)
        self.driver.reset()
        self.n_decisions = 0

    def _act(self, view: RobotView, obs: Any) -> tuple[float, float]:
        if not isinstance(obs, dict):
            raise ConfigError("PPOAgent.act(obs) needs the env's (Dict) observation")
        command = self.driver.command(view) if self.n_decisions else None
        if command is None:  # the decision is over: the policy picks the next goal
            self.finder.set_step(self.steps)
            k = self.config.max_candidates
            menu, extra = menu_observation(self.finder, view, k)
            mask = action_masks(menu, k) if self.use_masking else np.ones(k, np.bool_)
            choice = self._choose({**obs, **extra}, mask)
            if choice < len(menu) and menu.valid[choice]:  # else the driver turns in place
                self._log_decision(menu, choice)
            self.driver.start(view, menu, choice)
            self.n_decisions += 1
            command = self.driver.command(view)
        return command if command is not None else (0.0, 1.0)

    def _choose(self, obs: dict[str, np.ndarray], mask: np.ndarray) -> int:
        import torch

        from sfw_gym.rl.goal_policy import GoalsInputs, GoalsPolicy

        policy = self.model.policy
        if self.settings.deterministic and isinstance(policy, GoalsPolicy):
            # the most likely valid candidate: the actor's logits straight, without SB3's
            # predict() (its tensors, checks and distribution cost 1.2 ms a decision)
            with torch.no_grad():
                x = {
                    k: torch.as_tensor(obs[k], dtype=torch.float32)[None] for k in GoalsInputs.keys
                }
                features = policy.extract_features(x)
                logits = policy.heads.forward_actor(features)[0].numpy()  # type: ignore[arg-type]
            return int(np.argmax(np.where(mask, logits, -np.inf)))
        if self.settings.deterministic:
            action, _ = self.model.predict(obs, action_masks=mask, deterministic=True)
            return int(action)
        with torch.no_grad():
            tensor, _ = policy.obs_to_tensor(obs)
            dist = policy.get_distribution(tensor, action_masks=mask[None])
            probs = dist.distribution.probs[0].cpu().numpy().astype(np.float64)
        return int(self.rng.choice(len(probs), p=probs / probs.sum()))


def load_model(
    path: str | Path, device: str = "cpu", num_threads: int | None = 1
) -> tuple[Any, dict[str, Any]]:
    """A MaskablePPO model (fine-tuned ones load the same way) and its run's ``config.yml``
    (empty if none) from a ``sfw-gym train ppo_mask`` output folder (its model found as
    :mod:`sfw_gym.rl.runs` says), or a ``.zip`` in it or in its ``checkpoints``;
    ``num_threads``: PyTorch's CPU threads, set for the process."""
    import torch
    from sb3_contrib import MaskablePPO

    if num_threads is not None:
        torch.set_num_threads(num_threads)
    given = Path(path)
    folder = given.parent if given.suffix == ".zip" else given
    hint = (
        f"train one with `sfw-gym train ppo_mask --env SfW-ExploreRegions-v0 --out {folder}` "
        "(or SfW-ExploreGoals-v0)"
    )
    try:
        model_path = given if given.suffix == ".zip" else find_model(folder)
    except ConfigError as exc:
        raise ConfigError(f"{exc}; {hint}") from None
    # a checkpoint (OUT/checkpoints/ppo_mask_<steps>_steps.zip): the run's config is above it
    config_path = next(
        (p for p in (folder / "config.yml", folder.parent / "config.yml") if p.is_file()), None
    )
    if not model_path.is_file():
        raise ConfigError(f"{model_path} not found; {hint}")
    config: dict[str, Any] = {}
    if config_path is not None:
        config = yaml.safe_load(config_path.read_text(encoding="utf-8")) or {}
    return MaskablePPO.load(str(model_path), device=device), config


class RegionsPPOAgent(RegionAgent):
    """Acts with a model trained on ``SfW-ExploreRegions-v0`` (``sfw-gym train ppo_mask --env
    SfW-ExploreRegions-v0``): every ``decision_steps`` steps the policy picks a region of the
    candidate menu from the whole map (its actor reads no ground truth), and the classical
    steering drives towards it, exactly as in the env.

    Its parameters are :class:`RegionsPPOSettings`' fields, given as keyword arguments.

    Args:
        path: A training output folder or a ``.zip`` in it or in its ``checkpoints``; by
            default the shipped region model.
        deterministic: Take the most likely region (the default); else sample it with the
            agent's seeded generator.
        device: Torch device of the policy.
        num_threads: PyTorch's CPU threads, set for the process (None: leave them).
        max_steps: Optional step limit of the agent.
    """

    name = "regions-ppo"
    settings_class = RegionsPPOSettings  # type: ignore[assignment]  # the regions: the model's
    settings: RegionsPPOSettings  # type: ignore[assignment]

    def __init__(self, path: str | Path | None = None, **params: Any) -> None:
        Agent.__init__(self, **with_model_path(path, params))
        s = self.settings
        self.model, config = load_model(s.path, s.device, s.num_threads)
        regions = (config.get("env_kwargs") or {}).get("regions")
        self.config = RegionsConfig.from_dict(regions, "regions")

    def choose(
        self, view: RobotView, obs: Any, menu: CandidateGoals, extra: dict[str, np.ndarray]
    ) -> int:
        import torch

        if not isinstance(obs, dict):
            raise ConfigError(f"{type(self).__name__}.act(obs) needs the env's (Dict) observation")
        policy = self.model.policy
        k = self.config.max_candidates
        px = candidate_pixels(menu, view.grid, k, obs["map"].shape[-1])
        full = {**obs, **extra, "candidate_px": px}
        with torch.no_grad():
            x = {key: torch.as_tensor(full[key])[None] for key in policy.actor_keys}
            logits = policy.actor_logits(x)[0].numpy().astype(np.float64)
        logits = np.where(action_masks(menu, k), logits, -np.inf)
        if self.settings.deterministic:
            return int(np.argmax(logits))
        probs = np.exp(logits - logits.max())
        return int(self.rng.choice(k, p=probs / probs.sum()))

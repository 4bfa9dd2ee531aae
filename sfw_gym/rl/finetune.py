"""Fine-tuning a behaviour-cloned MaskablePPO policy without forgetting it (PIRLNav, kickstarting).

:class:`AnchoredMaskablePPO` is MaskablePPO with three guards for a policy that starts from
behaviour cloning: a critic warm-up (the first updates move only the critic, so the actor is not
pushed around by a critic that knows nothing yet), a linear ramp of the actor's learning rate
after it, and a decaying ``KL(anchor || policy)`` penalty towards a frozen copy of the cloned
policy (:meth:`~AnchoredMaskablePPO.set_anchor`). The policy must say which parameters are the
actor's and which the critic's (``parameter_groups()``, as
:class:`~sfw_gym.rl.goal_policy.GoalsPolicy` and :class:`~sfw_gym.rl.region_policy.RegionsPolicy`
do); a parameter in both, or in neither, counts as the actor's (it moves only when the actor may).

The anchor is saved in the model's zip as a pickled ``state_dict`` in SB3's data (not as a torch
``state_dict`` entry), so a plain ``MaskablePPO.load`` still reads the file.
"""

from __future__ import annotations

import copy
import io
import logging
import pathlib
from collections import defaultdict
from collections.abc import Iterable
from typing import Any

import numpy as np
import torch
from gymnasium import spaces
from sb3_contrib import MaskablePPO
from sb3_contrib.common.maskable.distributions import MaskableCategorical, MaskableDistribution
from sb3_contrib.common.maskable.policies import MaskableActorCriticPolicy
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.utils import explained_variance
from torch import nn
from torch.nn import functional as F

logger = logging.getLogger(__name__)

#: Keys under which :meth:`AnchoredMaskablePPO.train` keeps the anchor's distribution of each
#: rollout sample beside its observation (a leading underscore: no observation is named so).
ANCHOR_PROBS, ANCHOR_LOGITS = "_anchor_probs", "_anchor_logits"


def _categoricals(dist: MaskableDistribution) -> list[MaskableCategorical]:
    """The categorical distribution(s) behind a (multi-)categorical maskable distribution."""
    several = getattr(dist, "distributions", None)
    return list(several) if several is not None else [dist.distribution]  # type: ignore[list-item]


def masked_kl(anchor: MaskableDistribution, current: MaskableDistribution) -> torch.Tensor:
    """``KL(anchor || current)`` per sample; masked actions (probability 0) add nothing."""
    total: torch.Tensor | None = None
    for p, q in zip(_categoricals(anchor), _categoricals(current), strict=True):
        terms = torch.where(p.probs > 0, p.probs * (p.logits - q.logits), 0.0).sum(-1)
        total = terms if total is None else total + terms
    assert total is not None
    return total


def kl_from_anchor_rows(
    probs: torch.Tensor, logits: torch.Tensor, current: MaskableDistribution
) -> torch.Tensor:
    """:func:`masked_kl` with the anchor given by its (masked, normalised) ``probs`` and
    ``logits`` rows, as :meth:`AnchoredMaskablePPO.anchor_rows` keeps them."""
    (q,) = _categoricals(current)
    return torch.where(probs > 0, probs * (logits - q.logits), 0.0).sum(-1)


def frozen_copy(policy: MaskableActorCriticPolicy) -> MaskableActorCriticPolicy:
    """A deep copy of ``policy`` in eval mode whose parameters need no gradient."""
    anchor = copy.deepcopy(policy)
    anchor.set_training_mode(False)
    anchor.requires_grad_(False)
    return anchor


class AnchoredMaskablePPO(MaskablePPO):
    """MaskablePPO with a critic warm-up, an actor learning-rate ramp and a KL anchor.

    :param critic_warmup_updates: the first this many updates (``train()`` calls) move only the
        critic: the actor gets no gradient step at all.
    :param actor_warmup_updates: then the actor's learning rate ramps linearly up to the full
        rate over this many updates (``1/N, 2/N, ..., 1`` of it).
    :param kl_coef: weight of ``KL(anchor || policy)`` (masked distributions, on each
        minibatch's observations) in the loss; needs :meth:`set_anchor`.
    :param kl_half_life_updates: the weight halves every this many updates after the critic
        warm-up.
    Other arguments are MaskablePPO's.
    """

    def __init__(
        self,
        policy: str | type[MaskableActorCriticPolicy],
        env: Any,
        critic_warmup_updates: int = 0,
        actor_warmup_updates: int = 0,
        kl_coef: float = 0.0,
        kl_half_life_updates: float = 10.0,
        **kwargs: Any,
    ) -> None:
        if critic_warmup_updates < 0 or actor_warmup_updates < 0:
            raise ValueError("warm-up lengths must be >= 0")
        if kl_coef < 0 or kl_half_life_updates <= 0:
            raise ValueError("kl_coef must be >= 0 and kl_half_life_updates > 0")
        self.critic_warmup_updates = int(critic_warmup_updates)
        self.actor_warmup_updates = int(actor_warmup_updates)
        self.kl_coef = float(kl_coef)
        self.kl_half_life_updates = float(kl_half_life_updates)
        #: ``train()`` calls so far (saved with the model, so warm-ups resume where they were).
        self.n_train_calls = 0
        #: The frozen policy the KL term pulls towards (:meth:`set_anchor`).
        self.anchor: MaskableActorCriticPolicy | None = None
        self._anchor_state: bytes | None = None  # the anchor's state_dict, only while saving
        super().__init__(policy, env, **kwargs)

    # --- the anchor and its saving --------------------------------------------------------

    def set_anchor(self) -> None:
        """Freeze a copy of the current policy as the anchor (call it after behaviour cloning)."""
        self.anchor = frozen_copy(self.policy)

    def _setup_model(self) -> None:
        super()._setup_model()
        if (self.critic_warmup_updates or self.actor_warmup_updates) and not hasattr(
            self.policy, "parameter_groups"
        ):
            raise TypeError(
                f"{type(self.policy).__name__} has no parameter_groups(): warm-ups need the "
                "actor's and the critic's parameters"
            )
        self.anchor = None
        if self._anchor_state is not None:  # AnchoredMaskablePPO.load: restore the saved one
            self.anchor = frozen_copy(self.policy)
            state = torch.load(
                io.BytesIO(self._anchor_state), map_location=self.device, weights_only=True
            )
            self.anchor.load_state_dict(state)
            self._anchor_state = None

    def _excluded_save_params(self) -> list[str]:
        return [*super()._excluded_save_params(), "anchor"]

    def save(
        self,
        path: str | pathlib.Path | io.BufferedIOBase,
        exclude: Iterable[str] | None = None,
        include: Iterable[str] | None = None,
    ) -> None:
        """SB3's save, with the anchor's ``state_dict`` among the pickled data."""
        if self.anchor is not None:
            buffer = io.BytesIO()
            torch.save(self.anchor.state_dict(), buffer)
            self._anchor_state = buffer.getvalue()
        try:
            super().save(path, exclude, include)
        finally:
            self._anchor_state = None

    def _setup_learn(self, *args: Any, **kwargs: Any) -> tuple[int, BaseCallback]:
        if self.kl_coef > 0 and self.anchor is None:
            raise ValueError("kl_coef > 0 needs an anchor: call set_anchor() first")
        return super()._setup_learn(*args, **kwargs)

    # --- schedules ---------------------------------------------------------------------------

    @property
    def n_updates(self) -> int:
        """SB3's count of gradient epochs (``train/n_updates``)."""
        return self._n_updates

    def actor_lr_scale(self, call: int | None = None) -> float:
        """The actor's share of the learning rate at ``train()`` call ``call`` (the next one)."""
        u = (self.n_train_calls if call is None else call) - self.critic_warmup_updates
        if u < 0:
            return 0.0
        if self.actor_warmup_updates > 0:
            return min(1.0, (u + 1) / self.actor_warmup_updates)
        return 1.0

    def kl_weight(self, call: int | None = None) -> float:
        """The KL term's weight at ``train()`` call ``call`` (the next one)."""
        u = (self.n_train_calls if call is None else call) - self.critic_warmup_updates
        return self.kl_coef * 0.5 ** (max(u, 0) / self.kl_half_life_updates)

    def kl_to_anchor(
        self, obs: dict[str, np.ndarray], action_masks: np.ndarray | None = None
    ) -> torch.Tensor:
        """``KL(anchor || policy)`` for each observation of a batch (numpy, as from a VecEnv)."""
        if self.anchor is None:
            raise ValueError("no anchor: call set_anchor() first")
        tensor_obs, _ = self.policy.obs_to_tensor(obs)
        with torch.no_grad():
            anchor = self.anchor.get_distribution(tensor_obs, action_masks=action_masks)
            current = self.policy.get_distribution(tensor_obs, action_masks=action_masks)
            return masked_kl(anchor, current)

    def _actor_parameters(self) -> list[nn.Parameter]:
        """The policy's parameters that move only when the actor may: all but the critic's."""
        groups = self.policy.parameter_groups()  # type: ignore[operator]
        actor = {id(p) for p in groups["actor"]}
        critic_only = {id(p) for p in groups["critic"]} - actor
        return [p for p in self.policy.parameters() if id(p) not in critic_only]

    # --- the update ----------------------------------------------------------------------------

    def _cache_anchor_rows(self) -> bool:
        """Put the anchor's masked distribution of every rollout sample into the rollout
        buffer's observations (:data:`ANCHOR_PROBS`, :data:`ANCHOR_LOGITS`), so that each
        minibatch carries its rows: the frozen anchor runs once per rollout instead of once per
        epoch. Its outputs do not depend on which samples share a batch (the policies here
        compute each sample alone: tested), so the KL term is the same. False (nothing cached):
        no anchor, a dict-less buffer, several categoricals, or a buffer already flattened."""
        buffer: Any = self.rollout_buffer
        if (
            self.anchor is None
            or not isinstance(buffer.observations, dict)
            or buffer.generator_ready
            or not isinstance(self.action_space, spaces.Discrete)
        ):
            return False
        n_steps, n_envs = buffer.buffer_size, buffer.n_envs
        flat, size = n_steps * n_envs, self.batch_size or n_steps * n_envs
        # (step, env) order: reshaped back below, swapped and flattened by buffer.get as the rest
        rows = {
            key: value.reshape(flat, *value.shape[2:]) for key, value in buffer.observations.items()
        }
        all_masks = buffer.action_masks.reshape(flat, -1)
        probs, logits = [], []
        with torch.no_grad():
            for start in range(0, flat, size):
                obs = {
                    key: buffer.to_torch(value[start : start + size]) for key, value in rows.items()
                }
                masks: Any = buffer.to_torch(all_masks[start : start + size])  # a tensor: fine
                dist = self.anchor.get_distribution(obs, action_masks=masks)
                (p,) = _categoricals(dist)
                probs.append(p.probs.cpu().numpy())
                logits.append(p.logits.cpu().numpy())
        buffer.observations[ANCHOR_PROBS] = np.concatenate(probs).reshape(n_steps, n_envs, -1)
        buffer.observations[ANCHOR_LOGITS] = np.concatenate(logits).reshape(n_steps, n_envs, -1)
        return True

    def train(self) -> None:
        """One PPO update (clipped surrogate, value loss, entropy, target-KL early stop), plus
        the anchor's KL; the actor's steps are scaled by :meth:`actor_lr_scale`."""
        policy = self.policy
        policy.set_training_mode(True)
        self._update_learning_rate(policy.optimizer)
        progress = self._current_progress_remaining
        lr = float(self.lr_schedule(progress))
        clip_range = float(self.clip_range(progress))  # type: ignore[operator]
        clip_range_vf = (
            None if self.clip_range_vf is None else float(self.clip_range_vf(progress))  # type: ignore[operator]
        )
        actor_scale, kl_weight = self.actor_lr_scale(), self.kl_weight()
        if kl_weight > 0 and self.anchor is None:
            raise ValueError("kl_coef > 0 needs an anchor: call set_anchor() first")
        actor = self._actor_parameters() if actor_scale < 1.0 else []

        cached = self._cache_anchor_rows()
        stats: dict[str, list[float]] = defaultdict(list)
        approx_kls: list[float] = []
        loss = torch.zeros(())
        continue_training = True
        for epoch in range(self.n_epochs):
            approx_kls = []
            for batch in self.rollout_buffer.get(self.batch_size):
                observations = batch.observations
                anchor_rows = None
                if cached:  # the anchor's rows of this minibatch, left out of the policy's input
                    assert isinstance(observations, dict)
                    observations = dict(observations)
                    anchor_rows = observations.pop(ANCHOR_PROBS), observations.pop(ANCHOR_LOGITS)
                actions = batch.actions
                if isinstance(self.action_space, spaces.Discrete):
                    actions = actions.long().flatten()
                masks: Any = batch.action_masks  # a tensor: apply_masking takes it too
                dist = policy.get_distribution(observations, action_masks=masks)
                values = policy.predict_values(observations).flatten()
                log_prob = dist.log_prob(actions)
                entropy = dist.entropy()

                advantages = batch.advantages
                if self.normalize_advantage and len(advantages) > 1:
                    advantages = (advantages - advantages.mean()) / (advantages.std() + 1e-8)
                ratio = torch.exp(log_prob - batch.old_log_prob)
                clipped = torch.clamp(ratio, 1 - clip_range, 1 + clip_range)
                policy_loss = -torch.min(advantages * ratio, advantages * clipped).mean()

                if clip_range_vf is not None:
                    values = batch.old_values + torch.clamp(
                        values - batch.old_values, -clip_range_vf, clip_range_vf
                    )
                value_loss = F.mse_loss(batch.returns, values)
                entropy_loss = -entropy.mean() if entropy is not None else log_prob.mean()

                if actor_scale > 0:
                    loss = policy_loss + self.ent_coef * entropy_loss + self.vf_coef * value_loss
                else:  # critic warm-up
                    loss = self.vf_coef * value_loss
                if self.anchor is not None:
                    if anchor_rows is not None:
                        kl = kl_from_anchor_rows(*anchor_rows, dist).mean()
                    else:
                        with torch.no_grad():
                            anchor_dist = self.anchor.get_distribution(
                                observations, action_masks=masks
                            )
                        kl = masked_kl(anchor_dist, dist).mean()
                    stats["kl_to_anchor"].append(kl.item())
                    if kl_weight > 0 and actor_scale > 0:
                        loss = loss + kl_weight * kl

                stats["policy_gradient_loss"].append(policy_loss.item())
                stats["value_loss"].append(value_loss.item())
                stats["entropy_loss"].append(entropy_loss.item())
                stats["clip_fraction"].append(
                    ((ratio - 1).abs() > clip_range).float().mean().item()
                )
                with torch.no_grad():  # Schulman's unbiased estimator of KL(old || new)
                    log_ratio = log_prob - batch.old_log_prob
                    approx_kl = float(((log_ratio.exp() - 1) - log_ratio).mean())
                approx_kls.append(approx_kl)
                if self.target_kl is not None and approx_kl > 1.5 * self.target_kl:
                    continue_training = False
                    logger.info(
                        "early stopping at epoch %d: KL %.4f over the target", epoch, approx_kl
                    )
                    break

                policy.optimizer.zero_grad()
                loss.backward()
                if actor_scale == 0.0:
                    for p in actor:
                        p.grad = None  # no step at all, no optimiser state either
                nn.utils.clip_grad_norm_(policy.parameters(), self.max_grad_norm)
                ramped = actor if actor_scale > 0.0 else []
                before = [p.detach().clone() for p in ramped]
                policy.optimizer.step()
                with torch.no_grad():  # the actor's step at actor_scale · lr (Adam, SGD: exact)
                    for p, old in zip(ramped, before, strict=True):
                        p.copy_(old.lerp_(p, actor_scale))
            self._n_updates += 1
            if not continue_training:
                break

        self.n_train_calls += 1
        buffer = self.rollout_buffer
        if cached:
            kept: Any = buffer.observations
            for key in (ANCHOR_PROBS, ANCHOR_LOGITS):
                kept.pop(key)
        explained_var = explained_variance(buffer.values.flatten(), buffer.returns.flatten())
        for name, values_ in stats.items():
            self.logger.record(f"train/{name}", float(np.mean(values_)))
        self.logger.record("train/approx_kl", float(np.mean(approx_kls)))
        self.logger.record("train/loss", loss.item())
        self.logger.record("train/explained_variance", explained_var)
        self.logger.record("train/n_updates", self._n_updates, exclude="tensorboard")
        self.logger.record("train/clip_range", clip_range)
        if clip_range_vf is not None:
            self.logger.record("train/clip_range_vf", clip_range_vf)
        self.logger.record("train/actor_lr", lr * actor_scale)
        self.logger.record("train/critic_lr", lr)
        self.logger.record("train/kl_weight", kl_weight if actor_scale > 0 else 0.0)

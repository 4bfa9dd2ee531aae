"""A MaskablePPO policy for ``SfW-ExploreGoals-v0``: one scorer per candidate, a separate critic.

The actor's logit for candidate k is a small MLP of k's features and the robot's ``state`` (the
same MLP for every candidate: pointer-style, so what it learns about one goal holds for all);
masked candidates get no probability (sb3-contrib's ``MaskableCategorical``). The critic is a
separate MLP of the mean and max of the candidates' features and ``state``: no trunk is shared,
so the value loss cannot drown the policy's gradients (the waypoint policy's failure).
``shared_trunk=True`` (an ablation) feeds the critic the scorer's pooled hidden layer instead.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, NamedTuple

import gymnasium as gym
import numpy as np
import torch
from gymnasium import spaces
from sb3_contrib.common.maskable.policies import MaskableMultiInputActorCriticPolicy
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn


class GoalsInputs(BaseFeaturesExtractor):
    """Features = ``[candidates flattened (K·F), state (S)]`` (no parameters)."""

    #: The observation entries it reads.
    keys = ("candidates", "state")

    def __init__(self, observation_space: spaces.Dict) -> None:
        k, f = observation_space["candidates"].shape or (0, 0)
        s = int(np.prod(observation_space["state"].shape or (0,)))
        super().__init__(observation_space, features_dim=k * f + s)
        self.shape: tuple[int, int, int] = (k, f, s)

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        return torch.cat([observations["candidates"].flatten(1), observations["state"]], dim=1)


class CandidateHeads(nn.Module):
    """``forward_actor``: a logit per candidate; ``forward_critic``: the critic's latent."""

    def __init__(
        self, k: int, f: int, s: int, hidden: int = 64, shared_trunk: bool = False
    ) -> None:
        super().__init__()
        self.k, self.f, self.s = k, f, s
        self.shared_trunk = shared_trunk
        self.latent_dim_pi, self.latent_dim_vf = k, hidden
        self.scorer = nn.Sequential(
            nn.Linear(f + s, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh()
        )
        self.score = nn.Linear(hidden, 1)
        critic_in = 2 * hidden + s if shared_trunk else 2 * f + s
        self.critic = nn.Sequential(
            nn.Linear(critic_in, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh()
        )

    def _split(self, features: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        cand = features[:, : self.k * self.f].view(-1, self.k, self.f)
        return cand, features[:, self.k * self.f :]

    def _hidden(self, cand: torch.Tensor, state: torch.Tensor) -> torch.Tensor:
        both = torch.cat([cand, state[:, None, :].expand(-1, self.k, -1)], dim=2)
        return self.scorer(both)

    def forward_actor(self, features: torch.Tensor) -> torch.Tensor:
        return self.score(self._hidden(*self._split(features))).squeeze(-1)

    def forward_critic(self, features: torch.Tensor) -> torch.Tensor:
        cand, state = self._split(features)
        per_candidate = self._hidden(cand, state) if self.shared_trunk else cand
        pooled = torch.cat([per_candidate.mean(1), per_candidate.max(1).values, state], dim=1)
        return self.critic(pooled)

    def forward(self, features: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        return self.forward_actor(features), self.forward_critic(features)


class GoalsPolicy(MaskableMultiInputActorCriticPolicy):
    """:class:`CandidateHeads` as the policy's heads; the logits are the actor's output as is."""

    def __init__(
        self, *args: Any, hidden: int = 64, shared_trunk: bool = False, **kwargs: Any
    ) -> None:
        self.hidden, self.shared_trunk = hidden, shared_trunk
        kwargs.setdefault("features_extractor_class", GoalsInputs)
        super().__init__(*args, **kwargs)

    def _build_mlp_extractor(self) -> None:
        inputs = self.features_extractor
        assert isinstance(inputs, GoalsInputs)
        self.mlp_extractor = CandidateHeads(  # type: ignore[assignment]
            *inputs.shape, hidden=self.hidden, shared_trunk=self.shared_trunk
        )

    #: The observation entries the actor reads.
    actor_keys = GoalsInputs.keys

    def actor_logits(self, obs: dict[str, torch.Tensor]) -> torch.Tensor:
        """``(B, K)`` logits of the candidates (before masking)."""
        features = self.extract_features({k: obs[k].float() for k in self.actor_keys})
        assert isinstance(features, torch.Tensor)
        return self.heads.forward_actor(features)

    @property
    def heads(self) -> CandidateHeads:
        """The actor's and the critic's heads (SB3's ``mlp_extractor``)."""
        heads = self.mlp_extractor
        assert isinstance(heads, CandidateHeads)
        return heads

    def parameter_groups(self) -> dict[str, list[nn.Parameter]]:
        """The actor's and the critic's parameters (disjoint unless ``shared_trunk``: the policy
        loss reaches only the first, the value loss only the second)."""
        heads = self.heads
        trunk = [*heads.scorer.parameters()]
        return {
            "actor": [*trunk, *heads.score.parameters()],
            "critic": [
                *(trunk if heads.shared_trunk else []),
                *heads.critic.parameters(),
                *self.value_net.parameters(),
            ],
        }

    def _build(self, lr_schedule: Any) -> None:
        super()._build(lr_schedule)
        self.action_net = nn.Identity()  # one logit per candidate already
        self.optimizer = self.optimizer_class(  # type: ignore[call-arg]
            self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs
        )


class HeadGradientNorms(BaseCallback):
    """Logs the gradient norm of each of the policy's :meth:`~GoalsPolicy.parameter_groups`
    after every PPO update (its last minibatch's, after SB3 clips the whole policy's norm to
    ``max_grad_norm``, which keeps their ratio) as ``train/grad_norm_<group>``;
    ``history`` keeps them."""

    def __init__(self) -> None:
        super().__init__()
        self.history: list[dict[str, float]] = []

    def _on_rollout_start(self) -> None:  # the update of the previous rollout has just ended
        norms = {}
        for name, params in self.model.policy.parameter_groups().items():  # type: ignore[operator]
            grads = [p.grad.detach().flatten() for p in params if p.grad is not None]
            if grads:
                norms[name] = float(torch.cat(grads).norm())
                self.logger.record(f"train/grad_norm_{name}", norms[name])
        if norms:
            self.history.append(norms)

    def _on_step(self) -> bool:
        return True


class Demonstrations(NamedTuple):
    """A teacher's decisions (:func:`teacher_decisions`): the observations, the teacher's choice
    in each ``(N,)`` and the masks of the candidates allowed ``(N, K)``."""

    observations: list[dict[str, np.ndarray]]
    actions: np.ndarray
    masks: np.ndarray

    def joined(self, more: Demonstrations) -> Demonstrations:
        """These decisions followed by ``more`` (DAgger's growing data set)."""
        return Demonstrations(
            self.observations + more.observations,
            np.concatenate([self.actions, more.actions]),
            np.concatenate([self.masks, more.masks]),
        )


def teacher_decisions(
    env_id: str,
    env_kwargs: dict[str, Any],
    seeds: Iterable[int],
    learner: Any = None,
    learner_masked: bool = True,
    teacher: str = "explore_lite",
) -> Demonstrations:
    """Observations, choices and masks of the env's ``teacher`` (``teacher_action(teacher)``; by
    default the frontier agent's choice on the menu,
    :func:`~sfw_gym.navigation.menu.explore_lite_choice`) over one episode per seed. The
    teacher drives, or the ``learner`` (its most likely choice, among the valid ones if
    ``learner_masked``) does: DAgger's states, labelled with the teacher's choices."""
    observations, actions, masks = [], [], []
    for seed in seeds:
        env = gym.make(env_id, **env_kwargs)
        obs, _ = env.reset(seed=seed)
        done = False
        while not done:
            mask = env.unwrapped.action_masks()  # type: ignore[attr-defined]
            action = env.unwrapped.teacher_action(teacher)  # type: ignore[attr-defined]
            observations.append(obs)
            actions.append(action)
            masks.append(mask)
            if learner is not None:
                allowed = mask if learner_masked else np.ones_like(mask)
                taken, _ = learner.predict(obs, deterministic=True, action_masks=allowed)
                action = int(taken)
            obs, _, terminated, truncated, _ = env.step(action)
            done = terminated or truncated
        env.close()
    return Demonstrations(observations, np.array(actions), np.array(masks))


def behaviour_clone(
    policy: Any,
    demos: Demonstrations,
    epochs: int = 20,
    batch_size: int = 256,
    lr: float = 1e-3,
    seed: int = 0,
) -> list[float]:
    """Fit the actor of ``policy`` (:class:`GoalsPolicy` or any policy with ``actor_keys``,
    ``actor_logits`` and ``parameter_groups``) to a teacher's choices ``demos`` (cross-entropy
    over the masked candidates); returns the mean loss per epoch."""
    gen = torch.Generator().manual_seed(seed)
    obs = _actor_inputs(policy, demos.observations)
    acts = torch.as_tensor(demos.actions, dtype=torch.long)
    mask = torch.as_tensor(demos.masks, dtype=torch.bool)
    optimiser = torch.optim.Adam(policy.parameter_groups()["actor"], lr=lr)
    losses = []
    for _ in range(epochs):
        order = torch.randperm(len(acts), generator=gen)
        total = 0.0
        for start in range(0, len(acts), batch_size):
            idx = order[start : start + batch_size]
            logits = policy.actor_logits({k: v[idx] for k, v in obs.items()})
            logits = logits.masked_fill(~mask[idx], -1e8)
            loss = nn.functional.cross_entropy(logits, acts[idx])
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            total += float(loss.detach()) * len(idx)
        losses.append(total / len(acts))
    return losses


def teacher_agreement(policy: Any, demos: Demonstrations, batch_size: int = 512) -> float:
    """The share of ``demos``' decisions on which the actor's most likely allowed candidate is
    the teacher's (behaviour cloning's accuracy)."""
    actions, masks = demos.actions, demos.masks
    hits = 0
    with torch.no_grad():
        for start in range(0, len(actions), batch_size):
            obs = _actor_inputs(policy, demos.observations[start : start + batch_size])
            mask = torch.as_tensor(masks[start : start + batch_size], dtype=torch.bool)
            logits = policy.actor_logits(obs).masked_fill(~mask, -torch.inf)
            hits += int((logits.argmax(1).numpy() == actions[start : start + batch_size]).sum())
    return hits / max(len(actions), 1)


def _actor_inputs(policy: Any, observations: list[dict[str, np.ndarray]]) -> dict[str, Any]:
    """The observations' entries that ``policy``'s actor reads, stacked into tensors."""
    return {k: torch.as_tensor(np.stack([o[k] for o in observations])) for k in policy.actor_keys}

"""A MaskablePPO policy for ``SfW-ExploreRegions-v0``: candidates scored in the map's context.

The actor reads the global ``map`` image with a small CNN, samples its features at each
candidate's pixel (``candidate_px``) and adds a pooled summary of the whole map; with the
candidate's hand features and the robot's ``state`` they go through one MLP shared by every
candidate (pointer-style), one logit per candidate; masked candidates get no probability
(sb3-contrib's ``MaskableCategorical``). The critic is fully apart (its own CNN): the value loss
never reaches the actor. It may read the privileged ``true_map`` (``privileged_critic``); the
actor never does. ``map_context=False`` (an ablation) drops the actor's CNN.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import torch
from gymnasium import spaces
from sb3_contrib.common.maskable.policies import MaskableMultiInputActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn
from torch.nn import functional as F

#: The observation entries the actor reads (without its map context: only the last two).
ACTOR_KEYS = ("map", "candidate_px", "candidates", "state")


def _inverse_high(space: spaces.Space) -> float:
    """``1 / the Box's largest bound`` (1/255 for a uint8 image): scales it to [0, 1]."""
    assert isinstance(space, spaces.Box)
    return 1.0 / max(float(np.max(space.high)), 1.0)


#: Channels of a map encoder's features.
MAP_FEATURES = 32


def _input_sizes(observation_space: spaces.Dict) -> tuple[int, int]:
    """The number of features per candidate and the size of ``state``."""
    _, f = observation_space["candidates"].shape or (0, 0)
    return f, int(np.prod(observation_space["state"].shape or (0,)))


def map_encoder(channels: int, width: int = MAP_FEATURES) -> nn.Sequential:
    """Three 3×3 convolutions, the first two with stride 2: a ``P/4 × P/4`` feature map."""
    return nn.Sequential(
        nn.Conv2d(channels, width, 3, stride=2, padding=1),
        nn.ReLU(),
        nn.Conv2d(width, width, 3, stride=2, padding=1),
        nn.ReLU(),
        nn.Conv2d(width, width, 3, padding=1),
        nn.ReLU(),
    )


def _pooled(features: torch.Tensor) -> torch.Tensor:
    """Mean and max over a ``(B, C, H, W)`` feature map: ``(B, 2C)``."""
    return torch.cat([features.mean((2, 3)), features.amax((2, 3))], dim=1)


class PassThrough(BaseFeaturesExtractor):
    """The observation dict as is (SB3's preprocessing has made each entry a float tensor)."""

    def __init__(self, observation_space: spaces.Dict) -> None:
        super().__init__(observation_space, features_dim=1)

    def forward(self, observations: dict[str, torch.Tensor]) -> dict[str, torch.Tensor]:
        return observations


class RegionActor(nn.Module):
    """A logit per candidate: a shared MLP of its map features, the map's summary, its hand
    features and ``state``."""

    def __init__(
        self, observation_space: spaces.Dict, hidden: int = 64, map_context: bool = True
    ) -> None:
        super().__init__()
        f, s = _input_sizes(observation_space)
        self.map_scale = _inverse_high(observation_space["map"])
        self.cnn = map_encoder((observation_space["map"].shape or (0,))[0]) if map_context else None
        # + the map's features sampled at the candidate, their mean and their max
        inputs = f + s + (3 * MAP_FEATURES if map_context else 0)
        self.scorer = nn.Sequential(
            nn.Linear(inputs, hidden), nn.Tanh(), nn.Linear(hidden, hidden), nn.Tanh()
        )
        self.score = nn.Linear(hidden, 1)

    def forward(self, obs: Mapping[str, torch.Tensor]) -> torch.Tensor:
        cand, state = obs["candidates"], obs["state"]
        k = cand.shape[1]
        parts = [cand, state[:, None, :].expand(-1, k, -1)]
        if self.cnn is not None:
            features = self.cnn(obs["map"] * self.map_scale)  # (B, C, H, W)
            grid = obs["candidate_px"].flip(-1) * 2.0 - 1.0  # (row, col) in [0, 1] -> (x, y)
            local = F.grid_sample(
                features, grid[:, :, None, :], align_corners=False, padding_mode="border"
            )  # (B, C, K, 1)
            parts.append(local.squeeze(-1).transpose(1, 2))
            parts.append(_pooled(features)[:, None, :].expand(-1, k, -1))
        return self.score(self.scorer(torch.cat(parts, dim=2))).squeeze(-1)


class RegionCritic(nn.Module):
    """The critic's latent: its own CNN over ``map`` (and ``true_map`` if ``privileged``), pooled,
    with the candidates' mean and max, their share of valid slots and ``state``."""

    def __init__(
        self, observation_space: spaces.Dict, hidden: int = 64, privileged: bool = True
    ) -> None:
        super().__init__()
        f, s = _input_sizes(observation_space)
        map_shape = observation_space["map"].shape or (0, 0, 0)
        channels = map_shape[0]
        self.privileged = privileged and "true_map" in observation_space.spaces
        self.map_scale = _inverse_high(observation_space["map"])
        self.true_scale = 1.0
        if self.privileged:
            true_shape = observation_space["true_map"].shape or (0, 0, 0)
            if tuple(true_shape[1:]) != tuple(map_shape[1:]):
                raise ValueError(f"true_map {true_shape} and map {map_shape} differ in size")
            channels += true_shape[0]
            self.true_scale = _inverse_high(observation_space["true_map"])
        self.cnn = map_encoder(channels)
        self.mlp = nn.Sequential(
            nn.Linear(2 * MAP_FEATURES + 2 * f + 1 + s, hidden),
            nn.Tanh(),
            nn.Linear(hidden, hidden),
            nn.Tanh(),
        )

    def forward(self, obs: Mapping[str, torch.Tensor]) -> torch.Tensor:
        image = obs["map"] * self.map_scale
        if self.privileged:
            image = torch.cat([image, obs["true_map"] * self.true_scale], dim=1)
        cand = obs["candidates"]
        valid = obs["candidate_mask"].float().mean(1, keepdim=True)
        pooled = [_pooled(self.cnn(image)), cand.mean(1), cand.amax(1), valid, obs["state"]]
        return self.mlp(torch.cat(pooled, dim=1))


class RegionHeads(nn.Module):
    """SB3's ``mlp_extractor``: ``forward_actor`` gives the logits, ``forward_critic`` the
    critic's latent, each from the observation dict."""

    def __init__(
        self,
        observation_space: spaces.Dict,
        hidden: int = 64,
        map_context: bool = True,
        privileged_critic: bool = True,
    ) -> None:
        super().__init__()
        self.actor = RegionActor(observation_space, hidden, map_context)
        self.critic = RegionCritic(observation_space, hidden, privileged_critic)
        self.latent_dim_pi = (observation_space["candidates"].shape or (0,))[0]
        self.latent_dim_vf = hidden

    def forward_actor(self, obs: Mapping[str, torch.Tensor]) -> torch.Tensor:
        return self.actor(obs)

    def forward_critic(self, obs: Mapping[str, torch.Tensor]) -> torch.Tensor:
        return self.critic(obs)

    def forward(self, obs: Mapping[str, torch.Tensor]) -> tuple[torch.Tensor, torch.Tensor]:
        return self.actor(obs), self.critic(obs)


class RegionsPolicy(MaskableMultiInputActorCriticPolicy):
    """:class:`RegionHeads` as the policy's heads; the logits are the actor's output as is.

    Images are scaled by the heads (SB3's ``normalize_images`` is off). Keyword arguments
    (rl-zoo ``policy_kwargs``): ``hidden``, ``map_context``, ``privileged_critic``.
    """

    #: The observation entries the actor reads (an instance has its own, per ``map_context``).
    actor_keys: tuple[str, ...] = ACTOR_KEYS

    def __init__(
        self,
        observation_space: spaces.Dict,
        action_space: spaces.Space,
        lr_schedule: Any,
        hidden: int = 64,
        map_context: bool = True,
        privileged_critic: bool = True,
        **kwargs: Any,
    ) -> None:
        self.hidden, self.map_context = hidden, map_context
        self.privileged_critic = privileged_critic
        self.actor_keys = ACTOR_KEYS if map_context else ("candidates", "state")
        if kwargs.get("normalize_images", False):
            raise ValueError("RegionsPolicy scales its images itself: normalize_images=False")
        kwargs["normalize_images"] = False
        kwargs.setdefault("features_extractor_class", PassThrough)
        super().__init__(observation_space, action_space, lr_schedule, **kwargs)

    def _build_mlp_extractor(self) -> None:
        assert isinstance(self.observation_space, spaces.Dict)
        self.mlp_extractor = RegionHeads(  # type: ignore[assignment]
            self.observation_space, self.hidden, self.map_context, self.privileged_critic
        )

    def _build(self, lr_schedule: Any) -> None:
        super()._build(lr_schedule)
        self.action_net = nn.Identity()  # one logit per candidate already
        if self.ortho_init:  # near-uniform choices at first, as SB3's action_net would give
            self.init_weights(self.heads.actor.score, gain=0.01)
        self.optimizer = self.optimizer_class(  # type: ignore[call-arg]
            self.parameters(), lr=lr_schedule(1), **self.optimizer_kwargs
        )

    def _get_constructor_parameters(self) -> dict[str, Any]:
        data = super()._get_constructor_parameters()
        data.update(
            hidden=self.hidden,
            map_context=self.map_context,
            privileged_critic=self.privileged_critic,
        )
        return data

    @property
    def heads(self) -> RegionHeads:
        """The actor's and the critic's heads (SB3's ``mlp_extractor``)."""
        heads = self.mlp_extractor
        assert isinstance(heads, RegionHeads)
        return heads

    def actor_logits(self, obs: Mapping[str, torch.Tensor | np.ndarray]) -> torch.Tensor:
        """The unmasked logits ``(B, K)`` of a batch of raw observations (only
        :attr:`actor_keys` are read; ``true_map`` need not be there)."""
        device = self.device  # SB3 walks the parameters to find it: once per call
        inputs = {k: torch.as_tensor(obs[k], device=device).float() for k in self.actor_keys}
        return self.heads.actor(inputs)

    def parameter_groups(self) -> dict[str, list[nn.Parameter]]:
        """The actor's and the critic's parameters: disjoint, together all of the policy's."""
        heads = self.heads
        return {
            "actor": [*heads.actor.parameters()],
            "critic": [*heads.critic.parameters(), *self.value_net.parameters()],
        }

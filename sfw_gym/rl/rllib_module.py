"""The RLlib module for sfw_gym's Dict observations (imported only with ``ray[rllib]``)."""

from __future__ import annotations

import math
from typing import Any

import torch
from gymnasium import spaces
from ray.rllib.core.columns import Columns
from ray.rllib.core.rl_module.apis import ValueFunctionAPI
from ray.rllib.core.rl_module.torch import TorchRLModule
from torch import nn

from sfw_gym.core.errors import ConfigError

#: The observation key of the candidate-goal env's valid-action mask.
MASK_KEY = "candidate_mask"


def small_cnn(channels: int, out: int) -> nn.Sequential:
    """Two strided convolutions, pooled to 4 × 4, then one linear layer of width ``out``."""
    return nn.Sequential(
        nn.Conv2d(channels, 16, 5, stride=2, padding=2),
        nn.ReLU(),
        nn.Conv2d(16, 32, 3, stride=2, padding=1),
        nn.ReLU(),
        nn.AdaptiveAvgPool2d(4),
        nn.Flatten(),
        nn.Linear(32 * 16, out),
        nn.ReLU(),
    )


class DictObsModule(TorchRLModule, ValueFunctionAPI):
    """Actor-critic for sfw_gym's Dict observation: a small CNN per image (uint8, scaled to
    [0, 1]), an MLP for the vectors (``state``, flattened ``candidates``), policy and value
    heads on the joined features. Where the obs has ``candidate_mask`` and the actions are
    discrete, invalid actions get the lowest logit (never sampled). Box actions: a diagonal
    Gaussian (mean and log-std from the head).

    ``model_config``: ``{"hidden": 64}``.
    """

    def setup(self) -> None:
        hidden = int(self.model_config.get("hidden", 64))
        obs_space = self.observation_space
        if not isinstance(obs_space, spaces.Dict):
            raise ConfigError(f"DictObsModule needs a Dict observation, got {obs_space}")
        self.image_keys = [k for k, s in obs_space.spaces.items() if len(s.shape or ()) == 3]
        self.vector_keys = [k for k in obs_space.spaces if k not in [*self.image_keys, MASK_KEY]]
        discrete = isinstance(self.action_space, spaces.Discrete)
        self.masked = discrete and MASK_KEY in obs_space.spaces
        shapes = {k: tuple(s.shape or ()) for k, s in obs_space.spaces.items()}
        self.cnns = nn.ModuleDict({k: small_cnn(shapes[k][0], hidden) for k in self.image_keys})
        vector_dim = sum(math.prod(shapes[k]) for k in self.vector_keys)
        self.mlp = nn.Sequential(nn.Linear(vector_dim, hidden), nn.ReLU())
        joined = hidden * (len(self.image_keys) + 1)
        n_out = int(self.action_space.n) if discrete else 2 * math.prod(self.action_space.shape)
        head = nn.Linear(hidden, n_out)
        nn.init.orthogonal_(head.weight, gain=0.01)  # a near-uniform first policy
        nn.init.zeros_(head.bias)
        self.pi = nn.Sequential(nn.Linear(joined, hidden), nn.Tanh(), head)
        self.vf = nn.Sequential(nn.Linear(joined, hidden), nn.Tanh(), nn.Linear(hidden, 1))

    def _embed(self, obs: dict[str, Any]) -> torch.Tensor:
        parts = [self.cnns[k](obs[k].float() / 255.0) for k in self.image_keys]
        vectors = torch.cat([obs[k].float().flatten(1) for k in self.vector_keys], dim=1)
        return torch.cat([*parts, self.mlp(vectors)], dim=1)

    def _logits(self, obs: dict[str, Any], embeddings: torch.Tensor) -> torch.Tensor:
        logits = self.pi(embeddings)
        if self.masked:
            logits = logits.masked_fill(obs[MASK_KEY] <= 0, torch.finfo(logits.dtype).min)
        return logits

    def _forward(self, batch: dict[str, Any], **kwargs: Any) -> dict[str, Any]:
        obs = batch[Columns.OBS]
        return {Columns.ACTION_DIST_INPUTS: self._logits(obs, self._embed(obs))}

    def _forward_train(self, batch: dict[str, Any], **kwargs: Any) -> dict[str, Any]:
        obs = batch[Columns.OBS]
        embeddings = self._embed(obs)
        return {
            Columns.ACTION_DIST_INPUTS: self._logits(obs, embeddings),
            Columns.EMBEDDINGS: embeddings,
        }

    def compute_values(self, batch: dict[str, Any], embeddings: Any = None) -> torch.Tensor:
        if embeddings is None:
            embeddings = self._embed(batch[Columns.OBS])
        return self.vf(embeddings).squeeze(-1)

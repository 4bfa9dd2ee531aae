"""A PPO policy for waypoint actions that scores every block with one shared network.

The :class:`~sfw_gym.envs.waypoint.WaypointWrapper` observation carries ``blocks``: per block of
the map, what the robot knows of it (unknown/free/wall fractions, distance, ...). The policy's
logit for "drive to block b" is a small MLP of block b's features, the same MLP for every block,
so what it learns about one block holds for all (a pointer-style head); the value function sees
every block's features. The images are left to the baselines and the rest of the obs is unused.
"""

from __future__ import annotations

from typing import Any

import torch
from gymnasium import spaces
from stable_baselines3.common.policies import MultiInputActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn


class BlockScores(BaseFeaturesExtractor):
    """Features = ``[score of each block (n), every block's features flattened (n·f)]``."""

    def __init__(self, observation_space: spaces.Dict, hidden: int = 64) -> None:
        n, f = observation_space["blocks"].shape or (0, 0)
        super().__init__(observation_space, features_dim=n + n * f)
        self.n_blocks = n
        self.scorer = nn.Sequential(
            nn.Linear(f, hidden),
            nn.Tanh(),
            nn.Linear(hidden, hidden),
            nn.Tanh(),
            nn.Linear(hidden, 1),
        )

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        blocks = observations["blocks"]
        scores = self.scorer(blocks).squeeze(-1)
        return torch.cat([scores, blocks.flatten(1)], dim=1)


class _Scores(nn.Module):
    """The action head: the first ``n`` features are the logits."""

    def __init__(self, n: int) -> None:
        super().__init__()
        self.n = n

    def forward(self, latent: torch.Tensor) -> torch.Tensor:
        return latent[:, : self.n]


class WaypointPolicy(MultiInputActorCriticPolicy):
    """Actor-critic whose action logits are :class:`BlockScores`' per-block scores."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("features_extractor_class", BlockScores)
        kwargs.setdefault("net_arch", {"pi": [], "vf": [64, 64]})
        kwargs.setdefault("ortho_init", False)
        super().__init__(*args, **kwargs)

    def _build(self, lr_schedule: Any) -> None:
        super()._build(lr_schedule)
        assert isinstance(self.action_space, spaces.Discrete)
        self.action_net = _Scores(int(self.action_space.n))
        self.optimizer = self.optimizer_class(  # as SB3 builds it (its Optimizer type has no lr)
            self.parameters(),
            lr=lr_schedule(1),  # type: ignore[call-arg]
            **self.optimizer_kwargs,
        )

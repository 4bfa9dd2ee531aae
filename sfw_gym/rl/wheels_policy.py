"""A policy for PPO on the wheels: the maps turned to the robot's frame, small CNNs sized for them.

The env's images are north-up: the same corridor ahead of the robot looks different for every
heading, so a network must learn each view once per heading. :class:`EgoMaps` turns them, inside
the network, into the robot's frame (robot at the centre, its heading up) from the observation
alone: the heading is the state's sin and cos, the robot's pixel on the ``map`` image is its
marker in the trajectory channel. No env wrapper is needed, so the native vector env and
rl-baselines3-zoo train it as they train any ``MultiInputPolicy``.

Features: the local crop turned (belief at full resolution around the robot), the whole map
turned about the robot (belief, trajectory, routers), each through a small CNN, and the state
vector. Pixel values are shifted so that unknown is 0, free +1 and wall −1 (and the padding of
the turned images reads unknown).
"""

from __future__ import annotations

from typing import Any

import torch
import torch.nn.functional as F
from gymnasium import spaces
from stable_baselines3.common.policies import MultiInputActorCriticPolicy
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

#: Where the heading's sine and cosine sit in the state vector, counted from its end
#: (``envs.observation``: ..., bump, x, y, sin, cos, known fraction).
SIN_INDEX, COS_INDEX = -3, -2
#: The robot's marker in the ``map`` image's trajectory channel, as SB3 scales it (255 / 255).
ROBOT_MARK = 0.99


def ego_grid(sin: torch.Tensor, cos: torch.Tensor, centre: torch.Tensor, size: int) -> torch.Tensor:
    """The ``grid_sample`` grid of a ``size``² view centred on ``centre`` (normalised (x, y) of
    the source image) and turned so that the heading points up.

    An output pixel at normalised (a, b) (a to the right, b down) reads the source at
    ``centre + f·forward + s·side`` with f = −b and s = a; forward is (cos θ, sin θ) in the
    image's (column, row) axes, the map's (x, y).
    """
    rot = torch.stack(
        [torch.stack([sin, -cos], dim=-1), torch.stack([-cos, -sin], dim=-1)], dim=-2
    )  # (N, 2, 2): rows give source x and y from (a, b)
    theta = torch.cat([rot, centre.unsqueeze(-1)], dim=-1)
    return F.affine_grid(theta, [sin.shape[0], 1, size, size], align_corners=False)


def robot_centre(trajectory: torch.Tensor) -> torch.Tensor:
    """The robot's normalised (x, y) on the ``map`` image: the mean of its marker's pixels."""
    _, h, w = trajectory.shape
    mark = (trajectory >= ROBOT_MARK).float()
    count = mark.sum(dim=(1, 2)).clamp(min=1.0)
    rows = torch.arange(h, dtype=trajectory.dtype, device=trajectory.device)
    cols = torch.arange(w, dtype=trajectory.dtype, device=trajectory.device)
    r = (mark.sum(dim=2) * rows).sum(dim=1) / count
    c = (mark.sum(dim=1) * cols).sum(dim=1) / count
    return torch.stack([(2 * c + 1) / w - 1, (2 * r + 1) / h - 1], dim=-1)


def _cnn(channels: int, size: int, widths: tuple[int, ...]) -> tuple[nn.Module, int]:
    """Stride-2 3×3 convolutions of these widths and a flatten; the module and its output size."""
    layers: list[nn.Module] = []
    for c_in, c_out in zip((channels, *widths[:-1]), widths, strict=True):
        layers += [nn.Conv2d(c_in, c_out, 3, stride=2, padding=1), nn.ReLU()]
    net = nn.Sequential(*layers, nn.Flatten())
    with torch.no_grad():
        out = net(torch.zeros(1, channels, size, size)).shape[1]
    return net, int(out)


class EgoMaps(BaseFeaturesExtractor):
    """Features of the ``local`` and ``map`` images turned to the robot's frame, and ``state``.

    The turned views are sampled at ``local_px`` and ``map_px`` pixels a side (half the env's
    images by default: 0.2 m a pixel around the robot, the whole plan around it on the map), small
    enough that a PPO update on two CPU cores keeps pace with the native vector env.
    """

    def __init__(
        self,
        observation_space: spaces.Dict,
        features_dim: int = 128,
        local_px: int = 24,
        map_px: int = 32,
    ) -> None:
        super().__init__(observation_space, features_dim=features_dim)
        local_shape = observation_space["local"].shape
        map_shape = observation_space["map"].shape
        state_shape = observation_space["state"].shape
        assert local_shape is not None and map_shape is not None and state_shape is not None
        self.local_px, self.map_px = local_px, map_px
        self.local_cnn, local_out = _cnn(int(local_shape[0]), local_px, (8, 16))
        self.map_cnn, map_out = _cnn(int(map_shape[0]), map_px, (8, 16, 16))
        self.head = nn.Sequential(
            nn.Linear(local_out + map_out + int(state_shape[0]), features_dim), nn.ReLU()
        )

    def ego_views(self, observations: dict[str, torch.Tensor]) -> tuple[torch.Tensor, torch.Tensor]:
        """The local crop and the map turned to the robot's frame (unknown 0, free 1, wall −1)."""
        state = observations["state"]
        sin, cos = state[:, SIN_INDEX], state[:, COS_INDEX]
        local = observations["local"] * 2 - 1
        centre = torch.zeros(state.shape[0], 2, dtype=state.dtype, device=state.device)
        local = F.grid_sample(local, ego_grid(sin, cos, centre, self.local_px), align_corners=False)
        image = observations["map"]
        scale = torch.ones(image.shape[1], 1, 1, dtype=image.dtype, device=image.device)
        scale[0] = 2.0  # the belief channel only: 2 b - 1, the others as they are
        image = torch.addcmul(-(scale - 1), image, scale)
        grid = ego_grid(sin, cos, robot_centre(observations["map"][:, 1]), self.map_px)
        return local, F.grid_sample(image, grid, align_corners=False)

    def forward(self, observations: dict[str, torch.Tensor]) -> torch.Tensor:
        local, image = self.ego_views(observations)
        return self.head(
            torch.cat([self.local_cnn(local), self.map_cnn(image), observations["state"]], dim=1)
        )


class WheelsPolicy(MultiInputActorCriticPolicy):
    """Actor-critic on :class:`EgoMaps` features (SB3's MLP heads above them)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("features_extractor_class", EgoMaps)
        kwargs.setdefault("net_arch", {"pi": [64], "vf": [64]})
        super().__init__(*args, **kwargs)

    def parameter_groups(self) -> dict[str, list[nn.Parameter]]:
        """The shared features (both losses reach them), the actor's head (with its log std) and
        the critic's head: ``train/grad_norm_<group>`` in the training logs."""
        extractor = self.features_extractor
        return {
            "features": [*extractor.parameters()],
            "actor": [
                *self.mlp_extractor.policy_net.parameters(),
                *self.action_net.parameters(),
                *(
                    [self.log_std]
                    if isinstance(getattr(self, "log_std", None), nn.Parameter)
                    else []
                ),
            ],
            "critic": [*self.mlp_extractor.value_net.parameters(), *self.value_net.parameters()],
        }

"""Learning: PPO and MaskablePPO training (stable-baselines3, sb3-contrib, rl-zoo
hyperparameters), the policies, and the agents that act with a trained model (``PPOAgent``:
candidate goals, the shipped learned explorer; ``RegionsPPOAgent``: a region every 20 steps;
``WheelsPPOAgent``: PPO from scratch on the wheel commands; ``WaypointPPOAgent``: the earlier
block-waypoint policy). The only layer that imports torch and
stable-baselines3 (``pip install 'sfw-gym[rl]'``).
"""

from __future__ import annotations

from sfw_gym.rl.agent import PPOAgent, RegionsPPOAgent
from sfw_gym.rl.training import load_hyperparams, train_ppo
from sfw_gym.rl.waypoint_agent import WaypointPPOAgent
from sfw_gym.rl.wheels_agent import WheelsPPOAgent

__all__ = [
    "PPOAgent",
    "RegionsPPOAgent",
    "WaypointPPOAgent",
    "WheelsPPOAgent",
    "load_hyperparams",
    "train_ppo",
]

"""Learning: PPO and MaskablePPO training (stable-baselines3, sb3-contrib, rl-zoo
hyperparameters), the policies, and the agents that act with a trained model
(``RegionsPPOAgent``: a region every 20 steps, ``regions-ppo``, the default learned explorer and
the demo's; ``PPOAgent``: a candidate goal per decision, ``goals-ppo``; ``WheelsPPOAgent``: PPO
from scratch on the wheel commands, ``wheels-ppo``; ``WaypointPPOAgent``: the block-waypoint
policy, ``waypoint-ppo``, which did not learn). The only layer that imports torch and
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

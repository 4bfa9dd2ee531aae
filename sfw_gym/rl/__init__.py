"""Learning: PPO and MaskablePPO training (stable-baselines3, sb3-contrib, rl-zoo
hyperparameters), the policies, and the agents that act with a trained model (``PPOAgent``: block
waypoints; ``GoalsAgent``: candidate goals). The only layer that imports torch and
stable-baselines3 (``pip install 'sfw-gym[rl]'``).
"""

from __future__ import annotations

from sfw_gym.rl.agent import PPOAgent
from sfw_gym.rl.goal_agent import GoalsAgent
from sfw_gym.rl.training import load_hyperparams, train_ppo

__all__ = ["GoalsAgent", "PPOAgent", "load_hyperparams", "train_ppo"]

"""Learning: PPO training (stable-baselines3, rl-zoo hyperparameters), the waypoint policy and
the agent that acts with a trained model. The only layer that imports torch and
stable-baselines3 (``pip install 'sfw-gym[rl]'``).
"""

from __future__ import annotations

from sfw_gym.rl.agent import PPOAgent
from sfw_gym.rl.training import load_hyperparams, train_ppo

__all__ = ["PPOAgent", "load_hyperparams", "train_ppo"]

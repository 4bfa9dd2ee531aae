"""A recorded frontier drive: what Radio SLAM logs and localisation surveys are made of."""

from __future__ import annotations

from typing import Any

import numpy as np


def record_frontier_drive(env_id: str, seed: int, steps: int) -> dict[str, Any]:
    """The frontier agent for ``steps`` steps on ``env_id`` from ``seed``: per pose (reset
    included) ``truth``, ``odometry`` ``(N, 3)`` and ``fingerprints`` ``(N, L)`` (dBm, NaN not
    heard), the plan's ``bounds``, the control ``period_s`` and the env's ``slam_config``."""
    import gymnasium as gym

    import sfw_gym  # noqa: F401  (registration)
    from sfw_gym.agents import FrontierAgent
    from sfw_gym.envs.explore import unwrap_sfw

    env = gym.make(env_id, max_steps=steps)
    sfw = unwrap_sfw(env)
    obs, info = env.reset(seed=seed)
    agent = FrontierAgent()
    agent.reset(env, seed=seed)
    infos, done = [info], False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        infos.append(info)
        done = terminated or truncated
    return {
        "truth": np.array([i["true_pose"] for i in infos]),
        "odometry": np.array([i["odometry_pose"] for i in infos]),
        "fingerprints": np.array([i["fingerprint"] for i in infos]),
        "bounds": sfw.ground_truth().floorplan.bounds,
        "period_s": sfw.robot_config.control_period_s,
        "slam_config": sfw.slam_config,
    }

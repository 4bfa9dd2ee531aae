"""A recorded frontier drive: what Radio SLAM logs and localisation surveys are made of."""

from __future__ import annotations

from typing import Any

import numpy as np

from sfw_gym.slam.radio_slam import keyframes


def record_frontier_drive(env_id: str, seed: int, steps: int, **env_kwargs: Any) -> dict[str, Any]:
    """The frontier agent for ``steps`` steps on ``gym.make(env_id, **env_kwargs)`` from
    ``seed``: per pose (reset included) ``truth``, ``odometry`` ``(N, 3)``, ``fingerprints``
    ``(N, L)`` (dBm, NaN not heard), ``bumps`` ``(N,)`` and, with a LiDAR, ``lidar_ranges``
    ``(N, beams)`` and ``keyframe_scans`` (keyframe pose → points in its robot frame); the
    plan's ``bounds``, the control ``period_s``, the env's ``slam_config``, and ``env``: the
    explore env at the end (its grid, truth, RSSI history, LiDAR)."""
    import gymnasium as gym

    import sfw_gym  # noqa: F401  (registration)
    from sfw_gym.agents import FrontierAgent
    from sfw_gym.envs.explore import unwrap_sfw

    env = gym.make(env_id, max_steps=steps, **env_kwargs)
    sfw = unwrap_sfw(env)
    obs, info = env.reset(seed=seed)
    agent = FrontierAgent()
    agent.reset(env, seed=seed)
    scene = sfw.scene
    assert scene is not None
    infos, bumps, done = [info], [False], False
    while not done:
        obs, _, terminated, truncated, info = env.step(agent.act(obs))
        infos.append(info)
        bumps.append(scene.robot.bumped)
        done = terminated or truncated
    lidar: dict[str, Any] = {}
    if sfw.lidar is not None:  # the ranges, and each keyframe's scan points (lidar_slam's input)
        ranges = np.array([i["lidar_ranges"] for i in infos])
        keys = keyframes(len(infos), sfw.config.slam.keyframe_every)
        scans = {int(k): sfw.lidar.points((0, 0, 0), ranges[k]) for k in keys}
        lidar = {"lidar_ranges": ranges, "keyframe_scans": scans}
    return {
        **lidar,
        "bumps": np.array(bumps),
        "env": sfw,
        "truth": np.array([i["true_pose"] for i in infos]),
        "odometry": np.array([i["odometry_pose"] for i in infos]),
        "fingerprints": np.array([i["fingerprint"] for i in infos]),
        "bounds": sfw.ground_truth().floorplan.bounds,
        "period_s": sfw.config.robot.control_period_s,
        "slam_config": sfw.config.slam,
    }

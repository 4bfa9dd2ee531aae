"""The Gymnasium environments; registration happens on ``import sfw_gym``."""

from __future__ import annotations

from typing import Any

import gymnasium as gym

ENTRY_POINT = "sfw_gym.envs.explore:SfWExploreEnv"

#: Every registered id with its kwargs (also the parametrisation of the env test suite); what
#: each one is: :data:`ENV_SUMMARIES`; its versions: :data:`ENV_HISTORY`.
ENV_IDS: dict[str, dict[str, Any]] = {
    "SfW-Explore-v0": {},
    "SfW-ExploreFull-v0": {"steps_per_m2": 60.0, "max_steps": 30_000},
    "SfW-ExploreDiscrete-v0": {"action_type": "discrete"},
    "SfW-ExploreThick-v0": {"radio_preset": "thick"},
    "SfW-ExploreResidential-v0": {"radio_preset": "residential"},
    "SfW-ExploreSmall-v0": {
        "generator": {"area_m2": 45.0},
        "resolution_m": 0.2,
        "map_px": 36,
        "crop_px": 36,
        "max_steps": 300,
    },
    "SfW-ExploreGoals-v0": {},
    "SfW-ExploreRegions-v0": {},
    "SfW-ExploreDrift-v0": {
        "robot": {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02},
        "n_background_aps": 16,
    },
    "SfW-ExploreRadioSLAM-v0": {
        "robot": {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02},
        "n_background_aps": 16,
        "pose_source": "radio_slam",
    },
    "SfW-ExploreLidar-v0": {
        "robot": {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02},
        "n_background_aps": 16,
        "lidar": {},
        "pose_source": "radio_lidar",
    },
    "SfW-Localize-v0": {
        "robot": {"odometry_translation_std": 0.05, "odometry_heading_std_rad": 0.02},
        "n_background_aps": 16,
    },
}

_DRIFT = (
    "drifting odometry (5 % of each step's travel, 0.02 rad of heading per step: about 1 m of "
    "ATE over 1,500 frontier steps, scripts/studies/slam_study.py) and 16 background access "
    "points heard as a fingerprint"
)
#: What each id is, in a sentence or two (the first lines of its reference page).
ENV_SUMMARIES: dict[str, str] = {
    "SfW-Explore-v0": "The benchmark: continuous (linear, angular) actions, 10 dB per wall, "
    "3,000 steps whatever the plan's size.",
    "SfW-ExploreFull-v0": "Explore the whole building: the step budget grows with the plan, "
    "60 steps per m² of free area (at most 30,000).",
    "SfW-ExploreDiscrete-v0": "Discrete actions: forward, turn left, turn right.",
    "SfW-ExploreThick-v0": "Thick walls: 15 dB per wall (the paper's building).",
    "SfW-ExploreResidential-v0": "Per-material wall losses (the hard mode).",
    "SfW-ExploreSmall-v0": "Small and quick, for tests and smoke runs: small plans, 0.2 m "
    "cells, 300 steps.",
    "SfW-ExploreGoals-v0": "Candidate-goal actions: pick one of K goals of the navigation "
    "menu, the robot drives there.",
    "SfW-ExploreRegions-v0": "Region actions: pick one of K candidates as a region every 20 "
    "steps; the classical local steering drives towards it (≤ 150 decisions an episode).",
    "SfW-ExploreDrift-v0": f"The robot maps where its odometry says it is: {_DRIFT}, whose "
    "fingerprints Radio SLAM (sfw_gym.slam.radio_slam) can close loops with.",
    "SfW-ExploreRadioSLAM-v0": f"{_DRIFT[0].upper()}{_DRIFT[1:]}, mapped along Radio SLAM's "
    "trajectory: solved again every 100 steps, the map rebuilt along each correction "
    "(sfw_gym.slam.OnlineRadioSlam).",
    "SfW-ExploreLidar-v0": "A 2-D LiDAR on the robot (360 beams, 8 m), the same drift and "
    "access points, mapped along Radio+LiDAR SLAM's trajectory (the Radio SLAM paper's second "
    "system): the reference for how close WiFi-only mapping comes (sfw_gym.slam.radio_lidar).",
    "SfW-Localize-v0": "Find yourself on a known plan: a survey's GP gridmaps and WiFi "
    "Monte-Carlo localisation from an unknown start, with the same drift and access points.",
}

#: Each id's versions, oldest first: (version, what changed). The one place for them: the env
#: reference pages print them and the changelog points here. A change that alters an id's
#: behaviour or spaces registers the next version (``-v1``) and adds its entry.
ENV_HISTORY: dict[str, tuple[tuple[str, str], ...]] = {
    env_id: (("v0", "Initial version."),) for env_id in ENV_IDS
}
#: Ids whose env is not the explore env itself.
ENTRY_POINTS: dict[str, str] = {
    "SfW-ExploreGoals-v0": "sfw_gym.envs.goals:SfWGoalsEnv",
    "SfW-ExploreRegions-v0": "sfw_gym.envs.regions:SfWRegionsEnv",
    "SfW-Localize-v0": "sfw_gym.envs.localize:SfWLocalizeEnv",
}


#: The native vector env of each entry point (``gym.make_vec``'s default for every id).
VECTOR_ENTRY_POINTS: dict[str, str] = {
    ENTRY_POINT: "sfw_gym.envs.vector:explore_vector_env",
    "sfw_gym.envs.goals:SfWGoalsEnv": "sfw_gym.envs.vector:goals_vector_env",
    "sfw_gym.envs.regions:SfWRegionsEnv": "sfw_gym.envs.vector:regions_vector_env",
    "sfw_gym.envs.localize:SfWLocalizeEnv": "sfw_gym.envs.vector:localize_vector_env",
}


def register_envs() -> None:
    """Register every id in ENV_IDS (idempotent)."""
    for env_id, kwargs in ENV_IDS.items():
        if env_id not in gym.registry:
            entry_point = ENTRY_POINTS.get(env_id, ENTRY_POINT)
            gym.register(
                id=env_id,
                entry_point=entry_point,
                vector_entry_point=VECTOR_ENTRY_POINTS[entry_point],
                kwargs=dict(kwargs),
                max_episode_steps=None,
                disable_env_checker=False,
            )


def __getattr__(name: str) -> Any:
    """Lazy access to the env class and wrappers (``import sfw_gym`` stays light)."""
    if name == "SfWExploreEnv":
        from sfw_gym.envs.explore import SfWExploreEnv

        return SfWExploreEnv
    if name == "SfWGoalsEnv":
        from sfw_gym.envs.goals import SfWGoalsEnv

        return SfWGoalsEnv
    if name == "SfWRegionsEnv":
        from sfw_gym.envs.regions import SfWRegionsEnv

        return SfWRegionsEnv
    if name == "RobotViewInInfo":
        from sfw_gym.envs.robot_view_info import RobotViewInInfo

        return RobotViewInInfo
    if name == "WaypointWrapper":
        from sfw_gym.envs.waypoint import WaypointWrapper

        return WaypointWrapper
    if name == "ActionRepeat":
        from sfw_gym.envs.action_repeat import ActionRepeat

        return ActionRepeat
    raise AttributeError(name)

"""Oracles: privileged explorers that read the ground truth, to measure the benchmark's ceiling.

An oracle is an :class:`~sfw_gym.agents.base.Agent` whose class sets ``privileged = True`` and
whose registered name starts with ``oracle-``. Besides the robot's view it reads the episode's
ground truth (``env.unwrapped.ground_truth()``: the true plan, pose and radio), so it needs the
env itself at :meth:`OracleAgent.reset`, never only a step's info. Oracles are never a default:
the evaluation, the benchmark and the demo run one only when it is named, and no learned agent
reads one at test time. Their rows tell how much there is to win, not what a robot could do.
"""

from __future__ import annotations

from typing import Any, ClassVar

from sfw_gym.agents.base import Agent
from sfw_gym.core.errors import ConfigError
from sfw_gym.envs.episode import GroundTruth

#: The prefix of every oracle's registered name.
ORACLE_PREFIX = "oracle-"


class OracleAgent(Agent):
    """Base class of the oracles: an agent that may read the ground truth (privileged)."""

    privileged: ClassVar[bool] = True

    def reset(
        self, env: Any = None, seed: int | None = None, *, info: dict[str, Any] | None = None
    ) -> None:
        """Start an episode on ``env`` (required: an oracle reads its ground truth)."""
        sfw = getattr(env, "unwrapped", env)
        if env is None or info is not None or not callable(getattr(sfw, "ground_truth", None)):
            raise ConfigError(
                f"{type(self).__name__} is an oracle: reset it with the SfW env itself (it reads "
                "env.unwrapped.ground_truth()), not with a step's info"
            )
        self._env = sfw
        super().reset(env, seed)

    def ground_truth(self) -> GroundTruth:
        """The episode's ground truth now (true plan, pose, radio)."""
        return self._env.ground_truth()

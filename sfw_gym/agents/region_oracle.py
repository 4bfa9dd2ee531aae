"""The region oracle: region decisions chosen by look-ahead on a copy of the true env.

Privileged (:mod:`sfw_gym.agents.oracles`): it reads the episode's true state, not only the
robot's view. It decides exactly when and as the region teacher (:class:`RegionAgent`, the
decisions of ``SfW-ExploreRegions-v0``), but at each decision it simulates the top ``candidates``
regions of the teacher's ranking on a deep copy of the env and of its own steering: that region
for one decision, then ``horizon_decisions - 1`` decisions of the teacher. The true plan, pose,
radio and even the sensor noise (the env's generator is copied) are the model, so a simulation
is exactly what the real env would do. It takes the region whose simulation scored best (ties:
the teacher's ranking) and steers there as the teacher would; the next decision searches again
(a receding horizon).

The budget is deterministic: at most ``candidates * horizon_decisions * decision_steps``
simulated steps a decision. ``time_limit_s`` (off by default) stops starting new simulations
once a decision has spent that long; then the choices depend on the machine's speed.

The defaults (3 candidates, 6 decisions, scored by bits) simulate ~350 steps a decision, ~55 s
a 3,000-step ``SfW-Explore-v0`` episode on one shared core. On the four benchmark-v1 test seeds
they reached 1.12x frontier's coverage and 1.11x its bits per metre; 4 x 4 reached 1.04x /
1.06x, 6 x 3 1.09x / 1.07x and 3 x 10 (twice the cost) 1.12x / 1.13x: the horizon matters more
than the candidates, and little past 6 decisions. Scored by bits per metre, 3 x 6 reached 1.09x
coverage and 1.15x bits per metre, but fell below frontier on one seed; scored by bits it beat
frontier on both on every seed.
"""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from sfw_gym.agents.base import RobotView
from sfw_gym.agents.oracles import OracleAgent
from sfw_gym.agents.regions import RegionAgent, RegionAgentSettings
from sfw_gym.core.config import setting
from sfw_gym.envs.goals import menu_observation
from sfw_gym.envs.regions import region_anchor
from sfw_gym.navigation.menu import GREEDY_OFFSET_M, CandidateGoals, bits_per_metre

#: What a simulation is scored by (see :class:`RegionOracleSettings`).
SCORES = ("bits", "bits_per_metre", "coverage")


@dataclass(frozen=True)
class RegionOracleSettings(RegionAgentSettings):
    """The parameters of :class:`RegionOracle` (besides the region teacher's).

    Attributes:
        candidates: M: how many regions of the teacher's ranking are simulated each decision
            (its own choice first, then the other valid ones by expected bits per metre).
        horizon_decisions: H: decisions a simulation lasts (the candidate's, then the
            teacher's), ``decision_steps`` steps each.
        score: What ranks the simulations: ``bits`` (the map's entropy lost over the
            simulation), ``bits_per_metre`` (that, ÷ (metres driven + ``distance_offset_m``))
            or ``coverage`` (the coverage gained).
        distance_offset_m: Added to the metres of ``bits_per_metre``.
        time_limit_s: Optional wall-clock limit of one decision's search: no simulation
            starts after it (the first always runs). None (the default): the choices do not
            depend on the machine's speed.
    """

    candidates: int = setting(3, integer=True, ge=1)
    horizon_decisions: int = setting(6, integer=True, ge=1)
    score: str = setting("bits", choices=SCORES)
    distance_offset_m: float = setting(1.0, ge=0.0)
    time_limit_s: float | None = setting(None, gt=0.0, optional=True)


class RegionOracle(OracleAgent, RegionAgent):
    """Region decisions by look-ahead on a copy of the true env (privileged).

    Parameters: :class:`RegionOracleSettings` (keyword arguments, checked).

    Attributes:
        last_scores: The latest search's score per simulated candidate index (empty when the
            menu left no choice).
        simulated_steps: Env steps simulated this episode.
        search_seconds: Wall-clock seconds spent searching this episode.
    """

    name = "oracle-regions"

    settings_class = RegionOracleSettings
    settings: RegionOracleSettings

    def _on_reset(self, view: RobotView) -> None:
        super()._on_reset(view)
        self.last_scores: dict[int, float] = {}
        self.simulated_steps = 0
        self.search_seconds = 0.0

    def teacher_choice(
        self, view: RobotView, obs: Any, menu: CandidateGoals, extra: dict[str, np.ndarray]
    ) -> int:
        """The region teacher's choice (:meth:`RegionAgent.choose`)."""
        return RegionAgent.choose(self, view, obs, menu, extra)

    def ranking(self, menu: CandidateGoals, teacher: int) -> list[int]:
        """The candidates simulated, best first: the teacher's choice, then the other valid
        candidates by expected bits per metre (the greedy teacher's score), at most
        ``candidates``."""
        score = bits_per_metre(menu, GREEDY_OFFSET_M)
        others = [
            int(i) for i in np.argsort(-score, kind="stable") if menu.valid[i] and i != teacher
        ]
        return [teacher, *others][: self.settings.candidates]

    def choose(
        self, view: RobotView, obs: Any, menu: CandidateGoals, extra: dict[str, np.ndarray]
    ) -> int:
        """The candidate whose simulation scores best (see the module's docstring)."""
        teacher = self.teacher_choice(view, obs, menu, extra)
        self.last_scores = {}
        ranked = self.ranking(menu, teacher)
        if len(ranked) < 2:
            return teacher  # nothing to compare
        start = time.perf_counter()
        limit = self.settings.time_limit_s
        for i in ranked:
            if limit is not None and self.last_scores and time.perf_counter() - start > limit:
                break
            self.last_scores[i] = self.simulate(menu, i)
        self.search_seconds += time.perf_counter() - start
        best = max(self.last_scores.values())
        return next(i for i in ranked if self.last_scores.get(i) == best)

    def simulate(self, menu: CandidateGoals, choice: int) -> float:
        """The score of choosing ``choice`` of ``menu`` now, then the teacher's choices, for
        ``horizon_decisions`` decisions in all, on a deep copy of the env and of this agent's
        steering (neither the real env nor this agent's state changes)."""
        cfg, s = self.config, self.settings
        env, finder, steering = copy.deepcopy((self._env, self.finder, self.steering))
        entropy0, metres0 = env.mapper.entropy_bits, env.path_length_m
        coverage_before = env.tracker.metrics()["coverage"] if s.score == "coverage" else 0.0
        info: dict[str, Any] = {}
        steps, decisions = self.steps, 1
        max_steps = s.max_steps if s.max_steps is not None else np.inf
        steering.start(region_anchor(menu, choice), cfg.decision_steps)
        while steps < max_steps:
            view = env.robot_view()
            command = steering.command(view, steps)
            if command is None:  # the decision's steps are spent: the teacher's next one
                if decisions >= s.horizon_decisions:
                    break
                finder.set_step(steps)
                m, extra = menu_observation(finder, view, cfg.max_candidates)
                steering.start(
                    region_anchor(m, self.teacher_choice(view, None, m, extra)), cfg.decision_steps
                )
                decisions += 1
                command = steering.command(view, steps)
                assert command is not None
            _, _, terminated, truncated, info = env.step(self._to_action(*command))
            steps += 1
            self.simulated_steps += 1
            if terminated or truncated:
                break
        if not info:
            return 0.0
        bits = entropy0 - info["entropy_bits"]
        if s.score == "bits_per_metre":
            return bits / (info["path_length_m"] - metres0 + s.distance_offset_m)
        if s.score == "coverage":
            return float(info["coverage"] - coverage_before)
        return float(bits)

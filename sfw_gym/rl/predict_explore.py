"""The agents that read the learned map predictor
(:class:`~sfw_gym.rl.map_predictor.LearnedMapPredictor`, shipped in the package; a folder of
one's own with ``path``): ``predict-explore``
(:class:`~sfw_gym.agents.predict_explore.PredictiveExplorer`), ``rollout-explore`` and the
rollout oracle (:mod:`sfw_gym.agents.rollout_explore`)."""

from __future__ import annotations

from dataclasses import dataclass

from sfw_gym.agents.predict_explore import (
    BASELINE_PREDICTORS,
    PredictExploreSettings,
    PredictiveExplorer,
)
from sfw_gym.agents.rollout_explore import (
    RolloutExplorer,
    RolloutExploreSettings,
    RolloutOracle,
    RolloutOracleSettings,
)
from sfw_gym.core.config import setting
from sfw_gym.navigation.prediction import MapPredictor
from sfw_gym.rl.map_predictor import LearnedMapPredictor


@dataclass(frozen=True)
class LearnedPredictorSettings:
    """The learned predictor's settings, mixed into each agent's own.

    Attributes:
        predictor: ``"learned"`` (default), or a predictor that learns nothing.
        path: The predictor's folder (``model.pt``, ``config.json``; default: the shipped one).
    """

    predictor: str = setting("learned", choices=("learned", *BASELINE_PREDICTORS))
    path: str = ""

    def validate(self) -> None:
        object.__setattr__(self, "path", str(self.path))


class LearnedPredictorMixin:
    """``make_predictor`` of an agent whose settings mix in :class:`LearnedPredictorSettings`."""

    settings: LearnedPredictorSettings

    def make_predictor(self) -> MapPredictor:
        if self.settings.predictor == "learned":
            return LearnedMapPredictor(self.settings.path or None)
        return super().make_predictor()  # type: ignore[misc]


@dataclass(frozen=True)
class LearnedPredictExploreSettings(LearnedPredictorSettings, PredictExploreSettings):
    """:class:`PredictExploreSettings` with the learned predictor."""


class PredictExploreAgent(LearnedPredictorMixin, PredictiveExplorer):
    """Greedy bits per metre on the learned predictor's map (see
    :mod:`sfw_gym.agents.predict_explore`)."""

    name = "predict-explore"

    settings_class = LearnedPredictExploreSettings
    settings: LearnedPredictExploreSettings


@dataclass(frozen=True)
class LearnedRolloutExploreSettings(LearnedPredictorSettings, RolloutExploreSettings):
    """:class:`~sfw_gym.agents.rollout_explore.RolloutExploreSettings` with the learned
    predictor."""


class RolloutExploreAgent(LearnedPredictorMixin, RolloutExplorer):
    """Predict-explore's menu re-ranked by the dry-run rate of each path, on the learned
    predictor's map (see :mod:`sfw_gym.agents.rollout_explore`)."""

    name = "rollout-explore"

    settings_class = LearnedRolloutExploreSettings
    settings: LearnedRolloutExploreSettings


@dataclass(frozen=True)
class LearnedRolloutOracleSettings(LearnedPredictorSettings, RolloutOracleSettings):
    """:class:`~sfw_gym.agents.rollout_explore.RolloutOracleSettings` with the learned
    predictor: ``rollout-explore``'s own menu."""


class RolloutOracleAgent(LearnedPredictorMixin, RolloutOracle):
    """The rollout oracle on ``rollout-explore``'s menu (privileged; see
    :mod:`sfw_gym.agents.rollout_explore`)."""

    name = "oracle-rollout"

    settings_class = LearnedRolloutOracleSettings
    settings: LearnedRolloutOracleSettings

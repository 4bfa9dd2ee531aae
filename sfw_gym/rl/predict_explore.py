"""``predict-explore``: :class:`~sfw_gym.agents.predict_explore.PredictiveExplorer` reading the
learned map predictor (:class:`~sfw_gym.rl.map_predictor.LearnedMapPredictor`, shipped in the
package; a folder of one's own with ``path``)."""

from __future__ import annotations

from dataclasses import dataclass

from sfw_gym.agents.predict_explore import (
    BASELINE_PREDICTORS,
    PredictExploreSettings,
    PredictiveExplorer,
)
from sfw_gym.agents.rollout_explore import RolloutExplorer, RolloutExploreSettings
from sfw_gym.core.config import setting
from sfw_gym.navigation.prediction import MapPredictor
from sfw_gym.rl.map_predictor import LearnedMapPredictor


@dataclass(frozen=True)
class LearnedPredictExploreSettings(PredictExploreSettings):
    """:class:`PredictExploreSettings` with the learned predictor.

    Attributes:
        path: The predictor's folder (``model.pt``, ``config.json``; default: the shipped one).
    """

    predictor: str = setting("learned", choices=("learned", *BASELINE_PREDICTORS))
    path: str = ""

    def validate(self) -> None:
        object.__setattr__(self, "path", str(self.path))


class PredictExploreAgent(PredictiveExplorer):
    """Greedy bits per metre on the learned predictor's map (see
    :mod:`sfw_gym.agents.predict_explore`)."""

    name = "predict-explore"

    settings_class = LearnedPredictExploreSettings
    settings: LearnedPredictExploreSettings

    def make_predictor(self) -> MapPredictor:
        if self.settings.predictor == "learned":
            return LearnedMapPredictor(self.settings.path or None)
        return super().make_predictor()


@dataclass(frozen=True)
class LearnedRolloutExploreSettings(RolloutExploreSettings):
    """:class:`~sfw_gym.agents.rollout_explore.RolloutExploreSettings` with the learned
    predictor (``path`` as :class:`LearnedPredictExploreSettings`)."""

    predictor: str = setting("learned", choices=("learned", *BASELINE_PREDICTORS))
    path: str = ""

    def validate(self) -> None:
        object.__setattr__(self, "path", str(self.path))


class RolloutExploreAgent(RolloutExplorer):
    """Predict-explore's menu re-ranked by the dry-run rate of each path, on the learned
    predictor's map (see :mod:`sfw_gym.agents.rollout_explore`)."""

    name = "rollout-explore"

    settings_class = LearnedRolloutExploreSettings
    settings: LearnedRolloutExploreSettings

    def make_predictor(self) -> MapPredictor:
        if self.settings.predictor == "learned":
            return LearnedMapPredictor(self.settings.path or None)
        return super().make_predictor()

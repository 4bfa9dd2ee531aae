"""Evaluation: run agents paired on the same plans and seeds, summarise with 95 % confidence
intervals, write the results table and figures (``sfw-gym evaluate``, :func:`evaluate`)."""

from __future__ import annotations

from sfw_gym.evaluation.report import paired_markdown, results_csv, results_markdown
from sfw_gym.evaluation.runner import (
    CHECKPOINT,
    EpisodeSpec,
    evaluate,
    load_checkpoint,
    run_episode,
    zone_band_unknown,
)
from sfw_gym.evaluation.stats import (
    PAIRED_METRICS,
    TABLE_METRICS,
    mean_ci95,
    paired_differences,
    summarize,
)

__all__ = [
    "CHECKPOINT",
    "PAIRED_METRICS",
    "TABLE_METRICS",
    "EpisodeSpec",
    "evaluate",
    "load_checkpoint",
    "mean_ci95",
    "paired_differences",
    "paired_markdown",
    "results_csv",
    "results_markdown",
    "run_episode",
    "summarize",
    "zone_band_unknown",
]

"""Evaluation: run agents paired on the same plans and seeds, summarise with 95 % confidence
intervals, write the results table and figures (``sfw-gym evaluate``, :func:`evaluate`).

One job a module: :mod:`~.rollout` (one episode → its record), :mod:`~.checkpoint` (the run
folder's checkpoint and manifests), :mod:`~.executor` (where jobs run: this process, local worker
processes or Ray), :mod:`~.stats` (intervals and the paired comparison), :mod:`~.metric_table`
(labels, formats and directions), :mod:`~.report` and :mod:`~.plots` (tables and figures),
:mod:`~.runner` (``evaluate``), :mod:`~.benchmark` (the protocol) and
:mod:`~.localization` (the localisation study).
"""

from __future__ import annotations

from sfw_gym.evaluation.checkpoint import CHECKPOINT, load_checkpoint
from sfw_gym.evaluation.executor import Executor
from sfw_gym.evaluation.metric_table import METRICS, PAIRED_METRICS, TABLE_METRICS
from sfw_gym.evaluation.report import paired_markdown, results_csv, results_markdown
from sfw_gym.evaluation.rollout import EpisodeSpec, run_episode, zone_band_unknown
from sfw_gym.evaluation.runner import evaluate
from sfw_gym.evaluation.stats import (
    compare_paired,
    mean_ci95,
    paired_comparison,
    paired_differences,
    summarize,
)

__all__ = [
    "CHECKPOINT",
    "METRICS",
    "PAIRED_METRICS",
    "TABLE_METRICS",
    "EpisodeSpec",
    "Executor",
    "compare_paired",
    "evaluate",
    "load_checkpoint",
    "mean_ci95",
    "paired_comparison",
    "paired_differences",
    "paired_markdown",
    "results_csv",
    "results_markdown",
    "run_episode",
    "summarize",
    "zone_band_unknown",
]

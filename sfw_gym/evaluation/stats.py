"""Statistics over episode records: means with 95 % confidence intervals, per agent."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

#: Metrics of the results table: (record key, column label, format).
TABLE_METRICS: tuple[tuple[str, str, str], ...] = (
    ("coverage", "coverage", "{:.3f}"),
    ("map_iou", "IoU", "{:.3f}"),
    ("free_iou", "free IoU", "{:.3f}"),
    ("k_accuracy", "k-accuracy", "{:.3f}"),
    ("path_length_m", "path [m]", "{:.0f}"),
    ("info_gain_per_m", "info gain [bits/m]", "{:.0f}"),
    ("collisions", "collisions", "{:.0f}"),
    ("steps_to_coverage_50", "steps to 50 %", "{:.0f}"),
    ("steps_to_coverage_90", "steps to 90 %", "{:.0f}"),
    ("zone_band_unknown", "unknown zone-band cells", "{:.0f}"),
    ("zone_band_unknown_frac", "unknown zone-band fraction", "{:.3f}"),
)
#: Metrics of the paired table (agent − reference on the same plans and seeds).
PAIRED_METRICS: tuple[tuple[str, str, str], ...] = (
    ("coverage", "Δ coverage", "{:+.3f}"),
    ("info_gain_per_m", "Δ bits/m", "{:+.1f}"),
    ("path_length_m", "Δ path [m]", "{:+.0f}"),
    ("free_iou", "Δ free IoU", "{:+.3f}"),
    ("wall_precision", "Δ wall precision", "{:+.3f}"),
)
#: "steps to x %" metrics are averaged over the episodes that got there (count reported).
REACHED_METRICS = ("steps_to_coverage_50", "steps_to_coverage_90")


def ci95_half_width(samples: np.ndarray) -> np.ndarray | float:
    """Half-width of the 95 % confidence interval (Student t) of the mean of ``samples`` along
    its first axis (n ≥ 2): the one t-interval of the package and its scripts."""
    from scipy import stats

    a = np.asarray(samples, np.float64)
    return stats.t.ppf(0.975, len(a) - 1) * a.std(axis=0, ddof=1) / math.sqrt(len(a))


def mean_ci95(values: Sequence[float]) -> tuple[float, float, int]:
    """Mean, half-width of its 95 % confidence interval (Student t), and n (nan if n = 0)."""
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], np.float64)
    if len(v) == 0:
        return math.nan, math.nan, 0
    if len(v) == 1:
        return float(v[0]), math.nan, 1
    return float(v.mean()), float(ci95_half_width(v)), len(v)


def mean_ci95_text(values: Sequence[float], fmt: str = "{:.2f}") -> str:
    """``mean [low, high]`` of :func:`mean_ci95`, each number in ``fmt``."""
    mean, half, _ = mean_ci95(values)
    return f"{fmt.format(mean)} [{fmt.format(mean - half)}, {fmt.format(mean + half)}]"


def summarize(records: list[dict[str, Any]], agents: Sequence[str]) -> list[dict[str, Any]]:
    """Per agent: mean, 95 % CI and n of each table metric, and episode counts."""
    rows = []
    for name in agents:
        recs = [r for r in records if r["agent"] == name]
        row: dict[str, Any] = {"agent": name, "episodes": len(recs)}
        for key, _, _ in TABLE_METRICS:
            vals = [r.get(key) for r in recs]
            if key in REACHED_METRICS:
                vals = [v for v in vals if v is not None and v >= 0]
            mean, ci, n = mean_ci95([v for v in vals if v is not None])
            row[f"{key}_mean"], row[f"{key}_ci95"], row[f"{key}_n"] = mean, ci, n
        cov = [r.get("coverage", 0.0) for r in recs]
        row["episodes_coverage_ge_90"] = int(sum(c >= 0.9 for c in cov))
        row["episodes_coverage_ge_80"] = int(sum(c >= 0.8 for c in cov))
        reasons: dict[str, int] = {}
        for r in recs:
            reasons[r["stop_reason"]] = reasons.get(r["stop_reason"], 0) + 1
        row["stop_reasons"] = ";".join(f"{k}:{v}" for k, v in sorted(reasons.items()))
        rows.append(row)
    return rows


def paired_differences(
    records: list[dict[str, Any]], agents: Sequence[str], reference: str
) -> list[dict[str, Any]]:
    """Per agent other than ``reference``: mean, 95 % CI and n of (agent − reference) for each
    paired metric, over the episodes both ran (episode ``i``: the same plan and seed)."""
    by_episode = {(r["agent"], r["episode"]): r for r in records}
    rows = []
    for name in agents:
        if name == reference:
            continue
        pairs = [
            (rec, by_episode[(reference, episode)])
            for (agent, episode), rec in sorted(by_episode.items())
            if agent == name and (reference, episode) in by_episode
        ]
        row: dict[str, Any] = {"agent": name, "reference": reference, "pairs": len(pairs)}
        for key, _, _ in PAIRED_METRICS:
            values = [(a.get(key), b.get(key)) for a, b in pairs]
            diffs = [x - y for x, y in values if x is not None and y is not None]
            mean, ci, n = mean_ci95(diffs)
            row[f"{key}_diff"], row[f"{key}_ci95"], row[f"{key}_n"] = mean, ci, n
        rows.append(row)
    return rows

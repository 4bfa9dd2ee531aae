"""Statistics over episode records: means with 95 % confidence intervals (Student t) per agent,
bootstrap intervals of a mean, and the one paired comparison (the mean difference over paired
episodes with a seeded bootstrap interval) that evaluate, the benchmark and the scripts use."""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from sfw_gym.evaluation.metric_table import (
    HIGHER,
    LOWER,
    PAIRED_METRICS,
    REACHED_METRICS,
    TABLE_METRICS,
)

#: The bootstrap of every interval that is not a Student t (the benchmark protocol's
#: ``intervals`` block gives its own; benchmark-v1's are these): confidence level, resamples
#: and the seed of the resampling (the same numbers on every run).
BOOTSTRAP: dict[str, Any] = {"confidence": 0.95, "resamples": 10_000, "random_state": 0}


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
        row: dict[str, Any] = {
            "agent": name,
            "episodes": len(recs),
            "privileged": any(r.get("privileged", False) for r in recs),
        }
        for m in TABLE_METRICS:
            vals = [r.get(m.key) for r in recs]
            if m.key in REACHED_METRICS:
                vals = [v for v in vals if v is not None and v >= 0]
            mean, ci, n = mean_ci95([v for v in vals if v is not None])
            row[f"{m.key}_mean"], row[f"{m.key}_ci95"], row[f"{m.key}_n"] = mean, ci, n
        cov = [r.get("coverage", 0.0) for r in recs]
        row["episodes_coverage_ge_90"] = int(sum(c >= 0.9 for c in cov))
        row["episodes_coverage_ge_80"] = int(sum(c >= 0.8 for c in cov))
        reasons: dict[str, int] = {}
        for r in recs:
            reasons[r["stop_reason"]] = reasons.get(r["stop_reason"], 0) + 1
        row["stop_reasons"] = ";".join(f"{k}:{v}" for k, v in sorted(reasons.items()))
        rows.append(row)
    return rows


# ---------------------------------------------------------------------------------- bootstrap
def bootstrap_ci(
    values: Sequence[float] | np.ndarray,
    *,
    confidence: float = BOOTSTRAP["confidence"],
    resamples: int = BOOTSTRAP["resamples"],
    random_state: int = BOOTSTRAP["random_state"],
) -> tuple[float, float]:
    """The percentile-bootstrap interval of the mean of ``values`` (scipy.stats.bootstrap,
    seeded: the same interval every time); fewer than two values or equal values: the mean."""
    v = np.asarray(values, np.float64)
    if len(v) < 2 or np.ptp(v) == 0:
        mean = float(np.mean(v)) if len(v) else math.nan
        return mean, mean
    return _bootstrap((v,), np.mean, confidence, resamples, random_state)


def _ratio_of_means(a: np.ndarray, b: np.ndarray, axis: int = -1) -> np.ndarray:
    return np.mean(b, axis=axis) / np.mean(a, axis=axis)


def _bootstrap(
    samples: tuple[np.ndarray, ...],
    statistic: Callable[..., Any],
    confidence: float,
    resamples: int,
    random_state: int,
) -> tuple[float, float]:
    """scipy's seeded percentile bootstrap of ``statistic``; two samples are resampled as
    pairs (the same indices on both sides)."""
    from scipy import stats

    res = stats.bootstrap(
        samples,
        statistic,
        paired=len(samples) > 1,
        confidence_level=float(confidence),
        n_resamples=int(resamples),
        method="percentile",
        random_state=np.random.default_rng(int(random_state)),
    )
    return float(res.confidence_interval.low), float(res.confidence_interval.high)


# ---------------------------------------------------------------------------------- pairing
@dataclass(frozen=True)
class PairedDifference:
    """One metric compared over paired episodes: ``b − a`` (or ``b ÷ a``).

    Attributes:
        metric: The record key.
        n: Pairs where both values are finite.
        mean_a, mean_b: The two sides' means over those pairs.
        mean: Mean of the differences ``b − a``; with ``ratio``, the ratio of the means
            ``mean_b / mean_a``.
        low, high: Its seeded bootstrap interval (resampling the pairs).
        ratio: Whether ``mean`` is a ratio (no difference: 1) or a difference (no difference: 0).
    """

    metric: str
    n: int
    mean_a: float
    mean_b: float
    mean: float
    low: float
    high: float
    ratio: bool = False

    def text(self, fmt: str = "{:+.2f}") -> str:
        """``mean [low, high]``, each number in ``fmt``."""
        return f"{fmt.format(self.mean)} [{fmt.format(self.low)}, {fmt.format(self.high)}]"

    def resolved(self, direction: int) -> str:
        """Where the interval leaves out "no difference" (0, or 1 for a ratio; n ≥ 2):
        ``"better"``/``"worse"`` for b, by the metric's direction
        (:mod:`~sfw_gym.evaluation.metric_table`), or ``"higher"``/``"lower"`` where neither
        way is better; ``""`` where it holds it."""
        same = 1.0 if self.ratio else 0.0
        if self.n < 2 or self.low <= same <= self.high:
            return ""
        up = self.low > same
        if direction in (HIGHER, LOWER):
            return "better" if up == (direction == HIGHER) else "worse"
        return "higher" if up else "lower"


def _finite(x: Any) -> bool:
    return x is not None and math.isfinite(float(x))


def compare_paired(
    a: Sequence[float | None] | np.ndarray,
    b: Sequence[float | None] | np.ndarray,
    *,
    metric: str = "",
    ratio: bool = False,
    **intervals: Any,
) -> PairedDifference:
    """The paired comparison: ``a[i]`` and ``b[i]`` are one episode's values on either side
    (the same plan and seed); pairs with a missing or non-finite value are left out. The mean of
    ``b − a`` with its bootstrap interval (``intervals``: :func:`bootstrap_ci`'s keywords), or
    with ``ratio`` the ratio of the means ``mean(b) / mean(a)`` with a paired bootstrap interval
    (the pairs resampled together)."""
    if len(a) != len(b):
        raise ValueError(f"compare_paired: {len(a)} values against {len(b)}")
    both = np.array(
        [(x, y) for x, y in zip(a, b, strict=True) if _finite(x) and _finite(y)], np.float64
    )
    if not len(both):
        return PairedDifference(metric, 0, *(math.nan,) * 5, ratio=ratio)
    x, y = both[:, 0], both[:, 1]
    if not ratio:
        low, high = bootstrap_ci(y - x, **intervals)
        stat = float((y - x).mean())
    else:
        stat = float(y.mean() / x.mean())
        low = high = stat
        if len(x) >= 2 and np.ptp(y * x.mean() - x * y.mean()) > 0:  # not every pair alike
            settings = {**BOOTSTRAP, **intervals}
            low, high = _bootstrap(
                (x, y),
                _ratio_of_means,
                settings["confidence"],
                settings["resamples"],
                settings["random_state"],
            )
    return PairedDifference(
        metric, len(x), float(x.mean()), float(y.mean()), stat, low, high, ratio=ratio
    )


def paired_comparison(
    pairs: Sequence[tuple[Mapping[str, Any], Mapping[str, Any]]],
    metrics: Sequence[str],
    **intervals: Any,
) -> list[PairedDifference]:
    """:func:`compare_paired` of each metric over ``pairs`` of records ``(a, b)``."""
    return [
        compare_paired(
            [x.get(key) for x, _ in pairs], [y.get(key) for _, y in pairs], metric=key, **intervals
        )
        for key in metrics
    ]


def paired_differences(
    records: list[dict[str, Any]], agents: Sequence[str], reference: str, **intervals: Any
) -> list[dict[str, Any]]:
    """Per agent other than ``reference``: the paired comparison (agent − reference) of each
    paired-table metric over the episodes both ran (episode ``i``: the same plan and seed).

    Returns:
        Rows ``{"agent", "reference", "pairs", "differences": [PairedDifference, ...]}``.
    """
    by_episode = {(r["agent"], r["episode"]): r for r in records}
    rows = []
    for name in agents:
        if name == reference:
            continue
        pairs = [
            (by_episode[(reference, episode)], rec)
            for (agent, episode), rec in sorted(by_episode.items())
            if agent == name and (reference, episode) in by_episode
        ]
        keys = [m.key for m in PAIRED_METRICS]
        rows.append(
            {
                "agent": name,
                "reference": reference,
                "pairs": len(pairs),
                "differences": paired_comparison(pairs, keys, **intervals),
            }
        )
    return rows

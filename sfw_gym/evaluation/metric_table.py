"""The one table of reported metrics: each record key's column label, number format and which
way is better, for every table the package and its scripts print (evaluate's results and paired
tables, the benchmark's results and comparisons, the demo's report)."""

from __future__ import annotations

from dataclasses import dataclass

#: Directions: higher is better, lower is better, neither (e.g. a path length: shorter is
#: cheaper, but an agent that stops early drives less too).
HIGHER, LOWER, NEITHER = 1, -1, 0


@dataclass(frozen=True)
class Metric:
    """How a metric is shown.

    Attributes:
        key: The episode record's key.
        label: Column label (with its unit).
        fmt: Number format, e.g. ``"{:.3f}"``.
        direction: :data:`HIGHER`, :data:`LOWER` or :data:`NEITHER` is better.
    """

    key: str
    label: str
    fmt: str
    direction: int

    def format(self, value: float) -> str:
        """``value`` in the metric's format."""
        return self.fmt.format(value)

    def format_signed(self, value: float) -> str:
        """``value`` in the metric's format with its sign (a difference)."""
        return self.fmt.replace("{:", "{:+").format(value)


METRICS: dict[str, Metric] = {
    m.key: m
    for m in (
        Metric("coverage", "coverage", "{:.3f}", HIGHER),
        Metric("map_iou", "IoU", "{:.3f}", HIGHER),
        Metric("free_iou", "free IoU", "{:.3f}", HIGHER),
        Metric("k_accuracy", "k-accuracy", "{:.3f}", HIGHER),
        Metric("wall_precision", "wall precision", "{:.3f}", HIGHER),
        Metric("interior_wall_recall", "wall recall", "{:.3f}", HIGHER),
        Metric("path_length_m", "path [m]", "{:.0f}", NEITHER),
        Metric("info_gain_per_m", "info gain [bits/m]", "{:.1f}", HIGHER),
        Metric("collisions", "collisions", "{:.0f}", LOWER),
        Metric("steps_to_coverage_50", "steps to 50 %", "{:.0f}", LOWER),
        Metric("steps_to_coverage_90", "steps to 90 %", "{:.0f}", LOWER),
        Metric("zone_band_unknown", "unknown zone-band cells", "{:.0f}", LOWER),
        Metric("zone_band_unknown_frac", "unknown zone-band fraction", "{:.3f}", LOWER),
        Metric("ate_m", "ATE [m]", "{:.2f}", LOWER),
        Metric("wall_s", "wall time [s]", "{:.1f}", LOWER),
    )
}

#: Columns of evaluate's results table.
TABLE_METRICS: tuple[Metric, ...] = tuple(
    METRICS[key]
    for key in (
        "coverage",
        "map_iou",
        "free_iou",
        "k_accuracy",
        "path_length_m",
        "info_gain_per_m",
        "collisions",
        "steps_to_coverage_50",
        "steps_to_coverage_90",
        "zone_band_unknown",
        "zone_band_unknown_frac",
    )
)
#: Metrics of evaluate's paired table (agent − reference on the same plans and seeds).
PAIRED_METRICS: tuple[Metric, ...] = tuple(
    METRICS[key]
    for key in ("coverage", "info_gain_per_m", "path_length_m", "free_iou", "wall_precision")
)
#: "steps to x %" metrics are averaged over the episodes that got there (count reported).
REACHED_METRICS = ("steps_to_coverage_50", "steps_to_coverage_90")

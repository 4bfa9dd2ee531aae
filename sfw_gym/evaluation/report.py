"""The tables of an evaluation as text: the results table (CSV and Markdown) and the paired
table that every paired comparison prints (evaluate, ``benchmark compare``, the scripts)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

from sfw_gym.evaluation.metric_table import (
    METRICS,
    NEITHER,
    REACHED_METRICS,
    TABLE_METRICS,
    Metric,
)
from sfw_gym.evaluation.stats import PairedDifference


def results_csv(rows: list[dict[str, Any]]) -> str:
    """The summary rows as CSV text."""
    import csv
    import io

    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]) if rows else ["agent"])
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
    return buf.getvalue()


#: Under every table with an oracle's row (a privileged agent, marked †).
PRIVILEGED_NOTE = (
    "† privileged: an oracle that reads the ground truth (the true plan and pose); a ceiling "
    "for comparison, not a result a robot could reach."
)


def agent_label(name: str, privileged: bool) -> str:
    """An agent's name in a table: an oracle's marked † (:data:`PRIVILEGED_NOTE`)."""
    return f"{name} †" if privileged else name


def results_markdown(rows: list[dict[str, Any]]) -> str:
    """The summary rows as a Markdown table (mean ± 95 % CI); oracles' rows marked †."""
    head = ["agent", "episodes"] + [m.label for m in TABLE_METRICS] + ["≥ 90 % cov."]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [agent_label(row["agent"], row.get("privileged", False)), str(row["episodes"])]
        for m in TABLE_METRICS:
            mean, ci, n = row[f"{m.key}_mean"], row[f"{m.key}_ci95"], row[f"{m.key}_n"]
            if n == 0:
                cell = "–"
            else:
                cell = m.format(mean) + ("" if math.isnan(ci) else " ± " + m.format(ci))
            if m.key in REACHED_METRICS:
                cell += f" ({n}/{row['episodes']})"
            cells.append(cell)
        cells.append(f"{row['episodes_coverage_ge_90']}/{row['episodes']}")
        lines.append("| " + " | ".join(cells) + " |")
    if any(row.get("privileged") for row in rows):
        lines += ["", PRIVILEGED_NOTE]
    return "\n".join(lines) + "\n"


def paired_table(
    groups: Sequence[tuple[str, Sequence[PairedDifference]]], *, group: str, a: str, b: str
) -> str:
    """Paired comparisons as one Markdown table: a row per group (e.g. an agent pair or an env)
    and metric with pairs, both means, the mean difference ``b − a`` [95 % interval] and where
    the interval leaves out zero, whether b is better or worse (the metric table's direction).
    Metrics no pair holds are left out; one pair shows no interval."""
    lines = [
        f"| {group} | metric | pairs | {a} | {b} | {b} − {a} [95 % CI] | resolved |",
        "|---|---|---:|---:|---:|---:|---|",
    ]
    for name, differences in groups:
        for d in differences:
            if d.n == 0:
                continue
            m = METRICS.get(d.metric) or Metric(d.metric, d.metric, "{:.3g}", NEITHER)
            diff = m.format_signed(d.mean)
            if d.n >= 2:
                diff += f" [{m.format_signed(d.low)}, {m.format_signed(d.high)}]"
            lines.append(
                f"| {name} | {m.label} | {d.n} | {m.format(d.mean_a)} | {m.format(d.mean_b)} "
                f"| {diff} | {d.resolved(m.direction)} |"
            )
    return "\n".join(lines) + "\n"


def paired_markdown(rows: list[dict[str, Any]]) -> str:
    """Evaluate's paired table (rows of :func:`~sfw_gym.evaluation.stats.paired_differences`):
    every other agent against the reference, episode by episode."""
    groups = [(f"{r['agent']} − {r['reference']}", r["differences"]) for r in rows]
    return paired_table(groups, group="agent − reference", a="reference", b="agent")

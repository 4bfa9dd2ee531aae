"""The results table of an evaluation, as CSV and Markdown."""

from __future__ import annotations

import math
from typing import Any

from sfw_gym.evaluation.stats import PAIRED_METRICS, REACHED_METRICS, TABLE_METRICS


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


def results_markdown(rows: list[dict[str, Any]]) -> str:
    """The summary rows as a Markdown table (mean ± 95 % CI)."""
    head = ["agent", "episodes"] + [label for _, label, _ in TABLE_METRICS] + ["≥ 90 % cov."]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [row["agent"], str(row["episodes"])]
        for key, _, fmt in TABLE_METRICS:
            mean, ci, n = row[f"{key}_mean"], row[f"{key}_ci95"], row[f"{key}_n"]
            if n == 0:
                cell = "–"
            else:
                cell = fmt.format(mean) + ("" if math.isnan(ci) else " ± " + fmt.format(ci))
            if key in REACHED_METRICS:
                cell += f" ({n}/{row['episodes']})"
            cells.append(cell)
        cells.append(f"{row['episodes_coverage_ge_90']}/{row['episodes']}")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def paired_markdown(rows: list[dict[str, Any]]) -> str:
    """The paired differences as a Markdown table (mean [95 % CI])."""
    head = ["agent − reference", "pairs"] + [label for _, label, _ in PAIRED_METRICS]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for row in rows:
        cells = [f"{row['agent']} − {row['reference']}", str(row["pairs"])]
        for key, _, fmt in PAIRED_METRICS:
            mean, ci = row[f"{key}_diff"], row[f"{key}_ci95"]
            if math.isnan(mean):
                cells.append("–")
            elif math.isnan(ci):
                cells.append(fmt.format(mean))
            else:
                low, high = fmt.format(mean - ci), fmt.format(mean + ci)
                cells.append(f"{fmt.format(mean)} [{low}, {high}]")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"

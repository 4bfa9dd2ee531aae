"""The tables of an evaluation as text: the results table (CSV and Markdown) and the paired
table that every paired comparison prints (evaluate, ``benchmark compare``, the scripts); and
the report page of a run folder, written once as Markdown and rendered from it to HTML
(:func:`write_report`: ``index.md`` or ``results.md`` with ``index.html`` beside it, for a
browser).
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any
from urllib.parse import quote, urlsplit

from sfw_gym.core.atomic import write_text_atomic
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


# ------------------------------------------------------------------------------ report pages
def report_markdown(
    out: Path,
    rows: list[dict[str, Any]],
    files: Iterable[Path],
    *,
    paired: str = "",
    note: str = "",
) -> list[str]:
    """The body of a run folder's report page (Markdown lines): the results table with ``note``
    under it, links to the run's records, the ``paired`` table if given, then the figures among
    ``files`` (paths under ``out``): the curves, the trajectory overlays and the GIFs."""
    lines = [
        "## Results (mean ± 95 % CI over episodes)",
        "",
        results_markdown(rows).rstrip(),
        "",
        *([note, ""] if note else []),
        "Full table: [results.csv](results.csv); per-episode records: "
        "[episodes.jsonl](episodes.jsonl); the run's settings: [config.json](config.json).",
    ]
    if paired:
        lines += [
            "",
            "## Paired with the first agent, episode by episode",
            "",
            "Mean difference [95 % bootstrap interval] on the same plans and seeds.",
            "",
            paired.rstrip(),
        ]
    figures = [Path(f) for f in files]
    sections = {
        "Curves": [f for f in figures if f.parent == out and f.suffix == ".png"],
        "Trajectories (left: the true plan; right: each agent's final belief map)": [
            f for f in figures if f.parent.name == "trajectories" and f.suffix == ".png"
        ],
        "Animated episodes": [f for f in figures if f.suffix == ".gif"],
    }
    for heading, shown in sections.items():
        if shown:  # relative and quoted links: the folder can move, and any plan name links
            lines += ["", f"## {heading}", ""]
            lines += [f"![{f.stem}]({quote(f.relative_to(out).as_posix())})" for f in shown]
    return lines


#: The report page's stylesheet (inline, so that the page is one file beside its figures).
STYLE = """\
body { font: 15px/1.5 system-ui, sans-serif; max-width: 72rem; margin: 2rem auto;
       padding: 0 1rem; color: #222; }
h1, h2 { font-weight: 600; } h2 { margin-top: 2rem; border-bottom: 1px solid #ddd; }
table { border-collapse: collapse; margin: 1rem 0; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #ccc; padding: 0.25rem 0.6rem; }
th { background: #f3f3f3; } tbody tr:nth-child(even) { background: #fafafa; }
code { background: #f3f3f3; padding: 0 0.2rem; border-radius: 3px; }
img { max-width: 100%; vertical-align: top; margin: 0.25rem; }
"""


def report_html(text: str) -> str:
    """A Markdown report page as a standalone HTML page: the tables, links and images as in the
    Markdown, a small inline stylesheet, its first ``# `` heading as the title. Raw HTML in the
    text (e.g. in an agent or plan name) is shown as text, and links or images that are not
    relative paths are dropped: the page only ever points into its own folder."""
    import markdown
    from markdown.treeprocessors import Treeprocessor

    class _LocalLinksOnly(Treeprocessor):
        def run(self, root: Any) -> None:
            for element in root.iter():
                for attr in ("href", "src"):
                    link = element.get(attr)
                    if link is not None and (urlsplit(link).scheme or link.startswith("/")):
                        del element.attrib[attr]

    md = markdown.Markdown(extensions=["tables"], output_format="html")
    md.preprocessors.deregister("html_block")
    md.inlinePatterns.deregister("html")
    md.treeprocessors.register(_LocalLinksOnly(md), "local_links_only", -1)  # last
    body = md.convert(text)
    heading = next((line[2:] for line in text.splitlines() if line.startswith("# ")), "report")
    title = html.escape(heading.replace("`", "").strip())
    return (
        '<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{title}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n{body}\n"
        "</body>\n</html>\n"
    )


def write_report(path: Path, text: str) -> list[Path]:
    """Write the Markdown report page ``path`` and its HTML rendering, ``index.html`` beside it
    (:func:`report_html`); return both paths."""
    return [
        write_text_atomic(path, text),
        write_text_atomic(path.parent / "index.html", report_html(text)),
    ]

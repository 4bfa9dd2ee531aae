"""The text that evaluate and ``benchmark compare`` print, on hand-made numbers (no episodes):
the Student t interval text, the paired table, and the comparison of two results files."""

from __future__ import annotations

from typing import Any

from sfw_gym.evaluation import benchmark as bm
from sfw_gym.evaluation.report import paired_table, results_markdown
from sfw_gym.evaluation.stats import PairedDifference, mean_ci95_text, summarize


def test_the_interval_text_is_the_mean_and_its_student_t_interval():
    # 1, 2, 3: mean 2, s = 1, t(0.975, 2) = 4.3027: half-width 4.3027 / sqrt(3) = 2.484
    assert mean_ci95_text([1.0, 2.0, 3.0]) == "2.00 [-0.48, 4.48]"
    assert mean_ci95_text([1.0, 2.0, 3.0], "{:.1f}") == "2.0 [-0.5, 4.5]"


def test_one_episode_shows_its_values_without_an_interval_and_no_value_as_a_dash():
    record = {"agent": "b", "coverage": 0.95, "stop_reason": "max_steps"}
    record.update(steps_to_coverage_50=120, steps_to_coverage_90=-1)  # never reached 90 %
    table = results_markdown(summarize([record], ["b"])).splitlines()
    assert table[0].startswith("| agent | episodes | coverage | IoU |")
    # "steps to x %": the mean over the episodes that got there, with their count
    assert (
        table[2] == "| b | 1 | 0.950 | – | – | – | – | – | – | 120 (1/1) | – (0/1) | – | – | 1/1 |"
    )


def test_a_metric_outside_the_metric_table_shows_three_significant_digits():
    d = PairedDifference("bytes_sent", 3, 1234.5, 1300.25, 65.75, 10.125, 120.5)
    text = paired_table([("x", [d])], group="env", a="A", b="B")
    assert text.splitlines() == [
        "| env | metric | pairs | A | B | B − A [95 % CI] | resolved |",
        "|---|---|---:|---:|---:|---:|---|",
        "| x | bytes_sent | 3 | 1.23e+03 | 1.3e+03 | +65.8 [+10.1, +120] | higher |",
    ]
    assert text.endswith("|\n")  # one newline: printed or written as it is


def _results(agent: str, coverage: list[tuple[int, float]]) -> dict[str, Any]:
    """A results file's fields that compare reads, every metric 0 but coverage."""
    protocol = bm.load_protocol("benchmark-v1")
    rows = []
    for seed, value in coverage:
        row = {"env_id": "SfW-Explore-v0", "seed": seed, "floorplan": None, "steps": 10}
        row.update(dict.fromkeys(protocol["metrics"], 0.0), coverage=value)
        rows.append(row)
    return {
        "protocol": protocol["name"],
        "protocol_version": protocol["version"],
        "protocol_sha256": protocol["sha256"],
        "split": "test",
        "agent": agent,
        "episodes": rows,
    }


def test_compare_pairs_the_episodes_both_ran_and_names_both_agents():
    a = _results("A", [(1, 0.5), (2, 0.6), (3, 0.7)])
    b = _results("B", [(1, 0.6), (2, 0.8), (3, 0.75), (4, 0.1)])  # seed 4: only b ran it
    assert bm.compare(a, b).splitlines() == [
        "B − A on benchmark-v1 / test, paired by episode; mean difference [95 % bootstrap"
        " interval].",
        "",
        "| env | metric | pairs | A | B | B − A [95 % CI] | resolved |",
        "|---|---|---:|---:|---:|---:|---|",
        # the metrics that are 0 in every episode are left out
        "| SfW-Explore-v0 | coverage | 3 | 0.600 | 0.717 | +0.117 [+0.050, +0.200] | better |",
    ]

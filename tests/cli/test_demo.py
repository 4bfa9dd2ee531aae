"""``sfw-gym demo``: the main job writes a complete report with the shipped policy."""

from __future__ import annotations

import pytest

from sfw_gym.cli import main


@pytest.mark.slow
def test_demo_writes_the_report(tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["demo", "--out", str(out), "--episodes", "1", "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert f"report: {out / 'index.md'}" in printed
    assert f"open {out / 'index.html'} in a browser" in printed and (out / "index.html").exists()
    assert "| agent | episodes | coverage |" in printed  # the results table, printed too
    index = (out / "index.md").read_text(encoding="utf-8")
    for agent in ("frontier", "cross-pass", "regions-ppo"):
        assert f"| {agent} | 1 |" in index  # a results row per agent
        assert (out / "gifs" / f"{agent}_0000.gif").stat().st_size > 0
    for figure in ("coverage_vs_steps.png", "iou_vs_path.png"):
        assert f"]({figure})" in index and (out / figure).exists()
    overlays = sorted((out / "trajectories").glob("*.png"))
    assert len(overlays) == 1 and f"trajectories/{overlays[0].name}" in index


def test_the_report_shows_the_results_table_of_the_one_metric_table(tmp_path):
    from sfw_gym.demo import _index_markdown
    from sfw_gym.evaluation import results_markdown, summarize
    from sfw_gym.evaluation.metric_table import METRICS

    records = [
        {"agent": "frontier", "episode": 0, "floorplan": "gen-7", "area_m2": 80.0,
         "coverage": 0.9, "info_gain_per_m": 21.25, "stop_reason": "max_steps"},
    ]  # fmt: skip
    result = {"records": records, "rows": summarize(records, ["frontier"]), "files": []}
    index = _index_markdown(tmp_path, result, 7, 1.0, "shipped")
    assert results_markdown(result["rows"]).rstrip() in index
    assert "| frontier | 1 | 0.900 |" in index and "| 21.2 |" in index  # the table's formats
    assert f"*{METRICS['info_gain_per_m'].label}*" in index

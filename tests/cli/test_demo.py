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
    assert "| agent | episodes | coverage |" in printed  # the results table, printed too
    index = (out / "index.md").read_text(encoding="utf-8")
    for agent in ("frontier", "cross-pass", "regions-ppo"):
        assert f"| {agent} | 1 |" in index  # a results row per agent
        assert (out / "gifs" / f"{agent}_0000.gif").stat().st_size > 0
    for figure in ("coverage_vs_steps.png", "iou_vs_path.png"):
        assert f"]({figure})" in index and (out / figure).exists()
    overlays = sorted((out / "trajectories").glob("*.png"))
    assert len(overlays) == 1 and f"trajectories/{overlays[0].name}" in index

"""The report pages in a real browser (headless Chromium through Playwright): every image loads,
no request fails, the console shows no error, for the demo's and ``evaluate``'s ``index.html``;
and the checker itself sees a broken page as broken. Skips, saying why, without a Chromium."""

from __future__ import annotations

from pathlib import Path

import pytest

from sfw_gym import evaluation as ev
from tests.conftest import SCRIPTS_DIR, script_module

check_report = script_module("tools/check_report.py")

CHROMIUM = check_report.find_chromium()
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(CHROMIUM is None, reason="no Chromium on the PATH (apt install chromium)"),
]
pytest.importorskip("playwright", reason="Playwright is in the test extra")
#: Short episodes, as tests/evaluation/test_evaluate.py's TINY.
TINY = {"env_id": "SfW-ExploreSmall-v0", "env_kwargs": {"max_steps": 40}, "workers": 1}


def _loads_cleanly(index: Path, screenshot: Path | None = None) -> dict[str, bool]:
    check = check_report.check_page(index, CHROMIUM, screenshot)
    assert not check.problems, check.problems
    return check.images


def test_evaluate_report_loads_in_a_browser(tmp_path):
    ev.evaluate(["frontier", "random"], 2, seed=5, out=tmp_path, gif_episodes=1, **TINY)
    shot = tmp_path / "shot.png"
    images = _loads_cleanly(tmp_path / "index.html", shot)
    assert sorted(src for src in images if src.startswith("gifs/")) == [
        "gifs/frontier_0000.gif",
        "gifs/random_0000.gif",
    ]
    assert {"coverage_vs_steps.png", "iou_vs_path.png"} <= set(images)
    assert shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_demo_report_loads_in_a_browser(tmp_path, short_demo):
    demo = short_demo
    demo.run_demo(tmp_path, 1, workers=1, progress=False)
    images = _loads_cleanly(tmp_path / "index.html")
    assert {f"gifs/{a}_0000.gif" for a in demo.DEMO_AGENTS} <= set(images)
    assert sum(src.startswith("trajectories/") for src in images) == 1


def test_the_checker_sees_a_missing_image_and_a_console_error(tmp_path):
    (tmp_path / "ok.png").write_bytes(
        (SCRIPTS_DIR.parent / "docs/figures/lidar_maps.png").read_bytes()
    )
    (tmp_path / "index.html").write_text(
        '<html><body><img src="ok.png"><img src="missing.png">'
        "<script>console.error('boom')</script></body></html>",
        encoding="utf-8",
    )
    check = check_report.check_page(tmp_path / "index.html", CHROMIUM)
    assert check.images == {"ok.png": True, "missing.png": False}
    assert check.console_errors and any("boom" in e for e in check.console_errors)
    assert any(url.endswith("missing.png") for url in check.failed_requests)
    assert check_report.main([str(tmp_path / "index.html"), "--chromium", CHROMIUM]) == 1

"""The evaluation's figures, read back from matplotlib's objects (not from the PNG pixels)."""

from __future__ import annotations

import pytest

from sfw_gym.evaluation import plots


@pytest.fixture
def figures(monkeypatch):
    """The figures the plots would write, by file name (not written, closed afterwards)."""
    import matplotlib.pyplot as plt

    kept = {}

    def keep(fig, path):
        kept[path.name] = fig
        return path

    monkeypatch.setattr(plots, "_save_figure", keep)
    yield kept
    plt.close("all")


def test_the_curves_show_each_agents_mean_over_its_episodes(tmp_path, figures):
    # curve rows: (steps, coverage, map IoU, path length [m])
    records = [
        {"agent": "a", "curve": [[0, 0.0, 0.90, 0.0], [1, 0.5, 0.9, 0.1], [100, 0.5, 0.95, 2.0]]},
        {"agent": "a", "curve": [[0, 0.0, 0.90, 0.0], [1, 0.5, 0.9, 0.1], [100, 0.7, 0.94, 2.0]]},
        {"agent": "a", "curve": []},  # an episode without a curve is not counted
        {"agent": "b", "curve": [[0, 0.0, 0.92, 0.0], [1, 0.2, 0.92, 0.1], [100, 0.2, 0.92, 1.0]]},
    ]
    written = plots.plot_curves(records, ["a", "b"], tmp_path)
    assert [p.name for p in written] == ["coverage_vs_steps.png", "iou_vs_path.png"]

    coverage = figures["coverage_vs_steps.png"].axes[0]
    assert coverage.get_xlabel() == "steps"
    assert coverage.get_ylabel() == "coverage (fraction of free cells classified)"
    assert coverage.get_ylim() == (0.0, 1.0)  # coverage spans [0, 1], from 0 whatever it reached
    assert [t.get_text() for t in coverage.get_legend().get_texts()] == ["a (n=2)", "b (n=1)"]
    a_line, b_line = coverage.get_lines()
    assert a_line.get_ydata()[-1] == pytest.approx(0.6)  # a's mean at step 100
    assert b_line.get_ydata()[-1] == pytest.approx(0.2)  # b's only episode

    iou = figures["iou_vs_path.png"].axes[0]
    assert (iou.get_xlabel(), iou.get_ylabel()) == (
        "path length [m]",
        "map IoU (cells known in both maps)",
    )
    # IoU stays high: the axis starts 0.05 below the lowest band (≈ 0.9), rounded down
    assert iou.get_ylim() == pytest.approx((0.8, 1.0))

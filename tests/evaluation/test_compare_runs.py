"""``scripts/studies/compare_runs.py``: two runs' episodes paired by seed, through the package's one
paired comparison and its table."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "studies" / "compare_runs.py"


def _script():
    spec = importlib.util.spec_from_file_location("compare_runs", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _run(path: Path, coverages: dict[int, float]) -> Path:
    records = [
        {"agent": "frontier", "seed": s, "coverage": c, "path_length_m": 100.0, "wall_s": 2.0}
        for s, c in coverages.items()
    ]
    path.write_text("".join(json.dumps(r) + "\n" for r in records) + '{"agent": "cut')
    return path


def test_two_runs_are_paired_by_seed_in_the_paired_table(tmp_path):
    compare_runs = _script()
    before = compare_runs.load(_run(tmp_path / "a.jsonl", {1: 0.5, 2: 0.6, 3: 0.7}), "frontier")
    after = compare_runs.load(_run(tmp_path / "b.jsonl", {2: 0.7, 3: 0.8, 4: 0.1}), "frontier")
    text = compare_runs.compare_runs(before, after, "frontier")
    assert text.startswith("frontier: 2 paired episodes")  # seeds 2 and 3; a torn line skipped
    assert "| frontier | coverage | 2 | 0.650 | 0.750 | +0.100 [+0.100, +0.100] | better |" in text
    assert "| frontier | path [m] | 2 | 100 | 100 | +0 [+0, +0] |  |" in text
    assert "median 1.00" in text
    with pytest.raises(SystemExit, match="no seed of 'frontier' in both runs"):
        compare_runs.compare_runs(before, {9: after[2]}, "frontier")

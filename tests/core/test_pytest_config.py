"""The test suite's own configuration: a misspelt marker fails instead of quietly putting a heavy
test in the quick loop (``--strict-markers``)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run_pytest_on(tmp_path: Path, marker: str) -> subprocess.CompletedProcess:
    test = tmp_path / "test_marked.py"
    test.write_text(f"import pytest\n\n\n@pytest.mark.{marker}\ndef test_a():\n    pass\n")
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider"]
    cmd += ["-c", str(ROOT / "pyproject.toml"), "--rootdir", str(tmp_path), str(test)]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120)


def test_a_misspelt_marker_is_an_error_and_a_registered_one_is_not(tmp_path):
    bad = run_pytest_on(tmp_path, "episdoe")
    assert bad.returncode != 0
    assert "'episdoe' not found in `markers`" in bad.stdout + bad.stderr
    assert run_pytest_on(tmp_path, "episode").returncode == 0

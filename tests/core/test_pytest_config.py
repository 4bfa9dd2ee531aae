"""The test suite's own configuration: a misspelt marker fails instead of quietly putting a heavy
test in the quick loop (``--strict-markers``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def test_a_misspelt_marker_is_an_error_and_a_registered_one_is_not(tmp_path):
    for name, marker in (("misspelt", "episdoe"), ("registered", "episode")):
        test = tmp_path / f"test_{name}.py"
        test.write_text(f"import pytest\n\n\n@pytest.mark.{marker}\ndef test_a():\n    pass\n")
    # one pytest run under the project's configuration, going on past the collection error
    cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "no:xdist"]
    cmd += ["-c", str(ROOT / "pyproject.toml"), "--rootdir", str(tmp_path)]
    cmd += ["--continue-on-collection-errors", str(tmp_path)]
    run = subprocess.run(cmd, capture_output=True, text=True, timeout=120)
    out = run.stdout + run.stderr
    assert run.returncode != 0
    assert "ERROR collecting test_misspelt.py" in out
    assert "'episdoe' not found in `markers`" in out
    assert "1 passed, 1 error" in out  # the registered marker's test ran and passed


def test_an_xdist_worker_runs_one_openmp_and_blas_thread():
    """``-n auto`` fills the cores with workers: each worker's OpenMP and BLAS pools are one
    thread unless the caller set otherwise (tests/conftest.py)."""
    if "PYTEST_XDIST_WORKER" not in os.environ:
        pytest.skip("not in an xdist worker")
    assert all(os.environ.get(v) for v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS"))

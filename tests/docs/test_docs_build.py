"""The documentation site builds from the checkout, offline, with no warning."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.docs.pages import DOCS


@pytest.mark.slow
def test_the_site_builds_with_warnings_as_errors(tmp_path):
    out = tmp_path / "html"
    built = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html", str(DOCS),
         str(out)],
        capture_output=True, text=True, timeout=900,
    )  # fmt: skip
    assert built.returncode == 0, built.stderr[-5000:]
    assert "WARNING" not in built.stderr, built.stderr[-5000:]
    index = (out / "index.html").read_text(encoding="utf-8")
    for page in ("guide/train-and-compare.html", "envs/index.html", "api/envs.html",
                 "results/index.html"):  # fmt: skip
        assert page in index and (out / page).exists()
    assert "SfWExploreEnv" in (out / "api" / "envs.html").read_text(encoding="utf-8")

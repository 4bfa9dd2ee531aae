"""The blocks the benchmarks write into the docs: ``_docs.write_block`` replaces what lies
between a block's markers and nothing else, and ``benchmark_shipped.py --agents`` keeps the rows
of the agents it does not run (the table of the earlier layout gets its episodes column)."""

from __future__ import annotations

import importlib.util
import sys

import pytest

from tests.docs.pages import ROOT

BENCHMARKS = ROOT / "scripts" / "benchmarks"


def load(name: str):
    spec = importlib.util.spec_from_file_location(name, BENCHMARKS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def shipped():
    module = load("benchmark_shipped")
    yield module
    sys.path.remove(str(BENCHMARKS))


def test_a_block_is_replaced_between_its_markers_and_a_page_without_them_refused(shipped, tmp_path):
    docs = sys.modules["_docs"]
    page = tmp_path / "page.md"
    page.write_text("head\n<!-- b:begin -->\nold\n<!-- b:end -->\ntail\n")
    docs.write_block(page, "b", ["new", "lines"])
    assert page.read_text() == "head\n<!-- b:begin -->\nnew\nlines\n<!-- b:end -->\ntail\n"
    with pytest.raises(SystemExit, match="needs one"):
        docs.write_block(page, "other", ["x"])


EARLIER = """<!-- benchmark:begin -->
intro

**SfW-Explore-v0** (50 episodes)

| agent | coverage |
|---|---:|
| frontier | 0.697 |
| goals-ppo | 0.690 |
<!-- benchmark:end -->
"""


def test_rows_of_agents_not_run_are_kept_in_the_registry_s_order(shipped, tmp_path):
    page = tmp_path / "benchmark.md"
    page.write_text(EARLIER)
    kept = shipped.kept_rows(page, "benchmark")
    assert kept == {
        "SfW-Explore-v0": {
            "frontier": "| frontier | 50 | 0.697 |",
            "goals-ppo": "| goals-ppo | 50 | 0.690 |",
        }
    }
    interval = {"mean": 0.69, "ci_low": 0.64, "ci_high": 0.74, "n": 50}
    result = {
        "package_version": "0",
        "protocol": "benchmark-v1",
        "split": "test",
        "summary": {"SfW-Explore-v0": {"coverage": interval}},
    }
    lines = shipped.table({"regions-ppo": result}, kept)
    rows = [line.split(" | ")[0].lstrip("| ") for line in lines if line.startswith("| ")]
    assert rows == ["agent", "frontier", "regions-ppo", "goals-ppo"]  # AGENTS' order

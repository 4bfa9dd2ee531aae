"""The README's Python examples stay true: their imports resolve and the quick-start block runs."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

README = Path(__file__).resolve().parents[1] / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)


def test_readme_has_python_examples():
    assert len(BLOCKS) >= 3


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_readme_imports_resolve(index):
    """Every ``import`` and ``from … import`` line of every block names something that exists."""
    for node in ast.walk(ast.parse(BLOCKS[index])):
        if isinstance(node, ast.ImportFrom):
            module = __import__(node.module, fromlist=["_"])
            for alias in node.names:
                assert hasattr(module, alias.name), f"README: {node.module} has no {alias.name}"
        elif isinstance(node, ast.Import):
            for alias in node.names:
                __import__(alias.name)


def test_readme_quick_start_runs():
    """The first block (make, reset, step, the info keys, robot_view) runs as written."""
    namespace: dict = {}
    exec(compile(BLOCKS[0], "README.md", "exec"), namespace)
    assert namespace["info"]["coverage"] >= 0.0

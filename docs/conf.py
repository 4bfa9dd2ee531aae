"""Sphinx configuration of the sfw_gym documentation (MyST Markdown pages, API from docstrings).

Build: ``sphinx-build -W --keep-going -b html docs docs/_build/html`` (offline; CI builds it with
warnings as errors, in ``tests/docs/test_docs_build.py``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import sfw_gym
from sfw_gym.envs.reference import SECTIONS

project = "sfw_gym"
author = "sfw_gym developers"
copyright = "2026, sfw_gym developers"  # noqa: A001 (Sphinx's name)
release = sfw_gym.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.viewcode",
]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store"]

myst_enable_extensions = ["colon_fence", "deflist"]
myst_heading_anchors = 3  # [text](page.md#a-heading) links resolve to headings down to ###

autodoc_default_options = {"members": True, "show-inheritance": True}
autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_inherit_docstrings = False  # gymnasium's own step/reset docstrings are not ours to render
# the rl layer needs torch: document it where torch is installed, mock it elsewhere
autodoc_mock_imports: list[str] = []
# the env classes' docstrings have Gymnasium's sections (Description:, Action Space:, ...)
napoleon_custom_sections = list(SECTIONS)
nitpicky = False
suppress_warnings = ["myst.xref_ambiguous"]

html_theme = "furo"
html_title = f"sfw_gym {release}"
html_static_path: list[str] = []


def write_env_reference(app: Any) -> None:
    """The env reference pages (``envs/reference/``), from the registry, before the build reads
    the sources (only the pages that changed are written)."""
    from sfw_gym.envs.reference import write

    write(Path(app.srcdir) / "envs" / "reference")


def setup(app: Any) -> None:
    app.connect("builder-inited", write_env_reference)

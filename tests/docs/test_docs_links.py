"""No page points at what does not exist: links, headings, figures and scripts.

Every relative link and image of the README and the site's pages names a file of the checkout,
and a ``#heading`` one of the target's headings (as MyST and the code host make anchors); every
figure in ``docs/figures`` is shown by a page and named, as the file it writes, by a script; the
benchmark commands the results pages show name scripts and options that exist.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.docs.pages import DOCS, PAGES, ROOT, blocks, commands, prose, rel

LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FIGURES = sorted(p for p in (DOCS / "figures").iterdir() if p.suffix in (".png", ".gif", ".svg"))
MAKERS = sorted([*(ROOT / "scripts").rglob("*.py"), *(ROOT / "scripts").rglob("*.sh"),
                 *(ROOT / "sfw_gym").rglob("*.py")])  # fmt: skip


def slug(heading: str) -> str:
    """A heading's anchor as MyST (``myst_heading_anchors``) and GitHub make it."""
    text = re.sub(r"[`*_]|\[([^\]]*)\]\([^)]*\)", r"\1", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(page: Path) -> set[str]:
    return {slug(h) for h in re.findall(r"^#{1,6} (.+)$", prose(page), re.M)}


def links(page: Path) -> list[str]:
    return [t for t in LINK.findall(prose(page)) if not re.match(r"[a-z]+:", t)]


@pytest.mark.parametrize("page", PAGES, ids=rel)
def test_every_link_names_a_file_and_heading_that_exist(page):
    broken = []
    for target in links(page):
        path, _, anchor = target.partition("#")
        where = (page.parent / path).resolve() if path else page
        if not where.exists():
            broken.append(f"{target}: no such file")
        elif anchor and where.suffix == ".md" and anchor not in anchors(where):
            broken.append(f"{target}: no heading #{anchor} in {rel(where)}")
    assert not broken, f"{rel(page)}: " + "; ".join(broken)


def test_the_link_check_sees_a_broken_link(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# Title\n\n[a](missing.md) [b](#title) [c](#nope)\n")
    assert links(page) == ["missing.md", "#title", "#nope"]
    assert "title" in anchors(page) and "nope" not in anchors(page)
    assert slug("Env throughput (issue 33)") == "env-throughput-issue-33"


@pytest.mark.parametrize("figure", FIGURES, ids=lambda p: p.name)
def test_every_figure_is_shown_and_made_by_a_named_script(figure):
    shown = [rel(p) for p in PAGES if f"figures/{figure.name}" in p.read_text(encoding="utf-8")]
    assert shown, f"docs/figures/{figure.name} is shown by no page"
    makers = []
    for script in MAKERS:
        for name in re.findall(r"docs/figures/([\w\-.<>{}*]+)", script.read_text(encoding="utf-8")):
            pattern = re.sub(r"<[^>]*>|\\\{[^}]*\\\}|\\\*", ".+", re.escape(name))
            if re.fullmatch(pattern, figure.name):
                makers.append(rel(script))
    assert makers, f"docs/figures/{figure.name}: no script names it as a file it writes"


def _benchmark_commands() -> list[str]:
    return [
        line
        for page in PAGES
        if rel(page).startswith("docs/results/")
        for language, text in blocks(page)
        if language in ("bash", "")
        for line in commands(text)
        if re.match(r"(nice( -n \d+)? )?(\.venv/bin/)?python3? scripts/", line)
    ]


@pytest.mark.slow
@pytest.mark.parametrize("line", sorted(set(_benchmark_commands())))
def test_the_results_pages_benchmark_commands_name_real_scripts_and_options(line):
    """Each script exists and its ``--help`` lists every option the command gives it."""
    words = line.split()
    script = ROOT / next(w for w in words if w.startswith("scripts/"))
    assert script.exists(), f"{line}: no {rel(script)}"
    if script.suffix != ".py":
        return
    shown = subprocess.run([sys.executable, str(script), "--help"], capture_output=True,
                           text=True, cwd=ROOT, timeout=300)  # fmt: skip
    assert shown.returncode == 0, f"{rel(script)} --help: {shown.stderr[-1000:]}"
    for option in (w.split("=")[0] for w in words if w.startswith("--")):
        assert option in shown.stdout, f"{line}: {rel(script)} has no option {option}"

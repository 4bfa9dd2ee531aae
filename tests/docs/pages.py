"""The documentation's pages and their code blocks, as the doc tests read them."""

from __future__ import annotations

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"
SHARED = ROOT.parent / "shared"

#: Every Markdown page a user reads: the README and the site's sources (the build's output and
#: the generated API pages' sources included).
PAGES = sorted([ROOT / "README.md", ROOT / "scripts" / "README.md", *DOCS.rglob("*.md")])
PAGES = [p for p in PAGES if "_build" not in p.parts]

#: The pages whose commands ``test_doc_commands.py`` runs, and those it leaves to another test.
RUN_ELSEWHERE = {
    "docs/rl-zoo.md": "tests/rl/test_rl_zoo.py runs rl-zoo's train and enjoy on these files",
    "docs/ray.md": "the Ray venv runs tests/evaluation/test_ray_backend.py, tests/rl/test_rllib.py",
}
#: Results pages show the benchmarks behind each figure (minutes to hours each): their scripts
#: and options are checked (``test_docs_links.py``), not run.
BENCHMARK_PAGES = ("docs/results/",)

_FENCE = re.compile(r"^```([\w-]*)[^\n]*\n(.*?)^```", re.M | re.S)


def rel(page: Path) -> str:
    return page.relative_to(ROOT).as_posix()


def blocks(page: Path) -> list[tuple[str, str]]:
    """``(language, text)`` of each fenced code block of a page, in order."""
    return [(m.group(1), m.group(2)) for m in _FENCE.finditer(page.read_text(encoding="utf-8"))]


def saved_as(page: Path) -> dict[int, str]:
    """Blocks the page asks the reader to save as a file ("Save it as `my_agent.py`" just
    before the block), by block index."""
    text, out = page.read_text(encoding="utf-8"), {}
    for i, m in enumerate(_FENCE.finditer(text)):
        before = text[max(0, m.start() - 300) : m.start()]
        named = re.search(r"[Ss]ave it as `([\w.]+)`[^`]*$", before)
        if named:
            out[i] = named.group(1)
    return out


def prose(page: Path) -> str:
    """The page without its code blocks (where links and headings live)."""
    return _FENCE.sub("", page.read_text(encoding="utf-8"))


def commands(text: str) -> list[str]:
    """The commands of a bash block: one a line, ``\\`` continuations joined, comments dropped."""
    joined = text.replace("\\\n", " ")
    out = []
    for line in joined.splitlines():
        line = line.split("  #")[0].strip()
        if line and not line.startswith("#"):
            out.append(line)
    return out


def runnable_pages() -> list[Path]:
    return [
        p
        for p in PAGES
        if rel(p) not in RUN_ELSEWHERE
        and not rel(p).startswith(BENCHMARK_PAGES)
        and any(lang in ("bash", "python", "json") for lang, _ in blocks(p))
    ]

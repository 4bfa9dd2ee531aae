"""The report pages' ``index.html`` (demo, evaluate, benchmark run): parsed with the standard
library's parser, well-formed (html/head/title/body, every element closed), a results row per
agent, and every image, link and video source it names present beside it."""

from __future__ import annotations

from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit

import pytest
import yaml

from sfw_gym import evaluation as ev
from sfw_gym.core.data import data_path
from sfw_gym.evaluation import benchmark as bm
from sfw_gym.evaluation.report import report_html

#: Short episodes, as tests/evaluation/test_evaluate.py's TINY.
TINY = {"env_id": "SfW-ExploreSmall-v0", "env_kwargs": {"max_steps": 40}, "workers": 1}
VOID = {"meta", "img", "br", "hr", "link", "source", "input", "col", "wbr"}


class Page(HTMLParser):
    """What a test checks of a page: its tags, title, tables (header cells and the first cell of
    each body row) and the files it points to; fails on an element closed out of order."""

    def __init__(self, text: str) -> None:
        super().__init__(convert_charrefs=True)
        self.open: list[str] = []
        self.tags: list[str] = []
        self.title = ""
        self.tables: list[dict[str, list[str]]] = []
        self.links: list[str] = []
        self._cell: list[str] | None = None
        self._column = 0
        self.feed(text)
        self.close()
        assert not self.open, f"unclosed elements: {self.open}"

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append(tag)
        if tag not in VOID:
            self.open.append(tag)
        if tag == "table":
            self.tables.append({"head": [], "rows": []})
        elif tag == "tr":
            self._column = 0
        elif tag in ("th", "td"):
            self._cell = []
        if tag in ("img", "a", "video", "source"):
            self.links += [str(value) for name, value in attrs if name in ("src", "href") and value]

    def handle_startendtag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.handle_starttag(tag, attrs)  # <x/>: a void element's only tag

    def handle_endtag(self, tag: str) -> None:
        assert self.open and self.open[-1] == tag, f"</{tag}> closes {self.open[-1:]}"
        self.open.pop()
        if tag in ("th", "td") and self._cell is not None:
            text, table = "".join(self._cell).strip(), self.tables[-1]
            if tag == "th":
                table["head"].append(text)
            elif self._column == 0:
                table["rows"].append(text)
            self._column += 1
            self._cell = None

    def handle_data(self, data: str) -> None:
        if self.open and self.open[-1] == "title":
            self.title += data
        if self._cell is not None:
            self._cell.append(data)


def _page(index: Path) -> Page:
    """Parse ``index``, check its skeleton and that every local file it names exists."""
    page = Page(index.read_text(encoding="utf-8"))
    assert page.tags[:3] == ["html", "head", "meta"] and {"title", "style", "body"} <= set(
        page.tags
    )
    assert page.tags.index("body") > page.tags.index("title") and page.title.strip()
    for link in page.links:
        parts = urlsplit(link)
        assert not parts.scheme and not link.startswith("/"), f"{link}: not a relative link"
        assert (index.parent / unquote(parts.path)).is_file(), f"{link}: no such file"
    return page


def _table(page: Page, first_header: str) -> dict[str, list[str]]:
    (table,) = [t for t in page.tables if t["head"][:1] == [first_header]]
    return table


def _images(page: Page, folder: str) -> list[str]:
    return [link for link in page.links if link.startswith(folder)]


def test_evaluate_writes_an_html_report_beside_the_markdown(tmp_path):
    ev.evaluate(["frontier", "random"], 2, seed=5, out=tmp_path, gif_episodes=1, **TINY)
    page = _page(tmp_path / "index.html")
    assert "frontier, random" in page.title
    assert _table(page, "agent")["rows"] == ["frontier", "random"]  # a results row per agent
    paired = _table(page, "agent − reference")["rows"]
    assert paired and set(paired) == {"random − frontier"}
    assert {"coverage_vs_steps.png", "iou_vs_path.png", "results.csv"} <= set(page.links)
    assert len(_images(page, "trajectories/")) == 2  # one per floorplan
    assert sorted(_images(page, "gifs/")) == ["gifs/frontier_0000.gif", "gifs/random_0000.gif"]
    index_md = (tmp_path / "index.md").read_text(encoding="utf-8")
    assert all(f"]({link})" in index_md for link in page.links)  # one page, two renderings


@pytest.mark.slow
def test_the_demo_writes_an_html_report(tmp_path, short_demo):
    demo = short_demo
    out = tmp_path / "report"
    assert demo.run_demo(out, 1, workers=1, progress=False) == out / "index.md"
    page = _page(out / "index.html")
    assert page.title == "sfw_gym demo: WiFi-only exploration"
    assert _table(page, "agent")["rows"] == list(demo.DEMO_AGENTS)
    assert _table(page, "episode")["rows"] == ["0"]
    assert sorted(_images(page, "gifs/")) == [
        f"gifs/{a}_0000.gif" for a in sorted(demo.DEMO_AGENTS)
    ]
    assert len(_images(page, "trajectories/")) == 1
    assert {"coverage_vs_steps.png", "iou_vs_path.png", "episodes.jsonl"} <= set(page.links)


def test_benchmark_run_writes_an_html_report(tmp_path):
    protocol = yaml.safe_load(data_path("envs", "benchmark-v1.yml").read_text(encoding="utf-8"))
    for env in protocol["envs"]:  # the shipped protocol on 40-step episodes
        env["kwargs"] = {**(env.get("kwargs") or {}), "max_steps": 40}
    path = tmp_path / "short.yml"
    path.write_text(yaml.safe_dump(protocol), encoding="utf-8")
    out = tmp_path / "run"
    results = bm.run_benchmark(
        "random", protocol=path, split="validation", out=out, episodes=1, progress=False
    )
    page = _page(out / "index.html")
    assert page.title == "random on benchmark-v1 / validation"
    tables = [t for t in page.tables if t["head"][:1] == ["metric"]]
    assert len(tables) == len(results["summary"]) == 2  # a table per env
    for table, metrics in zip(tables, results["summary"].values(), strict=True):
        assert len(table["rows"]) == len(metrics) > 0  # a row per metric reported


def test_user_text_is_escaped_and_links_stay_in_the_folder():
    text = (
        "# <script>alert(1)</script> & co\n\n| agent | n |\n|---|---|\n"
        "| <img src=x onerror=alert(1)> | 1 |\n\n"
        "[a](javascript:alert(1)) [b](/etc/passwd) ![c](http://example.com/c.png) [d](d%20e.csv)\n"
    )
    page = Page(report_html(text))
    assert page.title == "<script>alert(1)</script> & co"  # shown as text, not run
    assert "script" not in page.tags and page.tags.count("img") == 1  # c, without its src
    assert page.tables[0]["rows"] == ["<img src=x onerror=alert(1)>"]
    assert page.links == ["d%20e.csv"]

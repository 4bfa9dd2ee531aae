"""The HouseExpo plans the results pages use are named on the datasets page: its table of ids
is the shared folder's files, in the order ``--floorplans`` hands them to the episodes."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from sfw_gym.evaluation.runner import plan_files
from tests.docs.pages import DOCS, SHARED

FOLDER = SHARED / "floorplans" / "houseexpo"


def listed_ids() -> list[str]:
    text = (DOCS / "datasets.md").read_text(encoding="utf-8")
    return re.findall(r"^\| \d+ \| `([0-9a-f]{32})` \|$", text, re.M)


@pytest.mark.skipif(not FOLDER.is_dir(), reason="../shared/floorplans/houseexpo is absent")
def test_datasets_page_lists_the_houseexpo_plans_in_order() -> None:
    assert listed_ids() == [Path(p).stem for p in plan_files(FOLDER) if p]


def test_every_results_page_on_houseexpo_links_the_list() -> None:
    """A page that reports figures on "the 11 HouseExpo plans" says where they come from."""
    unlinked = [
        page.name
        for page in sorted((DOCS / "results").glob("*.md"))
        if page.name != "history.md"
        and "11 HouseExpo plans" in page.read_text(encoding="utf-8")
        and "datasets.md#houseexpo-floorplans" not in page.read_text(encoding="utf-8")
    ]
    assert not unlinked, f"link datasets.md#houseexpo-floorplans from {unlinked}"

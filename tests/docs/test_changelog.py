"""CHANGELOG.md keeps step with the package: its newest release is ``sfw_gym.__version__`` (and
CITATION.cff's version), in Keep a Changelog's form, and every env id, agent name and deprecated
name the package registers is recorded in it."""

from __future__ import annotations

import re

import pytest
import yaml

import sfw_gym
from sfw_gym.agents import AGENTS, DEPRECATED_AGENTS
from tests.docs.pages import ROOT

CHANGELOG = ROOT / "CHANGELOG.md"
#: A release heading: ``## [1.2.3] - 2026-11-29``; ``## [Unreleased]`` is not a release.
RELEASE = re.compile(r"^## \[(\d+\.\d+\.\d+)\] - (\d{4}-\d{2}-\d{2})$", re.M)
#: Keep a Changelog's kinds of change.
KINDS = {"Added", "Changed", "Deprecated", "Removed", "Fixed", "Security"}


def releases(text: str) -> list[tuple[str, str]]:
    """``(version, date)`` of each release heading, newest first."""
    return RELEASE.findall(text)


def text() -> str:
    return CHANGELOG.read_text(encoding="utf-8")


def test_newest_release_is_the_package_version() -> None:
    found = releases(text())
    assert found, "CHANGELOG.md has no release heading '## [X.Y.Z] - YYYY-MM-DD'"
    assert found[0][0] == sfw_gym.__version__


def test_newest_release_is_the_citation_version() -> None:
    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text(encoding="utf-8"))
    assert releases(text())[0][0] == str(cff["version"])
    assert releases(text())[0][1] == str(cff["date-released"])


def test_keep_a_changelog_form() -> None:
    body = text()
    assert body.index("## [Unreleased]") < body.index(f"## [{sfw_gym.__version__}]")
    versions = [tuple(int(n) for n in v.split(".")) for v, _ in releases(body)]
    assert versions == sorted(versions, reverse=True), "releases must run newest first"
    kinds = set(re.findall(r"^### (\w+)$", body, re.M))
    assert kinds <= KINDS, f"not a Keep a Changelog section: {kinds - KINDS}"
    assert "## Version policy" in body


@pytest.mark.parametrize(
    "name",
    sorted({*sfw_gym.ENV_IDS, *AGENTS, *DEPRECATED_AGENTS}),
)
def test_every_registered_name_is_recorded(name: str) -> None:
    """A new env id or agent (or a renamed one) is a user-visible change: the changelog says so."""
    assert f"`{name}`" in text(), f"CHANGELOG.md does not mention `{name}`"

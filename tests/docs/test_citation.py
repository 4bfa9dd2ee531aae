"""CITATION.cff is valid Citation File Format 1.2.0, names this version and cites the papers.

Validated against the format's own JSON schema (``tests/data/cff-1.2.0-schema.json``, CC BY 4.0,
see ``tests/data/README.md``), as ``cffconvert --validate`` does; cffconvert itself pins a
jsonschema older than the one the rest of the environment uses.
"""

from __future__ import annotations

import datetime as dt
import json
from typing import Any

import pytest
import yaml

import sfw_gym
from tests.docs.pages import ROOT

jsonschema = pytest.importorskip("jsonschema")

CFF = ROOT / "CITATION.cff"
SCHEMA = ROOT / "tests" / "data" / "cff-1.2.0-schema.json"

#: The papers sfw_gym implements: each must be among the references (by title).
PAPERS = (
    "Inverse k-visibility for RSSI-based Indoor Geometric Mapping",
    "Exploiting Radio Fingerprints for Simultaneous Localization and Mapping",
    "Gaussian Gridmaps from Gaussian Processes for WiFi-based Robot Self-Localization in "
    "Outdoor Environments",
)


def _as_json(value: Any) -> Any:
    """YAML's dates as the ISO strings the schema (JSON) expects, as cffconvert reads them."""
    if isinstance(value, dict):
        return {k: _as_json(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_as_json(v) for v in value]
    if isinstance(value, dt.date):
        return value.isoformat()
    return value


def load_cff(text: str | None = None) -> dict[str, Any]:
    return _as_json(yaml.safe_load(CFF.read_text(encoding="utf-8") if text is None else text))


def errors(cff: dict[str, Any]) -> list[str]:
    schema = json.loads(SCHEMA.read_text(encoding="utf-8"))
    validator = jsonschema.Draft7Validator(schema, format_checker=jsonschema.FormatChecker())
    return [f"{list(e.absolute_path)}: {e.message}" for e in validator.iter_errors(cff)]


def test_citation_cff_is_valid_cff_1_2_0() -> None:
    cff = load_cff()
    assert cff["cff-version"] == "1.2.0"
    assert errors(cff) == []


def test_the_schema_catches_a_broken_file() -> None:
    """The check can fail: a reference without its type, an unknown key, a bad date."""
    cff = load_cff()
    del cff["references"][0]["type"]
    cff["citation"] = "unknown key"
    cff["date-released"] = "29 November 2026"
    found = "\n".join(errors(cff))
    assert "'type' is a required property" in found
    assert "'citation' was unexpected" in found
    assert "date-released" in found


def test_citation_version_is_the_package_version() -> None:
    assert str(load_cff()["version"]) == sfw_gym.__version__


def test_references_include_the_three_papers() -> None:
    titles = {" ".join(str(r["title"]).split()) for r in load_cff()["references"]}
    missing = [p for p in PAPERS if p not in titles]
    assert not missing, f"CITATION.cff's references lack {missing}"


def test_the_citing_section_cites_this_version() -> None:
    """docs/index.md's BibTeX entry for sfw_gym names the version CITATION.cff gives."""
    index = (ROOT / "docs" / "index.md").read_text(encoding="utf-8")
    entry = index[index.index("@software{sfw_gym,") :]
    entry = entry[: entry.index("\n}")]
    assert f"version = {{{sfw_gym.__version__}}}" in entry

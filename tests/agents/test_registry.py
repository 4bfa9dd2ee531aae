"""Agent names from outside the package: an installed distribution's ``sfw_gym.agents`` entry
points, read where every command resolves a name (:func:`sfw_gym.agents.agent_class`), listed
beside the built-in names, never taking a built-in's name."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from sfw_gym.agents import (
    AGENTS,
    ENTRY_POINT_GROUP,
    FrontierAgent,
    agent_class,
    agent_names,
    installed_agents,
    known_agent,
    make_agent,
)
from sfw_gym.core.errors import ConfigError

#: A module with an agent of its own: it drives straight on.
AGENT_MODULE = """
from sfw_gym.agents.base import Agent


class Mine(Agent):
    name, action_types = "mine", ("continuous",)

    def _act(self, view, obs):
        return (1.0, 0.0)
"""


def installed(site: Path, points: dict[str, str], module: str = "mine_agents") -> Path:
    """``site`` as an installed distribution looks to importlib.metadata: the module and a
    ``.dist-info`` holding ``points`` in the ``sfw_gym.agents`` group (the documented name)."""
    (site / module).mkdir(parents=True)
    (site / module / "__init__.py").write_text(AGENT_MODULE)
    info = site / f"{module}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {module}\nVersion: 0.1\n")
    lines = "".join(f"{name} = {value}\n" for name, value in points.items())
    (info / "entry_points.txt").write_text(f"[sfw_gym.agents]\n{lines}")
    return site


@pytest.fixture
def mine(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    site = installed(tmp_path / "site", {"mine": "mine_agents:Mine"})
    monkeypatch.syspath_prepend(str(site))
    return site


def test_an_installed_agent_is_known_listed_and_built_by_its_name(mine):
    assert installed_agents() == {"mine": "mine_agents:Mine"}
    assert agent_names() == [*AGENTS, "mine"]
    assert known_agent("mine")
    agent = make_agent("mine")
    assert type(agent).__name__ == "Mine" and agent.name == "mine"


def test_without_it_the_name_is_unknown_and_the_error_lists_every_name():
    assert "mine" not in agent_names() and not known_agent("mine")
    with pytest.raises(ConfigError) as exc:
        agent_class("mine")
    text = str(exc.value)
    assert "\n" not in text
    known = ", ".join(AGENTS)
    assert text == f"unknown agent 'mine'; known: {known}; or a 'module:Class' of your own"


def test_the_unknown_name_error_lists_the_installed_ones_too(mine):
    with pytest.raises(ConfigError, match=r"unknown agent 'nope'; known: frontier, .*, mine; or"):
        agent_class("nope")


def test_evaluate_s_help_lists_the_installed_agents(mine, monkeypatch, capsys):
    from sfw_gym.cli import main

    monkeypatch.setenv("COLUMNS", "1000")  # one line per option
    with pytest.raises(SystemExit):
        main(["evaluate", "--help"])
    listed = re.search(r"comma-separated agent names: ([^;]*);", capsys.readouterr().out)
    assert listed and listed.group(1).split(", ") == [*AGENTS, "mine"]


def test_a_built_in_name_stays_the_built_in_s_with_a_warning(tmp_path, monkeypatch):
    site = installed(tmp_path / "site", {"frontier": "mine_agents:Mine", "ppo": "mine_agents:Mine"})
    monkeypatch.syspath_prepend(str(site))
    with pytest.warns(UserWarning) as caught:
        assert agent_class("frontier") is FrontierAgent
        assert installed_agents() == {}  # a deprecated name is the package's too
    said = " | ".join(str(w.message) for w in caught)
    assert (
        "entry point frontier = 'mine_agents:Mine' (sfw_gym.agents) is ignored: 'frontier' "
        "is a built-in agent's name; run yours as 'mine_agents:Mine'"
    ) in said
    assert "entry point ppo = 'mine_agents:Mine'" in said


def test_an_installed_name_whose_module_is_gone_is_a_one_line_error(tmp_path, monkeypatch):
    site = installed(tmp_path / "site", {"gone": "no_such_module:Agent"})
    monkeypatch.syspath_prepend(str(site))
    with pytest.raises(ConfigError, match=r"^agent 'gone': cannot import no_such_module:Agent"):
        make_agent("gone")


def test_the_entry_point_group_is_the_documented_one():
    pages = ["docs/architecture.md", "docs/agents.md"]
    root = Path(__file__).resolve().parents[2]
    needle = f'[project.entry-points."{ENTRY_POINT_GROUP}"]'
    assert all(needle in (root / page).read_text(encoding="utf-8") for page in pages)

"""Every command's ``--help`` is what it was before ``sfw_gym/cli.py`` became the package
``sfw_gym/cli/`` (``data/help_before.json``, recorded at COLUMNS=100), but for the corrections
listed below; every default shows in one format; ``--version`` works; ``evaluate --help`` lists
the agent registry's names."""

from __future__ import annotations

import argparse
import difflib
import json
import re
import sys
from pathlib import Path

import pytest

from sfw_gym.agents import AGENTS, DEPRECATED_AGENTS, agent_names
from sfw_gym.cli import build_parser, main, version
from sfw_gym.cli.options import shown_default, shows_default
from sfw_gym.cli.train import describe

#: ``--routers``' help on evaluate and benchmark run, its default (in words) left out.
EPISODE_ROUTERS = "every episode's routers: a count, or positions 'x1,y1;x2,y2' (m)"
BEFORE = json.loads((Path(__file__).parent / "data" / "help_before.json").read_text("utf-8"))

#: The intended differences, per command: (text before, text now), both whitespace-normalised
#: (:func:`normalised`); "(default…)" fragments are stripped before either is applied.
CORRECTIONS: dict[str, list[tuple[str, str]]] = {
    # --version prints "sfw-gym <version>" and exits 0 (it was an unknown option, exit 2)
    "sfw-gym": [
        ("[-h] [--debug]", "[-h] [--version] [--debug]"),
        ("and exit --debug", "and exit --version show program's version number and exit --debug"),
    ],
    # one default format: "default" no longer said in the middle of a help text
    "sfw-gym map": [
        ("strongest band (max: the default, as the SfW authors mapped),", "strongest band (max),"),
        ("router's ray (all: the default, measured best on two-router logs)", "router's ray (all)"),
        ("(ours, default)", "(ours)"),
    ],
    "sfw-gym localize": [
        ("--json OUT output folder", "--json OUT output folder; --json is its old name")
    ],
    "sfw-gym evaluate": [
        ("or one file; default: the env's procedural plans", "or one file"),
        # one name per agent: the registry's names, not the deprecated ppo, ppo-waypoint
        (
            "comma-separated: frontier, cross-pass, greedy, random, ppo, ppo-waypoint",
            f"comma-separated agent names: {', '.join(AGENTS)}; or package.module:Class",
        ),
        ("--agents frontier,ppo,greedy", "--agents frontier,regions-ppo,greedy"),
        # issue 52: fixed routers for every episode, and ROS maps in a folder of plans
        (
            "[--floorplans FLOORPLANS] [--env ENV]",
            "[--floorplans FLOORPLANS] [--routers ROUTERS] [--env ENV]",
        ),
        (
            "--floorplans FLOORPLANS folder of plan files (cycled) or one file --env ENV",
            "--floorplans FLOORPLANS folder of plan files, JSON or ROS map YAML (cycled), or one "
            f"file --routers ROUTERS {EPISODE_ROUTERS} --env ENV",
        ),
    ],
    # issue 52: world and record share one --routers (in metres)
    "sfw-gym world": [
        (
            "--routers ROUTERS a count, or positions 'x1,y1;x2,y2' --preset",
            "--routers ROUTERS a count, or positions 'x1,y1;x2,y2' (m) --preset",
        )
    ],
    "sfw-gym speed": [("(e.g. frontier,ppo)", "(e.g. frontier,regions-ppo)")],
    "sfw-gym bench": [("(e.g. frontier,ppo)", "(e.g. frontier,regions-ppo)")],
    # options without a help line could not show their default
    "sfw-gym benchmark run": [
        (
            "--split {train,validation,test} --agent-params",
            "--split {train,validation,test} the protocol's split to run: its plans and seeds "
            "--agent-params",
        ),
        (
            "--out OUT default benchmark/AGENT/SPLIT (resumes)",
            "--out OUT output folder (resumes from it)",
        ),
        # issue 52: as evaluate's
        (
            "[--plans PLANS] [--episodes EPISODES]",
            "[--plans PLANS] [--routers ROUTERS] [--episodes EPISODES]",
        ),
        (
            "--plans PLANS a folder of plan files to add (by the split) --episodes",
            "--plans PLANS a folder of plan files, JSON or ROS map YAML, to add (by the split) "
            f"--routers ROUTERS {EPISODE_ROUTERS} --episodes",
        ),
    ],
    "sfw-gym fingerprints evaluate": [
        (
            "gridmaps} --not-heard NOT_HEARD",
            "gridmaps} the localisation method --not-heard NOT_HEARD",
        )
    ],
    # train says which policy it trains, what a timestep counts, how long, and how the default
    # learned agent is trained (a description; "env steps" were timesteps)
    "sfw-gym train": [
        ("{ppo,ppo_mask} positional", f"{{ppo,ppo_mask}} {describe()} positional"),
        (
            "TIMESTEPS total env steps",
            "TIMESTEPS total timesteps, what one counts depends on --env (above)",
        ),
        ("CHECKPOINT_EVERY env steps", "CHECKPOINT_EVERY timesteps"),
        ("EVAL_EVERY env steps", "EVAL_EVERY timesteps"),
        (
            "in this process; subproc",
            "in this process (SubprocVecEnv under an env_wrapper); subproc",
        ),
        (
            "CPU threads --backend",
            "CPU threads (1 suits the small networks; 0: PyTorch's own choice) --backend",
        ),
        ("(stable-baselines3, default)", "(stable-baselines3)"),
        # --device (issue 50): the long runs on a GPU where there is one
        ("[--address ADDRESS] [--resume]", "[--address ADDRESS] [--device DEVICE] [--resume]"),
        (
            "cluster's address ('auto') --resume",
            "cluster's address ('auto') --device DEVICE PyTorch device of the policy: auto (a GPU "
            "where there is one), cpu, cuda,... --resume",
        ),
    ],
}


def normalised(text: str) -> str:
    """Whitespace collapsed (argparse re-wraps; a word broken at its hyphen is joined again)."""
    text = re.sub(r"(\w)- (\w)", r"\1-\2", " ".join(text.split()))
    return " ".join(text.split())


def without_defaults(text: str) -> str:
    """``text`` normalised, its "(default…)" fragments out: their format is a correction."""
    text = re.sub(r"\(default[^()]*\)", "", normalised(text))
    return re.sub(r"\s+([:;,.)])", r"\1", " ".join(text.split()))


def by_option(text: str) -> list[str]:
    """A normalised help cut before each option, for a readable diff."""
    return re.split(r" (?=\[?--?\w)", text)


def every_help(monkeypatch: pytest.MonkeyPatch) -> dict[str, str]:
    """Each command's ``--help`` at COLUMNS=100 (as recorded), by its command line."""
    monkeypatch.setenv("COLUMNS", "100")
    found: dict[str, str] = {}

    def walk(parser: argparse.ArgumentParser, path: list[str]) -> None:
        found[" ".join(path)] = parser.format_help()
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    walk(sub, [*path, name])

    walk(build_parser(), ["sfw-gym"])
    return found


def every_option(parser: argparse.ArgumentParser, path: str = "sfw-gym"):
    """(command, parser, action) for every option of every command."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from every_option(sub, f"{path} {name}")
        elif action.option_strings:
            yield path, parser, action


@pytest.mark.skipif(
    f"{sys.version_info[0]}.{sys.version_info[1]}" != BEFORE["python"],
    reason=f"recorded with Python {BEFORE['python']}, whose argparse layout may differ",
)
def test_every_help_is_as_before_but_for_the_listed_corrections(monkeypatch):
    now = every_help(monkeypatch)
    assert sorted(now) == sorted(BEFORE["help"]), "commands added or gone"
    problems = []
    for command, before in BEFORE["help"].items():
        expected = without_defaults(before)
        for old, new in CORRECTIONS.get(command, []):
            assert old in expected, f"{command}: correction {old!r} matches nothing"
            expected = expected.replace(old, normalised(new), 1)
        got = without_defaults(now[command])
        if got != expected:
            diff = difflib.unified_diff(
                by_option(expected), by_option(got), "expected", "now", lineterm=""
            )
            problems.append(f"--- {command} --help\n" + "\n".join(diff))
    assert not problems, "\n\n".join(problems)


def test_version_prints_the_version_and_exits_0(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out == f"sfw-gym {version()}\n"
    assert re.fullmatch(r"\d+\.\d+\S*", version())


def test_every_default_shows_in_one_format(monkeypatch):
    monkeypatch.setenv("COLUMNS", "100")
    seen = 0
    for command, parser, action in every_option(build_parser()):
        line = normalised(parser.format_help())
        name = action.option_strings[-1]
        text = normalised(action.help or "")
        assert text.lower().count("default") <= 1, f"{command} {name}: {text!r}"
        if "default" in text.lower():  # a default told in words (its value is None)
            assert "(default: " in text, f"{command} {name}: {text!r} not in the one format"
        if shows_default(action):
            seen += 1
            shown = f"(default: {shown_default(action.default)})"
            assert "default" not in text.lower(), f"{command} {name}: its help says a default"
            assert shown in line, f"{command} {name}: {shown} not in its --help"
    assert seen > 50
    assert shown_default([]) == shown_default("") == "none"
    assert shown_default(["a", "b"]) == "a,b"


def test_options_that_needed_a_shown_default_show_one(monkeypatch):
    help_of = every_help(monkeypatch)
    assert "(default: test)" in help_of["sfw-gym benchmark run"]
    assert "the localisation method (default: " in help_of["sfw-gym fingerprints evaluate"]
    assert re.search(r"--address ADDRESS .*\(default: ", normalised(help_of["sfw-gym train"]))


def test_evaluate_lists_exactly_the_registrys_agents(monkeypatch):
    text = normalised(every_help(monkeypatch)["sfw-gym evaluate"])
    listed = re.search(r"comma-separated agent names: ([^;]*);", text)
    assert listed, text
    assert listed.group(1).split(", ") == agent_names()  # AGENTS, then installed ones
    for old in DEPRECATED_AGENTS:  # still accepted (with a warning), not advertised
        assert not re.search(rf"[\s,:]{re.escape(old)}[\s,;)]", text), old

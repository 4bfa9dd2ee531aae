"""Every agent name a page hands a command is one the package registers today.

The pages' commands (code blocks and inline code) name agents with ``--agents a,b,c``,
``--agent x``, ``evaluate --agent-params '{"x": ...}'`` and ``make_agent("x")``; each name
must be in :data:`sfw_gym.agents.AGENTS`, a ``module:Class`` entry point, a name the same page
declares as an entry point of the ``sfw_gym.agents`` group (the own-agent example), or a tuned
entry of the study script the command runs. A deprecated name (``ppo``) fails: pages speak of
today's names. The lab notebook (``docs/results/history.md``) keeps the names each section was
recorded with.
"""

from __future__ import annotations

import ast
import json
import re
import shlex
from pathlib import Path

import pytest

from sfw_gym.agents import AGENTS, DEPRECATED_AGENTS
from tests.docs.pages import PAGES, ROOT, blocks, rel

NOTEBOOK = "docs/results/history.md"
#: Inline code that holds a command (prose mentions like `--agents mine`).
INLINE = re.compile(r"`([^`\n]*--agent[^`\n]*)`")
#: A placeholder, not a name: NAME, AGENT, ``...``.
PLACEHOLDER = re.compile(r"^(?:[A-Z_]+|\.\.\.)$")
ENTRY_POINTS = re.compile(
    r'\[project\.entry-points\."sfw_gym\.agents"\]\n((?:[ \t]*[\w-]+ *= *"[^"]*"\n)+)'
)


def study_names(script: str) -> set[str]:
    """The extra agent names a study script resolves itself (its ``TUNED`` entries)."""
    path = ROOT / script
    if not path.is_file():
        return set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id == "TUNED" for t in targets):
                if isinstance(node.value, ast.Dict):
                    return {k.value for k in node.value.keys if isinstance(k, ast.Constant)}
    return set()


def command_names(command: str, variables: dict[str, str]) -> list[tuple[str, set[str]]]:
    """``(name, extra names allowed)`` for each agent a command line names."""
    try:
        argv = shlex.split(command, comments=True)
    except ValueError:
        return []

    def expand(m: re.Match[str]) -> str:
        return variables.get(m.group(1), m.group(0))

    argv = [re.sub(r"\$\{?(\w+)\}?", expand, a) for a in argv]
    if not argv:
        return []
    extra = set().union(*(study_names(a) for a in argv if a.endswith(".py")))
    found: list[tuple[str, set[str]]] = []
    for flag, value in zip(argv, [*argv[1:], ""], strict=True):
        if flag in ("--agents", "--agent"):
            found += [(n.strip(), extra) for n in value.split(",")]
        elif flag == "--agent-params" and "evaluate" in argv:  # keyed by agent name there
            try:
                found += [(n, extra) for n in json.loads(value)]
            except (ValueError, TypeError):
                pass
    return found


def page_names(page: Path) -> list[tuple[str, set[str]]]:
    """Every agent name the page's commands use, with the names allowed beside the registry."""
    text = page.read_text(encoding="utf-8")
    declared = {
        line.split("=")[0].strip()
        for group in ENTRY_POINTS.findall(text)
        for line in group.splitlines()
    }
    found: list[tuple[str, set[str]]] = []
    for _language, block in blocks(page):
        joined = block.replace("\\\n", " ")
        variables = dict(re.findall(r"^(\w+)=(\S+)$", joined, re.M))
        for line in joined.splitlines():
            found += command_names(line, variables)
        found += [(n, set()) for n in re.findall(r"make_agent\(\s*[\"']([^\"']+)[\"']", block)]
    for inline in INLINE.findall(text):
        found += command_names(inline, {})
    return [(name, allowed | declared) for name, allowed in found]


def check(name: str, allowed: set[str]) -> str | None:
    """Why ``name`` is not a registered agent name, or None."""
    if name in DEPRECATED_AGENTS:
        return f"{name!r} is deprecated: use {DEPRECATED_AGENTS[name]!r}"
    if name in AGENTS or name in allowed or PLACEHOLDER.match(name) or not name:
        return None
    if re.fullmatch(r"[\w.]+:\w+", name):  # module:Class
        return None
    if "|" in name:  # a usage line: NAME|pkg.mod:Class
        return None
    return f"{name!r} is not a registered agent"


USER_PAGES = [p for p in PAGES if rel(p) != NOTEBOOK]


@pytest.mark.parametrize("page", USER_PAGES, ids=rel)
def test_agent_names_on_the_page_are_registered(page: Path) -> None:
    wrong = sorted({why for name, allowed in page_names(page) if (why := check(name, allowed))})
    assert not wrong, f"{rel(page)}: {wrong}"


def test_the_scan_finds_names_and_catches_a_stale_one(tmp_path: Path) -> None:
    """The check can fail: a deprecated and an unknown name are caught, in blocks and inline;
    a variable, a module:Class and a declared entry point pass."""
    page = tmp_path / "page.md"
    page.write_text(
        "Run `sfw-gym evaluate --agents frontier,ppo`.\n\n"
        "```bash\nA=frontier,nonesuch\n"
        "sfw-gym evaluate --agents $A --agent-params '{\"greedy\": {}}'\n"
        "sfw-gym benchmark run --agent pkg.mod:Cls --agent-params '{\"turn_steps\": 1}'\n"
        "sfw-gym benchmark run --agent mine\n```\n\n"
        '```toml\n[project.entry-points."sfw_gym.agents"]\nmine = "my_agent:MyAgent"\n```\n',
        encoding="utf-8",
    )
    found = page_names(page)
    assert {n for n, _ in found} == {"frontier", "ppo", "nonesuch", "greedy", "pkg.mod:Cls", "mine"}
    wrong = {n for n, allowed in found if check(n, allowed)}
    assert wrong == {"ppo", "nonesuch"}

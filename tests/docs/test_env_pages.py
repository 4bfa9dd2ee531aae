"""Every registered env id has its reference page, and the page prints the env's real spaces.

The pages (``docs/envs/reference/``) are written by the docs build from the registry
(:mod:`sfw_gym.envs.reference`); they are committed, so these tests also hold them to what the
generator writes now.
"""

from __future__ import annotations

import re

import gymnasium as gym
import pytest

import sfw_gym
from sfw_gym.envs import ENV_HISTORY, ENV_SUMMARIES
from sfw_gym.envs.reference import pages
from tests.docs.pages import DOCS

REFERENCE = DOCS / "envs" / "reference"
#: Every id the package registers, read from Gymnasium's registry (not from a list of ours).
REGISTERED = sorted(
    i for i, spec in gym.registry.items() if str(spec.entry_point).startswith("sfw_gym.")
)


def row(text: str, name: str) -> str | None:
    """The code in the ``| name | `code` |`` row of a page's first table."""
    found = re.search(rf"^\| {name} \| `(.*)` \|$", text, re.M)
    return found.group(1) if found else None


def test_the_registry_is_what_sfw_gym_registers():
    assert REGISTERED == sorted(sfw_gym.ENV_IDS) and len(REGISTERED) == 12
    assert set(ENV_SUMMARIES) == set(ENV_HISTORY) == set(REGISTERED)


@pytest.mark.parametrize("env_id", REGISTERED)
def test_each_id_has_a_page_that_prints_its_real_spaces(env_id):
    page = REFERENCE / f"{env_id}.md"
    assert page.exists(), f"no reference page for {env_id}: build the docs or run " \
        "python -m sfw_gym.envs.reference docs/envs/reference"  # fmt: skip
    text = page.read_text(encoding="utf-8")
    env = gym.make(env_id)
    assert text.startswith(f"# {env_id}\n")
    assert f'env = gym.make("{env_id}")' in text and "import sfw_gym" in text
    assert row(text, "Action Space") == str(env.action_space)
    assert row(text, "Observation Space") == str(env.observation_space)
    for key, space in env.observation_space.spaces.items():  # the per-key table
        assert f"| `{key}` | `{space}` | `{space.shape}` | `{space.dtype}` |" in text, key
    listed = re.findall(r"^\| `(\w+)` \| `[^`]*` \|", text, re.M)
    assert sorted(set(listed) & set(env.observation_space.spaces)) == sorted(
        env.observation_space.spaces
    )
    for section in ("Description", "Action Space", "Observation Space", "Rewards",
                    "Starting State", "Episode End", "Arguments", "Version History"):  # fmt: skip
        body = text.split(f"\n## {section}\n", 1)
        assert len(body) == 2 and body[1].strip(), f"{env_id}: no {section}"
    for version, note in ENV_HISTORY[env_id]:
        assert f"- {version}: {note}" in text
    env.close()


@pytest.mark.parametrize("env_id", REGISTERED)
def test_every_keyword_has_its_value_and_meaning(env_id):
    text = (REFERENCE / f"{env_id}.md").read_text(encoding="utf-8")
    table = text.split("| keyword | value | accepts | meaning |", 1)[1].split("\n\n", 1)[0]
    rows = [r for r in table.splitlines() if r.startswith("| `")]
    assert len(rows) > 20  # the explore env's keywords, at least
    cells = [[c.strip() for c in re.split(r"(?<!\\)\|", r)[1:-1]] for r in rows]
    assert all(len(c) == 4 for c in cells)
    empty = [c[0] for c in cells if not c[3]]
    assert not empty, f"{env_id}: keywords without a meaning in the docstring: {empty}"


def test_the_committed_pages_are_what_the_generator_writes():
    wanted = pages()
    assert sorted(p.name for p in REFERENCE.glob("*.md")) == sorted(wanted)
    stale = [n for n, t in wanted.items() if (REFERENCE / n).read_text(encoding="utf-8") != t]
    assert not stale, (f"stale env reference pages {stale}: build the docs or run "
                       "python -m sfw_gym.envs.reference docs/envs/reference")  # fmt: skip


def test_the_envs_page_and_the_reference_index_link_every_id_in_full():
    envs = (DOCS / "envs" / "index.md").read_text(encoding="utf-8")
    index = (REFERENCE / "index.md").read_text(encoding="utf-8")
    for env_id in REGISTERED:
        assert f"[`{env_id}`](reference/{env_id}.md)" in envs, env_id
        assert f"[`{env_id}`]({env_id}.md)" in index, env_id
    assert "`-Explore" not in envs  # no abbreviated ids

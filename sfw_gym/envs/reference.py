"""The env reference: one Markdown page per registered id, in Gymnasium's layout, from the code.

Each page prints the id's real spaces (from ``gym.make``), its sections (Description, Action
Space, Observation Space, Rewards, Starting State, Episode End) from the env class's docstring,
its arguments from the config dataclasses (this id's value and what each accepts) with their
meaning from the docstring's ``Arguments``/``Args`` entries, and its versions from
:data:`~sfw_gym.envs.ENV_HISTORY`. The docs build writes them (``docs/conf.py``), and so does
``python -m sfw_gym.envs.reference docs/envs/reference``.
"""

from __future__ import annotations

import dataclasses
import inspect
import re
import sys
import textwrap
from pathlib import Path
from typing import Any

import gymnasium as gym
from gymnasium import spaces

from sfw_gym.core.config import Range
from sfw_gym.envs import ENTRY_POINT, ENTRY_POINTS, ENV_HISTORY, ENV_IDS, ENV_SUMMARIES

#: The sections of an env class's docstring a page shows, in Gymnasium's order.
SECTIONS = (
    "Description",
    "Action Space",
    "Observation Space",
    "Rewards",
    "Starting State",
    "Episode End",
)
_ARGUMENTS = ("Arguments", "Args")
_HEADER = re.compile(r"^(\w[\w ]*):$")
_ENTRY = re.compile(r"^(\*{0,2}\w+)(?: \([^)]*\))?: ?(.*)$")
_ROLE = re.compile(r":(\w+):`([^`]+)`")
#: The families' overview pages (relative to the reference folder), by id.
_EXPLORE, _DECISIONS = ("explore", "../explore.md"), ("decisions", "../decisions.md")
_DRIFT = ("drift and SLAM", "../drift-slam.md")
FAMILY = {
    "SfW-Explore-v0": _EXPLORE,
    "SfW-ExploreFull-v0": _EXPLORE,
    "SfW-ExploreDiscrete-v0": _EXPLORE,
    "SfW-ExploreThick-v0": _EXPLORE,
    "SfW-ExploreResidential-v0": _EXPLORE,
    "SfW-ExploreSmall-v0": _EXPLORE,
    "SfW-ExploreGoals-v0": _DECISIONS,
    "SfW-ExploreRegions-v0": _DECISIONS,
    "SfW-ExploreDrift-v0": _DRIFT,
    "SfW-ExploreRadioSLAM-v0": _DRIFT,
    "SfW-ExploreLidar-v0": _DRIFT,
    "SfW-Localize-v0": ("localise", "../localize.md"),
}


def docstring_sections(cls: type) -> dict[str, str]:
    """The ``Name:`` sections of a class's (Google-style) docstring, each dedented; the text
    before the first section under ``""``."""
    lines = inspect.cleandoc(cls.__doc__ or "").splitlines()
    out: dict[str, list[str]] = {"": []}
    name = ""
    for line in lines:
        header = _HEADER.match(line)
        if header:
            name = header.group(1)
            out[name] = []
        elif name and line and not line.startswith(" "):
            name = ""  # back at the docstring's own indentation: the section ended
            out[""].append(line)
        else:
            out[name].append(line)
    return {k: textwrap.dedent("\n".join(v)).strip() for k, v in out.items()}


def argument_docs(cls: type) -> dict[str, str]:
    """``name → meaning`` from the ``Arguments:`` or ``Args:`` section of a class's docstring."""
    sections = docstring_sections(cls)
    text = next((sections[s] for s in _ARGUMENTS if s in sections), "")
    out: dict[str, str] = {}
    name = None
    for line in text.splitlines():
        entry = _ENTRY.match(line)
        if entry and not line.startswith(" "):
            name = entry.group(1).lstrip("*")
            out[name] = entry.group(2)
        elif name is not None:
            out[name] += " " + line.strip()
    return out


def markdown(rest: str) -> str:
    """reST inline markup of a docstring as MyST Markdown (``:role:`x``` → ``{role}`x```)."""
    return _ROLE.sub(r"{\1}`\2`", rest)


def _cell(text: str) -> str:
    return markdown(text).replace("|", "\\|").replace("\n", " ")


def _value(value: Any) -> str:
    return f"`{value!r}`"


def _accepts(f: dataclasses.Field[Any]) -> str:
    rng = f.metadata.get("range")
    return rng.describe() if isinstance(rng, Range) else str(f.type)


def _config_table(config: Any) -> list[str]:
    rows = ["| field | value | accepts |", "|---|---|---|"]
    for f in dataclasses.fields(config):
        value = getattr(config, f.name)
        rows.append(f"| `{f.name}` | {_value(value)} | {_cell(_accepts(f))} |")
    return rows


def _section_text(classes: list[type], name: str) -> str:
    """The first of ``classes`` whose docstring has the section (own class, its bases, then the
    explore env that every env wraps)."""
    for cls in classes:
        text = docstring_sections(cls).get(name)
        if text:
            return markdown(text)
    return ""


def _classes(cls: type) -> list[type]:
    from sfw_gym.envs.explore import SfWExploreEnv

    own = [c for c in cls.__mro__ if c.__module__.startswith("sfw_gym.envs")]
    return [*own, SfWExploreEnv] if SfWExploreEnv not in own else own


def _space_rows(space: spaces.Space[Any]) -> list[str]:
    if not isinstance(space, spaces.Dict):
        return [f"`{space}`"]
    rows = ["| key | space | shape | dtype |", "|---|---|---|---|"]
    for key, sub in space.spaces.items():
        rows.append(f"| `{key}` | `{sub}` | `{sub.shape}` | `{sub.dtype}` |")
    return rows


def _budget(explore: Any) -> str:
    cfg = explore.config.explore
    if cfg.steps_per_m2 is None:
        return f"This id's step budget: `max_steps` = {cfg.max_steps:,} steps."
    return (
        f"This id's step budget: `min(max_steps, ceil(steps_per_m2 × free area))` with "
        f"`steps_per_m2` = {cfg.steps_per_m2:g} steps per m² and `max_steps` = "
        f"{cfg.max_steps:,}."
    )


def _arguments(env_id: str, env: Any, classes: list[type]) -> list[str]:
    """The keyword arguments of ``gym.make(env_id, ...)``: this id's value, what each accepts
    and its meaning; then each dict of overrides' fields."""
    from sfw_gym.envs.explore import SfWExploreEnv

    explore = getattr(env, "explore", env)
    cfg = explore.config
    flat = {f.name: (f, getattr(c, f.name)) for c in (cfg.explore, cfg.reward)
            for f in dataclasses.fields(c)}  # fmt: skip
    meanings: dict[str, str] = {}
    for cls in reversed(classes):
        meanings.update(argument_docs(cls))
    own = env.config if env is not explore else None  # a wrapper's own settings
    subsystems: dict[str, Any] = {
        "generator": cfg.generator, "radio": cfg.radio, "robot": cfg.robot,
        "mapper": cfg.mapper, "slam": cfg.slam,
    }  # fmt: skip
    if own is not None:
        subsystems = {own.prefix: own, **subsystems}
    names: list[str] = []
    for cls in (classes[0], SfWExploreEnv):  # the entry point's own, then those it passes on
        params = list(inspect.signature(cls).parameters.values())
        names += [p.name for p in params if p.kind is not p.VAR_KEYWORD and p.name not in names]
        if not any(p.kind is p.VAR_KEYWORD for p in params):
            break
    rows = [
        f'`gym.make("{env_id}", **kwargs)` takes these keyword arguments; "value" is this id\'s '
        f"(the registered kwargs `{ENV_IDS[env_id]!r}` over the defaults).",
        "",
        "| keyword | value | accepts | meaning |",
        "|---|---|---|---|",
    ]
    defaults = {p.name: p.default for p in inspect.signature(SfWExploreEnv).parameters.values()}
    for name in names:
        meaning = _cell(meanings.get(name, ""))
        if name in flat:
            f, value = flat[name]
            rows.append(f"| `{name}` | {_value(value)} | {_cell(_accepts(f))} | {meaning} |")
        elif name in subsystems or name == "lidar":
            config = cfg.lidar if name == "lidar" else subsystems[name]
            shown = "`None` (off)" if config is None else "see below"
            rows.append(f"| `{name}` | {shown} | a dict of overrides | {meaning} |")
        elif name == "floorplan":
            rows.append(f"| `{name}` | {_value(cfg.floorplan)} |  | {meaning} |")
        else:
            value = getattr(env, name, defaults.get(name))
            value = list(value) if isinstance(value, tuple) else value
            rows.append(f"| `{name}` | {_value(value)} |  | {meaning} |")
    lidar = cfg.lidar
    if lidar is None:
        from sfw_gym.world.lidar import LidarConfig

        lidar = LidarConfig()
    for name, config in [*subsystems.items(), ("lidar", lidar)]:
        doc = inspect.getdoc(type(config)) or ""
        first = " ".join(doc.split("\n\n")[0].split())
        off = (
            " (off for this id: these are the defaults of `lidar={}`)"
            if (name == "lidar" and cfg.lidar is None)
            else ""
        )
        rows += ["", f"### `{name}`: {type(config).__name__}", "", f"{markdown(first)}{off}", ""]
        rows += _config_table(config)
    return rows


def page(env_id: str) -> str:
    """The reference page of ``env_id``, as Markdown."""
    env = gym.make(env_id)
    unwrapped = env.unwrapped
    classes = _classes(type(unwrapped))
    entry = ENTRY_POINTS.get(env_id, ENTRY_POINT)
    family, family_page = FAMILY.get(env_id, ("the environments", "../index.md"))
    explore = getattr(unwrapped, "explore", unwrapped)
    out = [
        f"# {env_id}",
        "",
        "<!-- Generated by sfw_gym.envs.reference from the registry and the env's docstrings "
        "(the docs build writes it): edit those, not this page. -->",
        "",
        markdown(ENV_SUMMARIES[env_id]),
        "",
        "| | |",
        "|---|---|",
        f"| Action Space | `{env.action_space}` |",
        f"| Observation Space | `{env.observation_space}` |",
        f'| import | `import sfw_gym` then `gym.make("{env_id}")` |',
        f"| entry point | `{entry}` |",
        f"| registered kwargs | `{ENV_IDS[env_id]!r}` |",
        f"| family | [{family}]({family_page}) |",
        "",
        "```python",
        "import gymnasium as gym",
        "import sfw_gym  # registers the SfW ids",
        "",
        f'env = gym.make("{env_id}")',
        "```",
    ]
    for name in SECTIONS:
        out += ["", f"## {name}", ""]
        if name == "Action Space":
            out += [f"`{env.action_space}`", ""]
        elif name == "Observation Space":
            out += [*_space_rows(env.observation_space), ""]
        out.append(_section_text(classes, name))
        if name == "Episode End":
            out += ["", _budget(explore)]
    out += ["", "## Arguments", "", *_arguments(env_id, unwrapped, classes)]
    out += ["", "## Version History", ""]
    out += [f"- {version}: {note}" for version, note in ENV_HISTORY[env_id]]
    env.close()
    return "\n".join(out) + "\n"


def index() -> str:
    """The reference's index page: every id, its summary, and the toctree of the pages."""
    out = [
        "# Env reference",
        "",
        "<!-- Generated by sfw_gym.envs.reference from the registry: edit that, not this page. -->",
        "",
        "One page per registered id, generated from the code: the spaces `gym.make` gives, the "
        "env's docstring, its settings and its versions. The families' overviews: "
        "[the environments](../index.md).",
        "",
        "| id | what it is |",
        "|---|---|",
    ]
    out += [f"| [`{i}`]({i}.md) | {_cell(ENV_SUMMARIES[i])} |" for i in ENV_IDS]
    out += ["", "```{toctree}", ":hidden:", "", *ENV_IDS, "```"]
    return "\n".join(out) + "\n"


def pages() -> dict[str, str]:
    """Every page of the reference by file name: ``index.md`` and ``<id>.md`` per registered id."""
    return {"index.md": index(), **{f"{env_id}.md": page(env_id) for env_id in ENV_IDS}}


def write(folder: str | Path) -> list[Path]:
    """Write the reference into ``folder``: the pages that changed (written only then, so a
    build does not see every page as new) and removing pages of ids no longer registered."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    wanted, changed = pages(), []
    for old in folder.glob("*.md"):
        if old.name not in wanted:
            old.unlink()
            changed.append(old)
    for name, text in wanted.items():
        path = folder / name
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")
            changed.append(path)
    return changed


if __name__ == "__main__":  # pragma: no cover
    for path in write(sys.argv[1] if len(sys.argv) > 1 else "docs/envs/reference"):
        print(path)

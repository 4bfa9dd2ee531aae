"""What several ``sfw-gym`` commands share: the option types (``type=`` callables whose bad
input is argparse's usage error, exit 2), the help formatter that shows every default in one
format, and the argparse blocks that more than one command adds."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from sfw_gym.core.errors import ConfigError

#: An argparse parser or argument group: where an option block is added.
Options = argparse._ActionsContainer

#: The env most commands run on when no ``--env`` is given.
DEFAULT_ENV = "SfW-Explore-v0"


def checked(convert: Callable, ok: Callable, what: str) -> Callable:
    """An argparse ``type=``: ``convert(text)``, which must satisfy ``ok``; anything else is
    argparse's usage error, exit 2, its last line naming the option ("argument --steps: ...")."""

    def parse(text: str):
        try:
            value = convert(text)
            good = ok(value)
        except ValueError:
            good = False
        if not good:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}")
        return value

    return parse


positive_int = checked(int, lambda v: v >= 1, "an integer >= 1")
non_negative_int = checked(int, lambda v: v >= 0, "an integer >= 0")
seed_int = checked(int, lambda v: 0 <= v < 2**32, "a seed in [0, 2**32)")
positive_float = checked(float, lambda v: math.isfinite(v) and v > 0, "a finite number > 0")
non_negative_float = checked(float, lambda v: math.isfinite(v) and v >= 0, "a finite number >= 0")
unit_float = checked(float, lambda v: 0 <= v <= 1, "a number in [0, 1]")
folder = checked(str, lambda v: not Path(v).exists() or Path(v).is_dir(), "a folder, not a file")


def parse_routers(text: str) -> np.ndarray | int:
    """``"x1,y1;x2,y2"`` → (R, 2) array of positions; ``"3"`` → a router count (≥ 1)."""
    text = text.strip()
    if text.isdigit() and int(text) >= 1:
        return int(text)
    try:
        pts = [[float(v) for v in pair.split(",")] for pair in text.split(";") if pair.strip()]
        arr = np.array(pts, dtype=np.float64)
    except ValueError:
        arr = np.empty((0,))
    if arr.ndim != 2 or arr.shape[1] != 2 or len(arr) == 0 or not np.isfinite(arr).all():
        raise ConfigError(f"--routers: expected a count >= 1 or 'x1,y1;x2,y2;…', got {text!r}")
    return arr


#: ``--routers``' help where it places the routers of one plan (``world``, ``record``).
ROUTERS_HELP = "a count, or positions 'x1,y1;x2,y2' (m) (default: the plan's own routers, else 2)"
#: ``--routers``' help where it places every episode's (``evaluate``, ``benchmark run``).
EPISODE_ROUTERS_HELP = (
    "every episode's routers: a count, or positions 'x1,y1;x2,y2' (m) (default: a plan's own "
    "routers, else the env's n_routers placed by k-means)"
)


def add_routers(parser: Options, help: str = ROUTERS_HELP) -> None:
    """``--routers``: a count or positions in metres, read by :func:`optional_routers` (its
    bad input a one-line error naming ``--routers``); the order of who places the routers is
    :func:`~sfw_gym.world.floorplan.chosen_routers`'."""
    parser.add_argument("--routers", default=None, help=help)


def optional_routers(text: str | None) -> np.ndarray | int | None:
    """:func:`parse_routers` of an optional ``--routers`` (None: not given)."""
    return None if text is None else parse_routers(text)


def agents_from_here() -> None:
    """Let an agent's ``module:Class`` name a module of the current folder, as ``python -m``
    would (the worker processes, spawned, inherit the path)."""
    import sys

    if str(Path.cwd()) not in sys.path:
        sys.path.insert(0, str(Path.cwd()))


def json_object(option: str, text: str | None) -> dict:
    """A command-line JSON object (empty when not given), or a one-line error naming ``option``."""
    import json

    try:
        value = json.loads(text) if text else {}
    except json.JSONDecodeError as exc:
        raise ConfigError(f"{option}: not valid JSON ({exc})") from None
    if not isinstance(value, dict):
        raise ConfigError(f"{option}: expected a JSON object, got {text!r}")
    return value


def shown_default(value: Any) -> str:
    """An option's default as its help shows it: a list comma-joined, an empty one ``none``."""
    if isinstance(value, (list, tuple)):
        value = ",".join(map(str, value))
    return str(value) if value != "" else "none"


def shows_default(action: argparse.Action) -> bool:
    """Whether ``action``'s help ends in ``(default: …)``: an option that takes a value and has a
    default (not a flag, not a positional, not one whose default is None)."""
    return (
        bool(action.option_strings)
        and action.nargs != 0
        and action.default is not None
        and action.default is not argparse.SUPPRESS
    )


class HelpWithDefaults(argparse.RawDescriptionHelpFormatter):
    """Help that ends every option's text with its default in one format, ``(default: X)``
    (:func:`shows_default`, :func:`shown_default`), and keeps descriptions and the example's
    line as written."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        if not shows_default(action):
            return text
        return f"{text} (default: {shown_default(action.default).replace('%', '%%')})"


def add_command(
    sub: argparse._SubParsersAction,
    name: str,
    run: Callable[[argparse.Namespace], int],
    example: str | None = None,
    **kwargs: Any,
) -> argparse.ArgumentParser:
    """A subcommand's parser: help with its defaults, ``example`` at its end, ``run`` its
    handler (``args.func``)."""
    parser = sub.add_parser(name, formatter_class=HelpWithDefaults, **kwargs)
    if example:
        parser.epilog = f"example:\n  {example}"
    parser.set_defaults(func=run)
    return parser


def add_env(parser: Options, default: str = DEFAULT_ENV, help: str = "env id") -> None:
    """``--env``: a registered env id."""
    parser.add_argument("--env", default=default, help=help)


def add_seed(parser: Options, help: str, default: int = 0) -> None:
    """``--seed``: a seed in [0, 2**32)."""
    parser.add_argument("--seed", type=seed_int, default=default, help=help)


def add_out_folder(parser: Options, default: str | None, help: str) -> None:
    """``--out``: a folder (an existing file is a usage error)."""
    parser.add_argument("--out", type=folder, default=default, help=help)


def add_workers(parser: Options) -> None:
    """``--workers``: worker processes."""
    parser.add_argument("--workers", type=positive_int, default=2, help="worker processes")


def add_no_progress(parser: Options) -> None:
    """``--no-progress``."""
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")


#: ``--address``'s help where no address is given: Ray starts on this machine.
LOCAL_RAY = "a local Ray instance, started for the run"


def add_backend(parser: Options, choices: list[str], help: str) -> None:
    """``--backend``: where the work runs, the first of ``choices`` unless told."""
    parser.add_argument("--backend", choices=choices, default=choices[0], help=help)


def add_episode_runner_options(parser: Options) -> None:
    """Where the jobs (episodes, the study's plans) run, the executor's options: ``--workers``,
    ``--backend``, ``--address``, ``--no-progress`` (:func:`runner_settings` reads them)."""
    add_workers(parser)
    add_backend(
        parser,
        ["local", "ray"],
        "run the jobs in local worker processes or as Ray tasks (pip install sfw-gym[ray])",
    )
    parser.add_argument(
        "--address",
        default=None,
        help=f"with --backend ray: a cluster's address ('auto') (default: {LOCAL_RAY})",
    )
    add_no_progress(parser)


def runner_settings(args: argparse.Namespace) -> dict[str, Any]:
    """The executor's keyword arguments from :func:`add_episode_runner_options`' options."""
    return {
        "workers": args.workers,
        "backend": args.backend,
        "address": args.address,
        "progress": not args.no_progress,
    }

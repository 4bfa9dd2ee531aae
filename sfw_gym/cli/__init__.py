"""The ``sfw-gym`` command: :func:`main` (the console entry point) and :func:`build_parser`.

One module per command, named after it, holds its options beside its code: ``HELP`` (its line
in ``sfw-gym --help``), ``EXAMPLE`` (the last of its own help), ``add_options(parser)`` and
``run(args)``, which carries it out (exit status 0); some add ``ALIASES`` and ``DESCRIPTION``.
:mod:`sfw_gym.cli.options` holds what several commands share: the option types, the argparse
blocks, the help formatter that shows every default as ``(default: X)``. The commands import
the library when they run, not before, so that ``sfw-gym --help`` and the commands without a
learned agent need no torch.
"""

from __future__ import annotations

import argparse
import logging
import sys
from collections.abc import Sequence

from sfw_gym.cli import (
    benchmark,
    demo,
    evaluate,
    fingerprints,
    localize,
    record,
    slam,
    speed,
    train,
    world,
)
from sfw_gym.cli import map as map_log
from sfw_gym.cli.options import add_command
from sfw_gym.core.errors import SfwGymError

#: The commands, in the order ``sfw-gym --help`` lists them.
COMMANDS = (
    demo,
    world,
    map_log,
    record,
    slam,
    fingerprints,
    localize,
    speed,
    train,
    evaluate,
    benchmark,
)
#: One example per command, shown at the end of its ``--help``.
EXAMPLES = {command.__name__.rpartition(".")[2]: command.EXAMPLE for command in COMMANDS}


def version() -> str:
    """The installed distribution's version (the package's own where it is not installed)."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as installed

    try:
        return installed("sfw-gym")
    except PackageNotFoundError:
        from sfw_gym import __version__

        return __version__


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every command."""
    parser = argparse.ArgumentParser(
        prog="sfw-gym", description="Active WiFi exploration: worlds, mapping, agents."
    )
    parser.add_argument("--version", action="version", version=f"sfw-gym {version()}")
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an error (else one line)"
    )
    noise = parser.add_mutually_exclusive_group()
    noise.add_argument(
        "-v", "--verbose", action="count", default=0, help="the library's log: -v info, -vv debug"
    )
    noise.add_argument(
        "-q", "--quiet", action="store_true", help="errors only (no warnings from the library)"
    )
    sub = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        name = command.__name__.rpartition(".")[2]
        command.add_options(
            add_command(
                sub,
                name,
                command.run,
                command.EXAMPLE,
                help=command.HELP,
                aliases=getattr(command, "ALIASES", []),
                description=getattr(command, "DESCRIPTION", None),
            )
        )
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``sfw-gym``: exit status 0; 2 with a one-line error for bad input; 1 with
    a one-line error for any other failure (``--debug``: the traceback instead); 130 on Ctrl-C."""
    import gymnasium as gym

    argv = benchmark.bare_runs(list(sys.argv[1:] if argv is None else argv))
    args = build_parser().parse_args(argv)
    # -v/-vv raise the package's log only (not numba's or matplotlib's); -q: errors only.
    levels = (logging.WARNING, logging.INFO, logging.DEBUG)
    level = logging.ERROR if args.quiet else levels[min(args.verbose, 2)]
    logging.basicConfig(
        format="%(levelname)s %(name)s: %(message)s",
        level=logging.ERROR if args.quiet else logging.WARNING,
        force=True,
    )
    logging.getLogger("sfw_gym").setLevel(level)
    try:
        return args.func(args)
    except (SfwGymError, gym.error.Error) as exc:
        if args.debug:
            raise
        status, message = 2, str(exc)
        if isinstance(exc, gym.error.Error):  # e.g. NameNotFound: an unknown env id
            message = f"--env {getattr(args, 'env', '')}: {exc}"
    except KeyboardInterrupt:
        print(f"sfw-gym {args.command}: interrupted", file=sys.stderr)
        return 130
    except Exception as exc:  # a failure, not bad input: one line unless --debug
        if args.debug:
            raise
        status = 1
        message = f"failed: {type(exc).__name__}: {exc} (run with --debug for the traceback)"
    # One line, even when the message quotes a multi-line parser error (YAML, JSON).
    print(f"sfw-gym {args.command}: error: {' '.join(message.split())}", file=sys.stderr)
    return status


__all__ = ["COMMANDS", "EXAMPLES", "build_parser", "main", "version"]

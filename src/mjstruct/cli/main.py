"""Entry point of the ``mjstruct`` command: parses arguments, dispatches, maps errors
to exit statuses (0 success, 2 bad input or usage, 1 internal or numerical error).

Each command lives in its own module of this package with ``add_arguments(parser)``
and ``run(args) -> int``; :data:`COMMANDS` lists them in the order ``--help`` shows.
"""

from __future__ import annotations

import argparse
import importlib
import signal
import sys
import threading
from collections.abc import Sequence
from typing import Any, NoReturn

from mjstruct.cli.output import check_outputs, emit_error
from mjstruct.errors import MechanismError, NumericalError

COMMANDS: dict[str, str] = {
    "analyze": "structural report of a mechanism file or of a structural code",
    "iso": "exact isomorphism of two mechanism files",
    "atlas": "all non-isomorphic admissible chains with F DOF and n links",
    "cells": "synthesis cells (K, V), their [MJA] and [LA], and realisable counts",
    "lookup": "find a mechanism's chain in the shipped catalogs",
    "kinematics": "positions, velocities, accelerations over one cycle (triangle rule)",
    "draw": "the mechanism drawn at a configuration, with layers (SVG, PNG, PDF)",
    "animate": "the mechanism animated over one cycle (GIF, HTML, MP4 with ffmpeg)",
    "plot": "charts against q: angles, ω, ε, paths, Jacobian, transmission angle",
    "assur": "Assur-group decomposition (MJs kept whole) and driver choices",
    "singular": "singular positions (input limits, output extremes, change points) and zones",
    "dynamics": "equation of motion, steady motion, joint reactions and actuator loads",
    "convert": "between mechanism JSON/TOML, pyslvs expressions, GraphML and node-link JSON",
    "synthesize": "dimensional synthesis: the dimensions that make a mechanism do a task",
    "planetary": "tooth numbers of the 2AA planetary train for a ratio",
}


class _Formatter(argparse.HelpFormatter):
    """argparse's help formatter, its width found without importing ``shutil``
    (argparse imports it for every parser: compression modules a start-up pays for)."""

    def __init__(
        self, prog: str, indent_increment: int = 2, max_help_position: int = 24,
        width: int | None = None,
    ) -> None:  # fmt: skip
        if width is None:
            width = _columns() - 2  # as argparse: the terminal's columns less two
        super().__init__(prog, indent_increment, max_help_position, width)


def _columns() -> int:
    """The terminal's width as ``shutil.get_terminal_size().columns`` gives it."""
    import os

    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns  # type: ignore[union-attr]
        except (AttributeError, ValueError, OSError):
            columns = 0
    return columns or 80


class _Parser(argparse.ArgumentParser):
    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", _Formatter)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:  # one line, exit 2
        emit_error(f"{self.prog}: error: {message}")
        raise SystemExit(2)


def build_parser(only: str | None = None) -> argparse.ArgumentParser:
    """The argument parser; with ``only``, just that command's parser and module.

    Without ``only`` every command is listed (the top-level help); with it only the
    command that runs is built and imported, which keeps the start-up of, say,
    ``mjstruct analyze`` free of the plotting and numerical modules and of a dozen
    argparse parsers.
    """
    parser = _Parser(
        prog="mjstruct", description="Structural analysis of planar linkages with multiple joints."
    )
    from mjstruct import __version__

    parser.add_argument("--version", action="version", version=f"mjstruct {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    for name, help_text in COMMANDS.items():
        if only is not None and name != only:
            continue  # a command that runs needs only its own parser (argparse is slow)
        p = sub.add_parser(name, help=help_text, description=help_text)
        if only is None or name == only:
            module = importlib.import_module(f"mjstruct.cli.{name}")
            module.add_arguments(p)
            p.set_defaults(_run=module.run)
    return parser


def _command_in(argv: Sequence[str]) -> str | None:
    """The command named in ``argv`` (the first word that is not an option); None when
    a help option comes first (the top-level help lists every command)."""
    for a in argv:
        if a in ("-h", "--help"):
            return None
        if not a.startswith("-"):
            return a if a in COMMANDS else None
    return None


class _Terminated(BaseException):
    """SIGTERM, raised in the main thread so that pools and temporary files close."""


def _on_sigterm(signum: int, frame: object) -> None:
    raise _Terminated


def main(argv: Sequence[str] | None = None) -> int:
    words = sys.argv[1:] if argv is None else list(argv)
    # signals first: one landing while the parser is built is handled as any other
    previous = _install_sigterm()
    command = _command_in(words)
    try:
        args = build_parser(command).parse_args(words)
        command = args.command
        check_outputs(args)  # links, loops, output onto input: before any work
        return int(args._run(args))
    except _Terminated:
        emit_error("mjstruct: terminated")
        return 143
    except MechanismError as exc:
        emit_error(f"mjstruct {command}: {exc}")
        return 2
    except NumericalError as exc:
        emit_error(f"mjstruct {command}: numerical trouble: {exc}")
        return 1
    except KeyboardInterrupt:
        emit_error("mjstruct: interrupted")
        return 130
    except BrokenPipeError:
        return 0
    except Exception as exc:  # an internal error still gets one line, not a traceback
        emit_error(f"mjstruct {command}: internal error: {exc.__class__.__name__}: {exc}")
        return 1
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def _install_sigterm() -> Any:
    """Handle SIGTERM as an exception (main thread only); returns the old handler."""
    if threading.current_thread() is not threading.main_thread():
        return None
    return signal.signal(signal.SIGTERM, _on_sigterm)


if __name__ == "__main__":
    raise SystemExit(main())

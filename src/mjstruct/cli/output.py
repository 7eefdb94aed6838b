"""Writing a command's result (one JSON object, or text, on standard output) and reading
the arguments several commands share.

JSON is indented by object, with every list of plain values kept on one line, so that
long numeric columns (kinematics) stay compact and reports stay readable.

>>> print(dumps({"LA": [8, 1, 1], "checks": {"K": {"formula": 4}}}))
{
 "LA": [8, 1, 1],
 "checks": {
  "K": {
   "formula": 4
  }
 }
}
"""

from __future__ import annotations

import argparse
import json
import os
import re
import select
import signal
import stat
import sys
import threading
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from functools import partial
from typing import TYPE_CHECKING, Any

from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    from mjstruct.mechanism import Mechanism


def dumps(obj: Any, level: int = 0) -> str:
    """JSON text: objects and lists of objects indented, lists of plain values inline."""
    pad, inner = " " * level, " " * (level + 1)
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = [
            f"{inner}{json.dumps(str(k), ensure_ascii=False)}: {dumps(v, level + 1)}"
            for k, v in obj.items()
        ]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, (list, tuple)) and any(isinstance(x, (dict, list, tuple)) for x in obj):
        items = [inner + dumps(x, level + 1) for x in obj]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return json.dumps(obj, ensure_ascii=False, allow_nan=False, separators=(", ", ": "))


_C1 = re.compile("[\x7f-\x9f]")  # json.dumps leaves these raw with ensure_ascii=False


def emit_json(obj: Any) -> None:
    """One JSON object; no raw control character reaches the terminal."""
    text = _C1.sub(lambda c: f"\\u{ord(c.group()):04x}", dumps(obj))
    _write_whole(text + "\n")


def _write_whole(text: str) -> None:
    """Standard output written whole: a SIGINT or SIGTERM arriving meanwhile waits until
    the text is out (a reader never gets half a JSON object), then stops the command;
    but it waits no more than a second for a reader that has stopped reading."""
    try:
        fd: int | None = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # a stream in memory: one call
        fd = None
    if fd is None or threading.current_thread() is not threading.main_thread():
        sys.stdout.write(text)
        return
    held = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        sys.stdout.flush()
        _write_fd(fd, text.encode(sys.stdout.encoding, sys.stdout.errors or "strict"), held)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _write_fd(fd: int, data: bytes, held: set[signal.Signals]) -> None:
    """``data`` to ``fd`` in pieces a pipe takes without blocking, while no held signal is
    pending, or while the reader keeps taking them (a second at most between pieces)."""
    view = memoryview(data)
    piece = len(data) if stat.S_ISREG(os.fstat(fd).st_mode) else select.PIPE_BUF
    while view:
        pending = bool(signal.sigpending() & held)
        if not select.select([], [fd], [], 1.0 if pending else 0.2)[1]:
            if pending:
                return  # the reader stopped: the signal acts, the output stays short
            continue
        view = view[os.write(fd, view[:piece]) :]


_CONTROL = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f]")
_CONTROL_ALL = re.compile("[\x00-\x1f\x7f-\x9f]")


def printable(text: str, one_line: bool = False) -> str:
    r"""``text`` with control characters (terminal escapes) shown as ``\xNN``; newlines
    and tabs kept unless ``one_line`` (an error message: a file name holding a newline
    must not split it).

    >>> printable("Watt\x1b[31m six-bar\n")
    'Watt\\x1b[31m six-bar\n'
    >>> printable("/tmp/a\nb\x1b[31m: no such file", one_line=True)
    '/tmp/a\\x0ab\\x1b[31m: no such file'
    """
    pattern = _CONTROL_ALL if one_line else _CONTROL
    return pattern.sub(lambda c: f"\\x{ord(c.group()):02x}", text)


def emit_error(text: str) -> None:
    """One line on standard error; paths and names in it cannot drive the terminal."""
    sys.stderr.write(printable(text, one_line=True) + "\n")


def emit_text(text: str) -> None:
    """Text output: names from files and caches cannot drive the terminal."""
    _write_whole(printable(text.rstrip("\n")) + "\n")


@contextmanager
def flag_names(**flags: str) -> Iterator[None]:
    """Re-raise a library error that names a parameter as one naming the command's flag.

    Library functions speak of their parameters; inside this block an error naming a
    parameter given here is re-raised naming the flag instead, for the values that came
    from the command line:

    - a message that starts with the parameter (``drivers: ...``) starts with the flag;
    - a parameter whose name holds an underscore (an identifier, never a word of the
      sentence) is replaced wherever it stands outside a path, and its keyword form
      ``name='value'`` becomes ``--flag value``.

    >>> try:
    ...     with flag_names(drivers="--drivers"):
    ...         raise MechanismError("drivers: 'X' is not a joint id")
    ... except MechanismError as exc:
    ...     print(exc)
    --drivers: 'X' is not a joint id
    >>> try:
    ...     with flag_names(pin_slot="--pin-slot", max_memory="--max-memory"):
    ...         raise MechanismError("a.pmks: retry with pin_slot='block' (or max_memory)")
    ... except MechanismError as exc:
    ...     print(exc)
    a.pmks: retry with --pin-slot block (or --max-memory)
    """
    try:
        yield
    except MechanismError as exc:
        text = renamed = str(exc)
        for name, flag in flags.items():
            if renamed.startswith(name + ":"):
                renamed = flag + renamed[len(name) :]
            if "_" in name:
                renamed = re.sub(
                    rf"(?<![\w./\\-]){re.escape(name)}(?:='([^']*)')?(?![\w/\\])",
                    partial(_as_flag, flag),
                    renamed,
                )
        if renamed != text:
            raise MechanismError(renamed) from None
        raise


def _as_flag(flag: str, mt: re.Match[str]) -> str:
    """``--flag`` for a parameter's name, ``--flag value`` for its ``name='value'``."""
    return flag if mt[1] is None else f"{flag} {mt[1]}"


def driver_list(text: str | None, m: Mechanism) -> list[str] | None:
    """``--drivers J1,J2`` as joint ids of ``m`` (None when the option was not given).

    Checks that each is a joint id named once; whether they drive the mechanism is
    the analysis's check (:func:`mjstruct.structure.drivers.validate_drivers`).
    """
    from mjstruct.structure.drivers import validate_drivers

    if text is None:
        return None
    drivers = [d.strip() for d in text.split(",") if d.strip()]
    with flag_names(drivers="--drivers"):
        validate_drivers(m, drivers, balance=False)
    return drivers


#: the argument names of the files a command writes, and their flags
OUTPUT_FLAGS = {
    "output": "-o",
    "csv": "--csv",
    "draw": "--draw",
    "history": "--history",
    "targets_chart": "--targets-chart",
}
#: the argument names of the files a command reads
INPUT_ARGUMENTS = ("file", "input", "file_a", "file_b", "task")


def check_outputs(args: argparse.Namespace, extra_inputs: Mapping[str, str] | None = None) -> None:
    """Refuse, before any work, an output that cannot be written as the contract says.

    Each output a command was given (``-o``, ``--csv``, ``--draw``) is checked with
    its links followed (:func:`mjstruct.output_files.output_target`): a loop of links,
    a directory or a link to a file of another kind is bad input naming the flag, and
    so is an output that is the very file the command reads (writing it would destroy
    the input; ``extra_inputs`` adds files the input names, each with its description,
    such as a task's mechanism file) or the file of another output (one would silently
    replace the other).

    >>> ns = argparse.Namespace(file="four-bar.json", output="four-bar.json")
    >>> check_outputs(ns)
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: -o: four-bar.json is the input file (write elsewhere)
    """
    outputs = [(a, f) for a, f in OUTPUT_FLAGS.items() if isinstance(getattr(args, a, None), str)]
    if not outputs:
        return  # nothing written to a file (and nothing imported for it)
    import os

    from mjstruct.output_files import output_target, same_file

    inputs = {
        path: "the input file"
        for path in (getattr(args, a, None) for a in INPUT_ARGUMENTS)
        if isinstance(path, str) and path != "-"
    }
    inputs.update(extra_inputs or {})
    written: dict[str, str] = {}  # the file each output names -> its flag
    for attr, flag in outputs:
        out = getattr(args, attr, None)
        if not isinstance(out, str) or out == "-":
            continue
        for path, what in inputs.items():  # first: the most telling refusal
            if same_file(path, out) or os.path.realpath(path) == os.path.realpath(out):
                raise MechanismError(f"{flag}: {out} is {what} (write elsewhere)")
        target = str(output_target(out, flag))  # loops, directories, links to another kind
        if target in written:
            raise MechanismError(
                f"{flag}: {out} is also the output of {written[target]} (write elsewhere)"
            )
        written[target] = flag

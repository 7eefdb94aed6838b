"""Writing figures and animations to files: suffix check, then an atomic replace.

Owns the rule that a drawing command either writes its whole output or nothing: the
output's suffix is checked against the writers that handle it and its directory for
writability *before* anything is computed, and the file is written to a temporary
name in the target directory and moved into place with :func:`os.replace`, so an
error (or an interrupt) never leaves a partial file behind.

Examples
--------
>>> check_output("out.svg", FIGURE_SUFFIXES)
'.svg'
>>> check_output("out.bmp", FIGURE_SUFFIXES, name="-o")
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: -o: no writer for '.bmp' (use one of .pdf, .png, .svg)
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path

from mjstruct import output_files
from mjstruct.errors import MechanismError

#: suffixes a still figure can be written to
FIGURE_SUFFIXES = (".svg", ".png", ".pdf")


def check_output(path: str, suffixes: Iterable[str], name: str = "path") -> str:
    """The lower-case suffix of ``path`` once it is known writable, else ``MechanismError``.

    ``name`` is what the message calls the path (a parameter or a command-line flag).
    """
    allowed = tuple(suffixes)
    suffix = Path(path).suffix.lower()
    if suffix not in allowed:
        choices = ", ".join(sorted(allowed))
        what = repr(suffix) if suffix else "a file without suffix"
        raise MechanismError(f"{name}: no writer for {what} (use one of {choices})")
    folder = output_files.output_target(path, name).parent  # links followed
    if not folder.is_dir():
        raise MechanismError(f"{name}: cannot write {path} (no directory {folder})")
    if not os.access(folder, os.W_OK):
        raise MechanismError(f"{name}: cannot write {path} (directory not writable)")
    # os.access says yes to root and to pseudo file systems (/proc, /sys): only creating
    # a file tells, and it must fail here, before anything is computed
    try:
        fd, probe = tempfile.mkstemp(prefix=".mjstruct-", suffix=suffix, dir=folder)
    except OSError as exc:
        reason = f"cannot create a file in {folder}: {_reason(exc)}"
        raise MechanismError(f"{name}: cannot write {path} ({reason})") from None
    os.close(fd)
    os.unlink(probe)
    return suffix


def write_atomically(path: str, write: Callable[[str], None], name: str = "path") -> None:
    """Call ``write(tmp)`` on a temporary file next to ``path``, then move it into place.

    The temporary file keeps the suffix of ``path`` as given (writers choose their
    format by it, also when ``path`` is a link to a file named otherwise); it is
    removed if ``write`` fails, so ``path`` is either complete or untouched
    (:func:`mjstruct.output_files.write_atomically`).
    """
    output_files.write_atomically(path, write, name)


def _reason(exc: OSError) -> str:
    """The system's words for a failed write, without the temporary file's name."""
    return exc.strerror or type(exc).__name__

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
    folder = Path(path).resolve().parent
    if not folder.is_dir():
        raise MechanismError(f"{name}: cannot write {path} (no directory {folder})")
    if Path(path).is_dir():
        raise MechanismError(f"{name}: {path} is a directory")
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

    The temporary file keeps the suffix (writers choose their format by it); it is
    removed if ``write`` fails, so ``path`` is either complete or untouched.
    """
    target = Path(path).resolve()
    tmp: str | None = None
    try:
        # inside the try: the directory may be unwritable (or gone) since the check
        fd, tmp = tempfile.mkstemp(prefix=".mjstruct-", suffix=target.suffix, dir=target.parent)
        os.close(fd)
        write(tmp)
        os.chmod(tmp, _mode(target))
        os.replace(tmp, target)
    except OSError as exc:
        raise MechanismError(f"{name}: cannot write {path} ({_reason(exc)})") from None
    finally:
        if tmp is not None and os.path.exists(tmp):
            os.unlink(tmp)


def _reason(exc: OSError) -> str:
    """The system's words for a failed write, without the temporary file's name."""
    return exc.strerror or type(exc).__name__


def _mode(target: Path) -> int:
    """Permissions of the file replaced, else the usual ones (mkstemp makes 0600)."""
    if target.exists():
        return target.stat().st_mode & 0o777
    umask = os.umask(0)
    os.umask(umask)
    return 0o666 & ~umask

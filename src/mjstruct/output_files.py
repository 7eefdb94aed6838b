"""Output files: where an output really goes, and writing it whole with the user's permissions.

Owns the one rule every command follows when it writes a file (a drawing, an
animation, a CSV table, a converted mechanism):

- an output path that is a symbolic link is *followed*: the file it points to is
  replaced and the link stays (as the shell's ``>`` does); a link that points to a
  file not yet there creates that file; a loop of links, or a link to a file whose
  suffix differs (``picture.svg`` pointing to ``notes.txt``), is bad input;
- the file is written under a temporary name in the directory of that final file and
  moved into place with :func:`os.replace`, so it is either complete or untouched;
- a new file gets the permissions the user's umask gives (``0o666 & ~umask``, as
  ``open()`` would); a replaced file keeps its permissions;
- the output may not be the file a command reads (:func:`same_file`: also through
  links), which the commands refuse before computing anything.

Examples
--------
>>> import tempfile
>>> folder = Path(tempfile.mkdtemp())
>>> write_text(folder / "table.csv", "q,x\\n0,1\\n")
>>> (folder / "table.csv").read_text()
'q,x\\n0,1\\n'
>>> (folder / "link.csv").symlink_to(folder / "table.csv")
>>> write_text(folder / "link.csv", "new\\n")   # follows the link
>>> (folder / "table.csv").read_text(), (folder / "link.csv").is_symlink()
('new\\n', True)
"""

from __future__ import annotations

import errno
import os
import tempfile
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

from mjstruct.errors import MechanismError

__all__ = [
    "created_mode",
    "output_target",
    "replacing",
    "same_file",
    "write_atomically",
    "write_text",
]


def output_target(path: str | os.PathLike[str], name: str = "path") -> Path:
    """The file that writing to ``path`` replaces or creates: symbolic links followed.

    Raises
    ------
    MechanismError
        ``path`` is a loop of symbolic links, a directory, or a link to a file with
        another suffix.
    """
    try:
        real = os.path.realpath(path, strict=True)
    except FileNotFoundError:  # a new file, or a link to one: created where it points
        real = os.path.realpath(path)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            loop = f"{os.fspath(path)} is a loop of symbolic links"
            raise MechanismError(f"{name}: {loop}") from None
        raise MechanismError(f"{name}: cannot write {os.fspath(path)} ({_reason(exc)})") from None
    target = Path(real)
    if target.is_dir():
        raise MechanismError(f"{name}: {os.fspath(path)} is a directory")
    given = Path(os.fspath(path))
    if target.suffix.lower() != given.suffix.lower() and given.name != target.name:
        # a link to a file of another kind: following it would put, say, an SVG
        # picture into notes.txt
        raise MechanismError(
            f"{name}: {os.fspath(path)} is a link to {target}, a file of another kind "
            f"({target.suffix or 'no suffix'}); write to that file by its own name"
        )
    return target


def same_file(a: str | os.PathLike[str], b: str | os.PathLike[str]) -> bool:
    """Whether ``a`` and ``b`` name one existing file (links and hard links followed).

    >>> same_file(__file__, __file__), same_file(__file__, "no-such-file")
    (True, False)
    """
    try:
        return os.path.samefile(a, b)
    except (OSError, ValueError):  # a missing file, a loop, a NUL in the name
        return False


def created_mode(target: Path) -> int:
    """Permissions for writing ``target``: its own when it exists, else what the umask gives."""
    try:
        return target.stat().st_mode & 0o7777
    except OSError:
        umask = os.umask(0)  # the only way to read the umask: set it and put it back
        os.umask(umask)
        return 0o666 & ~umask


@contextmanager
def replacing(
    path: str | os.PathLike[str], name: str = "path", suffix: str | None = None
) -> Iterator[str]:
    """A temporary file to write, moved onto ``path``'s target when the block ends well.

    The temporary file sits in the final file's directory (so the move is atomic) and
    has ``suffix`` (default: that of ``path`` as given, not of a link's target:
    writers such as matplotlib choose their format by it).  It is removed if the
    block fails or is interrupted, so the target is complete or untouched.  Errors of
    the file system propagate as :class:`OSError`.

    >>> import tempfile
    >>> out = Path(tempfile.mkdtemp()) / "a.txt"
    >>> with replacing(out) as tmp:
    ...     _ = Path(tmp).write_text("done")
    >>> out.read_text()
    'done'
    """
    target = output_target(path, name)
    chosen = Path(os.fspath(path)).suffix if suffix is None else suffix
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=chosen, dir=target.parent)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, created_mode(target))
        os.replace(tmp, target)
    finally:
        if os.path.lexists(tmp):
            os.unlink(tmp)


def write_atomically(
    path: str | os.PathLike[str],
    write: Callable[[str], None],
    name: str = "path",
    suffix: str | None = None,
) -> None:
    """Call ``write(tmp)`` on a temporary file, then move it onto ``path``'s target
    (:func:`replacing`).

    Raises
    ------
    MechanismError
        the target cannot be written (naming ``name``), a loop of links, a directory.
    """
    try:
        with replacing(path, name, suffix) as tmp:
            write(tmp)
    except OSError as exc:
        raise MechanismError(f"{name}: cannot write {os.fspath(path)} ({_reason(exc)})") from None


def write_text(path: str | os.PathLike[str], text: str, name: str = "path") -> None:
    """Write ``text`` (UTF-8) to ``path`` by :func:`write_atomically`."""

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            fh.write(text)

    write_atomically(path, write, name)


def _reason(exc: OSError) -> str:
    """The system's words for a failed write, without the temporary file's name."""
    return exc.strerror or type(exc).__name__

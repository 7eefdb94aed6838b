"""Every command of README's "Use" block and of docs/user-guide.md runs as written.

The commands run in this process (``mjstruct.cli.main.main``, one interpreter for all:
the suite stays fast) in a temporary directory that sees the repository's
``catalogs/`` under its own name, so the relative paths work as pasted and the files
the commands write land there. Each has a time bound: a README command must take
seconds, not minutes. The guide's commands are checked against the output the guide
shows under them (every shown line that is not elided with "...").
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import signal
import sys
import time
import warnings
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from project_paths import ROOT

README = ROOT / "README.md"
GUIDE = ROOT / "docs" / "user-guide.md"
SECONDS = 30  # per command; they take well under 10 s on a quiet 2-core machine


@dataclass
class Command:
    """One documented command: its words, what it reads on standard input, and the
    lines the document shows as its output."""

    line: str
    argv: list[str]
    stdin: str | None = None
    shown: list[str] = field(default_factory=list)


def _fences(text: str) -> Iterator[tuple[str, list[str]]]:
    """(info string, lines) of each fenced code block of a Markdown text."""
    lines = text.splitlines()
    k = 0
    while k < len(lines):
        start = re.match(r"^(\s*)```(\S*)", lines[k])
        if start is None:
            k += 1
            continue
        indent, info = start.groups()
        body = []
        k += 1
        while k < len(lines) and not lines[k].strip().startswith("```"):
            body.append(lines[k][len(indent) :])
            k += 1
        yield info, body
        k += 1


def _command(line: str) -> Command:
    """A shell line (``mjstruct ...``, or ``echo '...' | mjstruct ...``) as a Command."""
    words = shlex.split(line, comments=True)
    stdin = None
    if words[0] == "echo":
        bar = words.index("|")
        stdin, words = " ".join(words[1:bar]) + "\n", words[bar + 1 :]
    assert words[0] == "mjstruct", line
    return Command(line, words[1:], stdin)


def readme_commands() -> list[Command]:
    """The ``mjstruct`` lines of the first bash block under README's "## Use"."""
    text = README.read_text(encoding="utf-8")
    use = text.split("\n## Use\n", 1)[1].split("\n## ", 1)[0]
    info, body = next(_fences(use))
    assert info == "bash"
    return [_command(line) for line in body if line.startswith("mjstruct ")]


def _use_block() -> list[str]:
    text = README.read_text(encoding="utf-8")
    use = text.split("\n## Use\n", 1)[1].split("\n## ", 1)[0]
    return next(_fences(use))[1]


def readme_folders() -> list[str]:
    """The folders README's Use block makes (``mkdir -p DIR`` lines)."""
    words = [shlex.split(line, comments=True) for line in _use_block()]
    return [w[2] for w in words if w[:2] == ["mkdir", "-p"] and len(w) == 3]


#: the options that name a file a command writes
OUTPUT_FLAGS = ("-o", "--output", "--csv", "--targets-chart", "--history", "--draw")


def test_readme_commands_write_under_one_folder_they_make() -> None:
    # a new user pasting the Use block found seven files in the repository's root:
    # every file a command writes goes under a folder the block makes first
    folders = readme_folders()
    assert folders
    for cmd in readme_commands():
        for flag, value in zip(cmd.argv, cmd.argv[1:], strict=False):
            if flag in OUTPUT_FLAGS:
                assert any(value.startswith(f"{d}/") for d in folders), cmd.line


def guide_commands() -> list[Command]:
    """Every ``$ ...`` line of the guide's code blocks, with the lines shown below it."""
    out: list[Command] = []
    for _, body in _fences(GUIDE.read_text(encoding="utf-8")):
        current = None
        for line in body:
            if line.startswith("$ "):
                current = _command(line[2:])
                out.append(current)
            elif current is not None and line.strip():
                current.shown.append(line)
    return out


class _TooLong(BaseException):
    """Raised by the alarm: not an Exception, so the CLI's handlers let it through."""


def _on_alarm(signum: int, frame: object) -> None:
    raise _TooLong


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    """A fresh directory where ``catalogs/`` is the repository's."""
    path = tmp_path_factory.mktemp("docs-commands")
    (path / "catalogs").symlink_to(ROOT / "catalogs", target_is_directory=True)
    for folder in readme_folders():  # README's `mkdir -p DIR` lines, as pasted
        (path / folder).mkdir(parents=True, exist_ok=True)
    old = Path.cwd()
    os.chdir(path)
    try:
        yield path
    finally:
        os.chdir(old)


def run(cmd: Command) -> tuple[int, str, str, float]:
    """Run ``cmd`` in this process: (exit status, stdout, stderr, seconds)."""
    import matplotlib

    matplotlib.use("Agg")
    from mjstruct.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    stdin = io.TextIOWrapper(io.BytesIO((cmd.stdin or "").encode()), encoding="utf-8")
    previous = signal.signal(signal.SIGALRM, _on_alarm)
    signal.setitimer(signal.ITIMER_REAL, SECONDS)
    start = time.perf_counter()
    try:
        with (
            contextlib.redirect_stdout(out),
            contextlib.redirect_stderr(err),
            warnings.catch_warnings(),
        ):
            warnings.simplefilter("default")  # as the command does: a warning is printed
            old_stdin, sys.stdin = sys.stdin, stdin
            try:
                status = main(cmd.argv)
            except SystemExit as exc:  # usage errors leave through argparse
                status = int(exc.code or 0)
            finally:
                sys.stdin = old_stdin
    except _TooLong:
        pytest.fail(f"{cmd.line!r} ran longer than {SECONDS} s")
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    return status, out.getvalue(), err.getvalue(), time.perf_counter() - start


def test_the_readme_shows_commands() -> None:
    commands = readme_commands()
    assert len(commands) >= 20
    optional = [c.line for c in commands if any(re.match(r"\[-", w) for w in c.argv)]
    assert not optional, f"optional parts in brackets fail when pasted: {optional}"


@pytest.mark.parametrize("cmd", readme_commands(), ids=lambda c: " ".join(c.argv)[:60])
def test_readme_command_runs_as_pasted(cmd: Command, workdir: Path) -> None:
    status, _, err, _ = run(cmd)
    assert status == 0, f"{cmd.line}\n{err}"


def test_the_guide_shows_commands() -> None:
    commands = guide_commands()
    assert len(commands) >= 12


@pytest.mark.parametrize("cmd", guide_commands(), ids=lambda c: " ".join(c.argv)[:60])
def test_guide_command_prints_what_the_guide_shows(cmd: Command, workdir: Path) -> None:
    status, out, err, _ = run(cmd)
    error = bool(cmd.shown) and cmd.shown[0].startswith("mjstruct ")
    assert status == (2 if error else 0), f"{cmd.line}\n{err}"
    printed = (err if error else out).splitlines()
    at = 0
    for line in cmd.shown:
        if "..." in line or "…" in line:
            continue  # elided in the guide
        found = [k for k in range(at, len(printed)) if printed[k].rstrip() == line.rstrip()]
        assert found, f"{cmd.line}: the guide shows\n{line}\nnot printed (in order):\n" + (
            "\n".join(printed)
        )
        at = found[0] + 1


def test_the_guides_example_is_the_shipped_file_and_its_numbers_hold() -> None:
    """Section 4 of the guide shows the shipped file and states numbers of its motion:
    they are measured here on a fine sweep, not copied from the code."""
    import json

    import numpy as np

    from mjstruct.io import read_mechanism
    from mjstruct.kinematics.solver import kinematic_analysis

    path = ROOT / "catalogs" / "examples" / "six-bar-mj-slider.json"
    blocks = [
        "\n".join(body)
        for info, body in _fences(GUIDE.read_text(encoding="utf-8"))
        if info == "json" and '"six-bar with a multiple joint' in "\n".join(body)
    ]
    assert len(blocks) == 1
    data = json.loads(path.read_text(encoding="utf-8"))
    assert json.loads(blocks[0]) == data
    m = read_mechanism(path)
    at = {j["id"]: complex(*j["at"]) for j in data["joints"]}
    lengths = [abs(at[a] - at[b]) for a, b in (("O1", "A"), ("A", "B"), ("O2", "B"), ("B", "C"))]
    assert np.round(lengths, 2).tolist() == [1.0, 3.0, 2.5, 2.5]
    r = kinematic_analysis(m, frames=3600, speed=1.0)
    assert not r.warnings
    by, cx = np.asarray(r.joints["B"]["y"]), np.asarray(r.joints["C"]["x"])
    assert (round(by.min(), 2), round(by.max(), 2)) == (1.65, 2.50)
    assert (round(cx.min(), 2), round(cx.max(), 2), round(np.ptp(cx), 2)) == (3.60, 5.57, 1.97)
    lean = np.degrees(np.abs(np.arcsin((by - 2.0) / lengths[3])))
    assert round(lean.max(), 1) == 11.5

"""Files the commands write: the user's umask, links followed, loops and the input refused.

One rule for every output (docs/contract.md §4): a link is followed (the file it points
to is replaced, the link stays), a new file gets ``0o666 & ~umask``, a replaced file keeps
its permissions, a loop of links or the command's own input file is bad input.
"""

from __future__ import annotations

import os
import stat
from collections.abc import Iterator
from pathlib import Path

import pytest

from mjstruct.cli.main import main
from project_paths import EXAMPLES

FOUR_BAR = EXAMPLES / "four-bar.json"
DYNAMICS = EXAMPLES / "slider-crank-seed000-dynamics.json"

#: (command line without the output, the output flag, the output's suffix)
WRITERS = {
    "convert": (["convert", str(FOUR_BAR)], "-o", ".pmks"),
    "kinematics": (["kinematics", str(FOUR_BAR), "--frames", "4"], "--csv", ".csv"),
    "dynamics": (["dynamics", str(DYNAMICS), "--frames", "4", "--speed", "1"], "--csv", ".csv"),
    "draw": (["draw", str(FOUR_BAR)], "-o", ".svg"),
}


def run(capsys: pytest.CaptureFixture[str], argv: list[str]) -> tuple[int, str, str]:
    status = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.fixture
def umask() -> Iterator[object]:
    """Set the process umask in a test (``umask.set(0o077)``), restored afterwards."""
    old = os.umask(0o022)

    class Setter:
        def set(self, value: int) -> None:
            os.umask(value)

    try:
        yield Setter()
    finally:
        os.umask(old)


def mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_created_files_follow_the_umask(command, tmp_path, capsys, umask) -> None:
    argv, flag, suffix = WRITERS[command]
    for mask, expected in ((0o022, 0o644), (0o077, 0o600), (0o002, 0o664)):
        umask.set(mask)  # type: ignore[attr-defined]
        out = tmp_path / f"out-{mask:o}{suffix}"
        status, _, err = run(capsys, [*argv, flag, str(out)])
        assert status == 0, err
        assert mode(out) == expected, (command, oct(mask), oct(mode(out)))
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]  # no temporaries


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_a_link_is_followed_and_keeps_its_target_permissions(command, tmp_path, capsys) -> None:
    argv, flag, suffix = WRITERS[command]
    real = tmp_path / "kept" / f"real{suffix}"
    real.parent.mkdir()
    real.write_text("old")
    real.chmod(0o640)
    link = tmp_path / f"link{suffix}"
    link.symlink_to(real)
    status, _, err = run(capsys, [*argv, flag, str(link)])
    assert status == 0, err
    assert link.is_symlink() and os.readlink(link) == str(real)
    assert real.read_text() != "old" and mode(real) == 0o640
    assert sorted(p.name for p in real.parent.iterdir()) == [real.name]


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_a_link_to_a_file_of_another_kind_is_refused(command, tmp_path, capsys) -> None:
    # before: draw -o picture.svg -> notes.txt was matplotlib's "Format 'txt' is not
    # supported" (internal error); following it would put a picture into notes.txt
    argv, flag, suffix = WRITERS[command]
    notes = tmp_path / "notes.txt"
    notes.write_text("notes")
    link = tmp_path / f"picture{suffix}"
    link.symlink_to(notes)
    status, out, err = run(capsys, [*argv, flag, str(link)])
    assert (status, out) == (2, "")
    assert err == (
        f"mjstruct {command}: {flag}: {link} is a link to {notes}, a file of another kind "
        "(.txt); write to that file by its own name\n"
    )
    assert notes.read_text() == "notes"


def test_a_dangling_link_creates_its_target(tmp_path, capsys) -> None:
    link = tmp_path / "out.pmks"
    link.symlink_to(tmp_path / "made.pmks")
    assert run(capsys, ["convert", str(FOUR_BAR), "-o", str(link)])[0] == 0
    assert (tmp_path / "made.pmks").read_text().startswith("# mjstruct")


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_a_loop_of_links_is_bad_input_naming_the_flag(command, tmp_path, capsys) -> None:
    argv, flag, suffix = WRITERS[command]
    a, b = tmp_path / f"a{suffix}", tmp_path / f"b{suffix}"
    a.symlink_to(b)
    b.symlink_to(a)
    status, out, err = run(capsys, [*argv, flag, str(a)])
    assert (status, out) == (2, "")
    assert err == f"mjstruct {command}: {flag}: {a} is a loop of symbolic links\n"


@pytest.mark.parametrize("command", sorted(WRITERS))
def test_writing_onto_the_input_is_refused(command, tmp_path, capsys) -> None:
    argv, flag, suffix = WRITERS[command]
    source = Path(argv[1])
    copy = tmp_path / source.name
    copy.write_bytes(source.read_bytes())
    link = tmp_path / f"link{suffix}"
    link.symlink_to(copy)
    for out in (copy, link):  # the input itself, or a link to it
        status, stdout, err = run(capsys, [argv[0], str(copy), *argv[2:], flag, str(out)])
        assert (status, stdout) == (2, "")
        assert err == f"mjstruct {command}: {flag}: {out} is the input file (write elsewhere)\n"
        assert copy.read_bytes() == source.read_bytes()


def test_convert_says_what_it_wrote_where(tmp_path, capsys) -> None:
    out = tmp_path / "four-bar.toml"
    status, stdout, err = run(capsys, ["convert", str(FOUR_BAR), "-o", str(out)])
    assert (status, err) == (0, "")
    assert stdout == f"wrote {out} (mechanism TOML: 4 links, 4 joints, from {FOUR_BAR})\n"
    # --json keeps its one object; without -o the result itself is the output
    status, stdout, _ = run(capsys, ["convert", str(FOUR_BAR), "-o", str(out), "--json"])
    assert status == 0 and stdout.startswith("{") and "wrote" not in stdout
    status, stdout, _ = run(capsys, ["convert", str(FOUR_BAR), "--to", "toml"])
    assert status == 0 and "wrote" not in stdout and '"frame" = "0"' in stdout

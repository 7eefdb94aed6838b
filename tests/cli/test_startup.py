"""The CLI's start-up: what importing it and running ``analyze`` load (in a fresh
interpreter), and the parser built for the command that runs only."""

from __future__ import annotations

import subprocess
import sys

import pytest

from mjstruct.cli.main import COMMANDS, main
from project_paths import EXAMPLES

HEAVY = ("numpy", "scipy", "sympy", "matplotlib", "networkx")


def _loaded_after(code: str) -> set[str]:
    probe = (
        "import sys, io, contextlib\n"
        f"{code}\n"
        "print(' '.join(sorted(m.split('.')[0] for m in sys.modules)))"
    )
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return set(p.stdout.split())


def test_importing_the_cli_and_analyze_load_no_numerical_library():
    assert not _loaded_after("import mjstruct.cli.main") & set(HEAVY)
    run = (
        "from mjstruct.cli.main import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    main(['analyze', {str(EXAMPLES / 'four-bar.json')!r}, '--json'])"
    )
    loaded = _loaded_after(run)
    assert "pynauty" in loaded  # the canonical code was computed: the path really ran
    # nor a TOML reader for a JSON file, nor argparse's terminal-size helper (shutil)
    assert not loaded & {*HEAVY, "tomllib", "shutil"}


def test_help_before_the_command_lists_every_command(capsys):
    with pytest.raises(SystemExit):
        main(["-h", "analyze"])
    out = capsys.readouterr().out
    assert all(name in out for name in COMMANDS)

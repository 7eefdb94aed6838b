"""The layer contract (``[tool.importlinter]`` in pyproject.toml) holds: no unit imports
a unit above it, function-level imports included, so there is no cycle between units."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from project_paths import ROOT


def test_layer_contract_kept():
    # lint-imports (import-linter, a test extra) sits beside this Python
    exe = Path(sys.executable).parent / "lint-imports"
    assert exe.exists(), "lint-imports (import-linter, a test extra) is not installed"
    run = subprocess.run(
        [str(exe), "--no-cache"], cwd=ROOT, capture_output=True, text=True, timeout=120
    )
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-1000:]
    assert "0 broken" in run.stdout, run.stdout[-500:]

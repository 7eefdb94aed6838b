"""A user's code type-checks under `mypy --strict` through the lazy top-level names.

`mjstruct/__init__.py` resolves its names lazily at run time; its literal `__all__` and
its `TYPE_CHECKING` imports are what a type checker reads.  This test writes the kind of
code a user writes and runs `mypy --strict` on it: every name must be an explicit
re-export (no "does not explicitly export attribute") and carry its real type, not `Any`
(`assert_type` fails on `Any`).
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from project_paths import ROOT

USER_CODE = textwrap.dedent(
    """
    from typing import assert_type

    import mjstruct
    from mjstruct import (
        Decomposition,
        KinematicsResult,
        Mechanism,
        MechanismError,
        assur_groups,
        canonical_code,
        is_isomorphic,
        kinematic_analysis,
        mechanism_to_pyslvs,
        read_mechanism,
        structural_report,
    )


    def summary(path: str) -> str:
        m = read_mechanism(path)
        assert_type(m, Mechanism)
        assert_type(assur_groups(m), Decomposition)
        assert_type(kinematic_analysis(m), KinematicsResult)
        assert_type(is_isomorphic(m, m), bool)
        assert_type(mjstruct.generic_dof(m), int)
        try:
            structural_report(m)
        except MechanismError as exc:
            return str(exc)
        return canonical_code(m) + mechanism_to_pyslvs(m)
    """
)


def test_user_code_passes_mypy_strict(tmp_path: Path) -> None:
    pytest.importorskip("mypy")
    (tmp_path / "user_code.py").write_text(USER_CODE)
    # an empty config so that no mypy configuration outside tmp_path applies
    (tmp_path / "mypy.ini").write_text("[mypy]\n")
    env = {**os.environ, "MYPYPATH": str(ROOT / "src")}
    # --follow-imports=silent: the package is analysed for its types, but (as for an
    # installed package) its own findings, e.g. untyped third-party imports, are not
    # reported against the user's code
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "mypy",
            "--strict",
            "--follow-imports=silent",
            "--config-file",
            str(tmp_path / "mypy.ini"),
            "--cache-dir",
            str(tmp_path / ".mypy_cache"),
            "user_code.py",
        ],
        cwd=tmp_path,
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Success" in proc.stdout

"""Where the project's files are, for tests in any folder: the repository root, the
shipped examples and the tests' own data."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "catalogs" / "examples"
DATA = ROOT / "tests" / "data"

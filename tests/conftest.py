"""Shared fixtures: paths of shipped examples."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "catalogs" / "examples"


@pytest.fixture
def examples() -> Path:
    return EXAMPLES

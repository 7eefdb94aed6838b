"""Shared fixtures: paths of shipped examples, a count of the closure's evaluations."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from mjstruct.kinematics import closure_newton
from project_paths import EXAMPLES


@pytest.fixture
def examples() -> Path:
    return EXAMPLES


@pytest.fixture
def closure_evaluations(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Calls of ``evaluate()`` made by the closure, in ``[0]`` (assign 0 to restart).

    Every evaluation of the closure goes through :mod:`~mjstruct.kinematics.closure_newton`.
    """
    calls = [0]
    real = closure_newton.evaluate

    def counting(*args: Any, **kwargs: Any) -> Any:
        calls[0] += 1
        return real(*args, **kwargs)

    monkeypatch.setattr(closure_newton, "evaluate", counting)
    return calls

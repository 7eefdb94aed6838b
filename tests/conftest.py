"""Shared fixtures: paths of shipped examples, counts of the closure's evaluations."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from browser_report import browser_line
from mjstruct.kinematics import closure_continuation, closure_newton
from project_paths import EXAMPLES


def pytest_terminal_summary(terminalreporter: Any) -> None:
    """Say whether the HTML animation's browser test ran (it skips without Chromium)."""
    stats = terminalreporter.stats
    line = browser_line(r for key in ("passed", "failed", "skipped", "error")
                        for r in stats.get(key, ()))  # fmt: skip
    if line is not None:
        terminalreporter.write_line(line)


@pytest.fixture
def examples() -> Path:
    return EXAMPLES


def _count_evaluations(monkeypatch: pytest.MonkeyPatch, module: Any) -> list[int]:
    """Calls of ``module.evaluate`` from now on, in ``[0]`` (assign 0 to restart)."""
    calls = [0]
    real = module.evaluate

    def counting(*args: Any, **kwargs: Any) -> Any:
        calls[0] += 1
        return real(*args, **kwargs)

    monkeypatch.setattr(module, "evaluate", counting)
    return calls


@pytest.fixture
def closure_evaluations(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Calls of ``evaluate()`` made by the closure, in ``[0]`` (assign 0 to restart).

    Every evaluation of the closure goes through :mod:`~mjstruct.kinematics.closure_newton`.
    """
    return _count_evaluations(monkeypatch, closure_newton)


@pytest.fixture
def scan_evaluations(monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Calls of ``evaluate()`` made by the continuation's scans of the residual, in ``[0]``.

    :func:`~mjstruct.kinematics.closure_continuation.scanned_roots` evaluates through
    :mod:`~mjstruct.kinematics.closure_continuation` (the rest of the closure does not).
    """
    return _count_evaluations(monkeypatch, closure_continuation)

"""Whether the HTML animation's browser test ran: one line at the end of a test run.

The browser test skips where headless Chromium is not installed; a skip among ~1800
passes is easy to miss, so the run's summary says what happened to it (``.ci/run``
installs Chromium from the distribution's packages when it can, and then requires the
test to run: ``MJSTRUCT_BROWSER_TEST=required``).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any

#: the test's node id ends so (the path's separator differs between runs)
BROWSER_TEST = "test_browser.py::test_the_html_animation_plays_in_chromium"


def browser_line(reports: Iterable[Any]) -> str | None:
    """The summary line for the browser test's reports (None: it was not collected)."""
    mine = [r for r in reports if str(getattr(r, "nodeid", "")).endswith(BROWSER_TEST)]
    if not mine:
        return None
    if any(r.outcome == "failed" for r in mine):
        return "browser test (headless Chromium): FAILED"
    skipped = [r for r in mine if r.outcome == "skipped"]
    if skipped:
        longrepr = skipped[0].longrepr
        reason = longrepr[2] if isinstance(longrepr, tuple) else str(longrepr)
        return f"browser test (headless Chromium): did not run, {reason.removeprefix('Skipped: ')}"
    return "browser test (headless Chromium): ran and passed"

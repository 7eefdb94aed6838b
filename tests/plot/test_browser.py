"""The HTML animation in a real browser: headless Chromium opens the page that
``mjstruct animate FILE -o x.html`` writes, the play button is pressed with the mouse,
and two screenshots taken while it plays show the mechanism moved, the frame counter
and the slider advanced.

Chromium is driven through the DevTools protocol over a pipe (``--remote-debugging-pipe``:
JSON messages separated by NUL bytes on file descriptors 3 and 4), so no port is
opened and nothing beyond the standard library is needed.  Where Chromium is not
installed the test is skipped, saying so (Debian: ``apt-get install chromium``; CI's
``.ci/run`` installs it when it can and then requires the test to run, by
``MJSTRUCT_BROWSER_TEST=required``), and the run's last lines say whether it ran.
"""

from __future__ import annotations

import base64
import contextlib
import fcntl
import io
import json
import os
import select
import shutil
import subprocess
import time
from typing import Any

import numpy as np
import pytest
from PIL import Image

from mjstruct.cli.main import main
from project_paths import EXAMPLES

#: where Debian and other systems install Chromium (or Chrome)
BROWSERS = ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable")
#: the flags of a quiet, throw-away headless browser
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--no-first-run",
    "--disable-dev-shm-usage",
    "--force-color-profile=srgb",
    "--hide-scrollbars",
    "--window-size=760,720",
    "--remote-debugging-pipe",
)
#: seconds any one step may take (a loaded two-core machine starts Chromium slowly)
PATIENCE = 30.0


def browser() -> str | None:
    for name in BROWSERS:
        found = shutil.which(name)
        if found:
            return found
    return None


class DevTools:
    """A headless Chromium and its DevTools protocol over a pipe."""

    def __init__(self, executable: str, profile: str) -> None:
        to_browser, self._write = os.pipe()  # we write, Chromium reads fd 3
        self._read, from_browser = os.pipe()  # Chromium writes fd 4, we read

        def descriptors() -> None:
            # in the child: the pipe's ends become fds 3 and 4 (through fds >= 10, so
            # that neither is overwritten on the way: either may be 3 or 4 already)
            a = fcntl.fcntl(to_browser, fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(from_browser, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        # close_fds=False: fds 3 and 4 made here must survive (our own ends of the pipes
        # are not inheritable, so Chromium does not hold them)
        self.process = subprocess.Popen(
            [executable, *FLAGS, f"--user-data-dir={profile}", "about:blank"],
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            preexec_fn=descriptors,
            close_fds=False,
        )
        os.close(to_browser)
        os.close(from_browser)
        self._buffer = b""
        self._next = 0
        self.session: str | None = None

    def send(self, method: str, session: bool = True, **params: Any) -> dict[str, Any]:
        """Send a command and wait for its answer (events that come first are dropped)."""
        self._next += 1
        message: dict[str, Any] = {"id": self._next, "method": method, "params": params}
        if session and self.session is not None:
            message["sessionId"] = self.session
        os.write(self._write, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + PATIENCE
        while True:
            answer = self._message(deadline)
            if answer.get("id") == self._next:
                if "error" in answer:
                    raise RuntimeError(f"{method}: {answer['error']}")
                return dict(answer.get("result", {}))

    def _message(self, deadline: float) -> dict[str, Any]:
        while b"\0" not in self._buffer:
            left = deadline - time.monotonic()
            ready, _, _ = select.select([self._read], [], [], max(0.0, left))
            if not ready:
                raise TimeoutError("Chromium did not answer")
            chunk = os.read(self._read, 1 << 20)
            if not chunk:
                raise RuntimeError("Chromium closed its DevTools pipe")
            self._buffer += chunk
        raw, self._buffer = self._buffer.split(b"\0", 1)
        return dict(json.loads(raw))

    def evaluate(self, expression: str) -> Any:
        result = self.send("Runtime.evaluate", expression=expression, returnByValue=True)
        return result["result"].get("value")

    def screenshot(self) -> np.ndarray:
        data = self.send("Page.captureScreenshot", format="png")["data"]
        with Image.open(io.BytesIO(base64.b64decode(data))) as image:
            return np.asarray(image.convert("RGB"))

    def wait_for(self, expression: str, what: str) -> Any:
        """Poll a JavaScript expression until it is truthy; its value."""
        deadline = time.monotonic() + PATIENCE
        while time.monotonic() < deadline:
            value = self.evaluate(expression)
            if value:
                return value
            time.sleep(0.02)
        raise TimeoutError(f"the page never showed {what}")

    def close(self) -> None:
        with contextlib.suppress(OSError, RuntimeError, TimeoutError):
            self.send("Browser.close", session=False)
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        os.close(self._write)
        os.close(self._read)


STATE = (
    "JSON.stringify({counter: document.getElementById('counter').textContent,"
    " slider: +document.getElementById('slider').value})"
)


def test_the_html_animation_plays_in_chromium(tmp_path, capsys):
    executable = browser()
    if executable is None and os.environ.get("MJSTRUCT_BROWSER_TEST") == "required":
        pytest.fail("MJSTRUCT_BROWSER_TEST=required, but no Chromium is on PATH")
    if executable is None:
        pytest.skip(
            "headless Chromium is not installed (Debian: apt-get install chromium); "
            "the HTML animation's browser test needs it"
        )
    page = tmp_path / "x.html"
    argv = ["animate", str(EXAMPLES / "six-bar-mj-slider.json"), "--frames", "24", "--fps", "8"]
    assert main([*argv, "--dpi", "60", "-o", str(page)]) == 0
    capsys.readouterr()
    chrome = DevTools(executable, str(tmp_path / "profile"))
    try:
        target = chrome.send("Target.createTarget", session=False, url=page.as_uri())["targetId"]
        chrome.session = chrome.send(
            "Target.attachToTarget", session=False, targetId=target, flatten=True
        )["sessionId"]
        chrome.wait_for(
            "document.readyState === 'complete' && document.getElementById('frame').complete"
            " && document.getElementById('frame').naturalWidth > 0",
            "its first frame",
        )
        start = json.loads(chrome.evaluate(STATE))
        assert start == {"counter": "1 / 24", "slider": 0}  # still until play is pressed
        # the drawing's place on the page, and the play button's middle
        box = chrome.evaluate(
            "(() => { const r = document.getElementById('frame').getBoundingClientRect();"
            " return [r.left, r.top, r.width, r.height]; })()"
        )
        x, y = chrome.evaluate(
            "(() => { const r = document.getElementById('play').getBoundingClientRect();"
            " return [r.left + r.width / 2, r.top + r.height / 2]; })()"
        )
        for kind in ("mousePressed", "mouseReleased"):
            chrome.send(
                "Input.dispatchMouseEvent", type=kind, x=x, y=y, button="left", clickCount=1
            )
        # two moments while it plays: each after the counter has moved on
        shots, states = [], []
        seen = start["counter"]
        for moment in ("first", "second"):
            chrome.wait_for(
                f"document.getElementById('counter').textContent !== {json.dumps(seen)}",
                f"the {moment} moment: the counter moving on",
            )
            shots.append(chrome.screenshot())
            states.append(json.loads(chrome.evaluate(STATE)))
            seen = states[-1]["counter"]
    finally:
        chrome.close()
    first, second = states
    assert first["counter"] != "1 / 24" and second["counter"] != first["counter"]
    assert first["slider"] != 0 and second["slider"] != first["slider"]
    assert first["counter"] == f"{first['slider'] + 1} / 24"
    # the mechanism moved: the drawings differ below the title (the driver's value there
    # changes too), in more than a few pixels
    left, top, width, height = (round(v) for v in box)
    assert width > 200 and height > 200
    below_title = slice(top + height // 6, top + height), slice(left, left + width)
    a, b = shots[0][below_title], shots[1][below_title]
    changed = np.any(np.abs(a.astype(int) - b.astype(int)) > 40, axis=-1)
    assert changed.sum() > 200, changed.sum()
    # and what is shown is a drawing (dark bars on white), not a blank or broken image
    assert (a.sum(axis=-1) < 300).sum() > 500


def test_the_run_says_whether_the_browser_test_ran():
    # a skip among the suite's passes went unnoticed: the summary names its fate
    from types import SimpleNamespace

    from browser_report import browser_line

    node = "tests/plot/test_browser.py::test_the_html_animation_plays_in_chromium"
    other = SimpleNamespace(nodeid="tests/test_api.py::test_x", outcome="passed")
    assert browser_line([other]) is None
    passed = SimpleNamespace(nodeid=node, outcome="passed", longrepr=None)
    assert browser_line([other, passed]) == "browser test (headless Chromium): ran and passed"
    why = "headless Chromium is not installed (Debian: apt-get install chromium)"
    skipped = SimpleNamespace(nodeid=node, outcome="skipped", longrepr=("f", 1, f"Skipped: {why}"))
    assert browser_line([skipped]) == f"browser test (headless Chromium): did not run, {why}"
    failed = SimpleNamespace(nodeid=node, outcome="failed", longrepr="boom")
    assert browser_line([passed, failed]) == "browser test (headless Chromium): FAILED"

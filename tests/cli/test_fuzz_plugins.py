"""Fuzz over the file format for the numerical commands: kinematics, singular, dynamics.

Random values in every field (the dynamics keys included: inertia, gravity,
parameters, loads with random expressions) never give an internal error (status 1
other than the contract's one-line "numerical trouble"), a traceback,
more than one line on standard error, NaN or Infinity in JSON output, or a hang: the
CLI runs in-process through its ``main()`` with a per-case time limit (SIGALRM).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import re
import signal
import sys
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from strategies import field_paths

pytestmark = pytest.mark.skipif(
    not hasattr(signal, "SIGALRM"), reason="the per-case time limit needs SIGALRM"
)

#: seconds one command may take on a small file before the case counts as a hang
CASE_SECONDS = 20

BASE: dict[str, Any] = json.loads(example_path("slider-crank-seed000-dynamics").read_text())

COMMANDS = {
    "kinematics": ["--frames", "6", "--json"],
    # the text form: no "max error inf ... warnings: none" (a point at [1e200, 1e200])
    "kinematics-text": ["--frames", "6"],
    "singular": ["--json"],
    "dynamics-speed": ["--frames", "6", "--speed", "1", "--json"],
    "dynamics-free": ["--frames", "6", "--qdot0", "1", "--json"],
}


# pieces of load expressions: valid, degenerate (zero division, overflow, complex,
# undefined names) and hostile (attribute access, imports; nothing that acts)
TOKENS = [
    "q", "qdot", "M", "p", "1", "0", "2.5", "-", "+", "*", "/", "**", "(", ")",
    "sin(q)", "cos(qdot)", "exp(1000)", "1e308", "1/0", "sqrt(-1)", "log(0)", "zoo",
    "oo", "nan", "I", "x", "pi", "Piecewise((1, q < pi), (0, True))", "q < 1",
    "__import__('sys')", "q.__class__", "lambda: 1", "[1, 2]", "'text'", ",",
]  # fmt: skip
EXPRESSIONS = st.lists(st.sampled_from(TOKENS), min_size=1, max_size=6).map(" ".join)
VALUES = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**400), 10**400)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=4)
    | EXPRESSIONS,
    lambda inner: (
        st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=3), inner, max_size=3)
    ),
    max_leaves=6,
)
DYNAMICS_KEYS = ("inertia", "gravity", "parameters", "loads", "energy_change")
ALL_PATHS = [p for p in field_paths(BASE) if p]
DYNAMICS_PATHS = [p for p in ALL_PATHS if p[0] in DYNAMICS_KEYS]


class _Hang(BaseException):  # not an Exception: main's internal-error net must not catch it
    pass


def _alarm(signum: int, frame: object) -> None:
    raise _Hang


def _mutated(edits: list[tuple[tuple[Any, ...], Any]]) -> dict[str, Any]:
    data = json.loads(json.dumps(BASE))
    for where, value in edits:
        cur = data
        try:
            for k in where[:-1]:
                cur = cur[k]
            cur[where[-1]] = value
        except (KeyError, IndexError, TypeError):  # an earlier edit replaced the parent
            continue
    return data


def _run(tmp: Path, data: dict[str, Any], command: str) -> None:
    path = tmp / "m.json"
    path.write_text(json.dumps(data))
    argv = [command.split("-")[0], str(path), *COMMANDS[command]]
    out, err = io.StringIO(), io.StringIO()
    previous = signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(CASE_SECONDS)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            status = main(argv)
    except _Hang:
        pytest.fail(f"{argv[0]} took over {CASE_SECONDS} s on {json.dumps(data)[:300]}")
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
    message = err.getvalue()
    # status 1 is the contract's "numerical trouble" (a motion that stops, no assembly):
    # an answer about the data, one line; an internal error never is
    trouble = status == 1 and ": numerical trouble: " in message
    assert status in (0, 2) or trouble, f"{message} on {json.dumps(data)[:300]}"
    assert message.count("\n") == (status != 0), message
    if status == 0:
        _answer(out.getvalue(), command)


def _answer(text: str, command: str) -> None:
    """The JSON object without NaN or Infinity; a text report without inf or nan."""
    if command.endswith("-text"):
        bad = re.search(r"(?<![\w.])-?(inf|nan)(?![\w])", text)
        assert bad is None, f"{bad.group() if bad else ''} in the text report:\n{text}"
    else:
        json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} in JSON output"))


FUZZ = settings(
    max_examples=int(os.environ.get("MJSTRUCT_FUZZ_EXAMPLES", "25")),
    deadline=None,  # the per-case limit is the alarm above
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    derandomize=not os.environ.get("MJSTRUCT_FUZZ_EXAMPLES"),  # deterministic in the suite
)


@FUZZ
@given(
    st.lists(st.tuples(st.sampled_from(ALL_PATHS), VALUES), min_size=1, max_size=2),
    st.sampled_from(["kinematics", "kinematics-text", "singular"]),
)
def test_any_value_for_kinematics_and_singular(
    tmp_path: Path, edits: list[tuple[tuple[Any, ...], Any]], command: str
) -> None:
    _run(tmp_path, _mutated(edits), command)


@FUZZ
@given(
    st.lists(st.tuples(st.sampled_from(DYNAMICS_PATHS), VALUES), min_size=1, max_size=3),
    st.sampled_from(["dynamics-speed", "dynamics-free"]),
)
def test_any_dynamics_data(
    tmp_path: Path, edits: list[tuple[tuple[Any, ...], Any]], command: str
) -> None:
    _run(tmp_path, _mutated(edits), command)


@FUZZ
@given(
    st.lists(EXPRESSIONS, min_size=1, max_size=2),
    st.sampled_from(["moment", "force"]),
    st.sampled_from(["dynamics-speed", "dynamics-free"]),
)
def test_any_load_expression(
    tmp_path: Path, expressions: list[str], kind: str, command: str
) -> None:
    data = _mutated([])
    load: dict[str, Any] = {"link": "3"}
    load[kind] = expressions[0] if kind == "moment" else [expressions[0], expressions[-1]]
    data["loads"] = [*data["loads"], load]
    _run(tmp_path, data, command)


def test_the_time_limit_catches_a_hang(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import time

    monkeypatch.setattr(sys.modules[__name__], "CASE_SECONDS", 1)
    monkeypatch.setattr("mjstruct.cli.main.build_parser", lambda only=None: time.sleep(5))
    with pytest.raises(pytest.fail.Exception, match="took over 1 s"):
        _run(tmp_path, BASE, "singular")


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_the_unchanged_file_is_answered(
    tmp_path: Path, command: str, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "m.json"
    path.write_text(json.dumps(BASE))
    assert main([command.split("-")[0], str(path), *COMMANDS[command]]) == 0
    out = capsys.readouterr().out
    _answer(out, command)
    assert out.strip()


def test_a_complex_load_value_is_bad_input(tmp_path: Path) -> None:
    data = _mutated([])
    data["loads"] = [*data["loads"], {"link": "3", "moment": "sqrt(-1)"}]
    path = tmp_path / "m.json"
    path.write_text(json.dumps(data))
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        status = main(["dynamics", str(path), *COMMANDS["dynamics-speed"]])
    assert status == 2 and "loads[2].moment" in err.getvalue()

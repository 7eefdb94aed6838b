"""Hostile flags of the commands: overflowing values and unbounded runs are refused."""

from __future__ import annotations

from pathlib import Path

import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main


def _cli(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    status = main(argv)
    captured = capsys.readouterr()
    return status, captured.out, captured.err


@pytest.mark.parametrize("value", ["1e308", "1e200", "1.7976931348623157e308"])
def test_overflowing_clearance_is_bad_input(
    value: str, capsys: pytest.CaptureFixture[str]
) -> None:
    status, out, err = _cli(
        ["singular", str(example_path("four-bar")), "--clearance", value], capsys
    )
    assert (status, out) == (2, "")
    assert err.startswith("mjstruct singular: --clearance: ") and "too large" in err
    assert err.count("\n") == 1


def test_large_but_representable_clearance_is_answered(capsys: pytest.CaptureFixture[str]) -> None:
    status, _, err = _cli(
        ["singular", str(example_path("four-bar")), "--clearance", "1e150", "--json"], capsys
    )
    assert status == 0, err


def test_library_clearance_overflow_names_the_parameter() -> None:
    from mjstruct.errors import MechanismError
    from mjstruct.io import read_mechanism
    from mjstruct.kinematics.singular import singular_analysis

    m = read_mechanism(example_path("four-bar"))
    with pytest.raises(MechanismError, match=r"^clearance: 1e\+308 is too large"):
        singular_analysis(m, clearance=1e308)


@pytest.mark.parametrize(
    ("drivers", "why"),
    [("O1,B", "over-constrained (B already fixed"), ("O1,A,B", "over-constrained (A, B")],
)
@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_convert_refuses_an_over_driven_result(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], drivers: str, why: str, suffix: str
) -> None:
    out = tmp_path / f"out{suffix}"
    argv = ["convert", str(example_path("four-bar")), "--drivers", drivers, "-o", str(out)]
    status, stdout, err = _cli(argv, capsys)
    assert (status, stdout) == (2, "")
    assert err.startswith("mjstruct convert: --drivers: with ") and why in err
    assert err.count("\n") == 1 and list(tmp_path.iterdir()) == []
    # to standard output as well: nothing printed
    status, stdout, _ = _cli([*argv[:4], "--to", "json"], capsys)
    assert (status, stdout) == (2, "")


def test_convert_keeps_balanced_and_special_geometry_drivers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    import json

    out = tmp_path / "out.json"
    argv = ["convert", str(example_path("four-bar")), "--drivers", "B", "-o", str(out)]
    assert _cli(argv, capsys)[0] == 0
    assert json.loads(out.read_text())["drivers"] == ["B"]
    # a double parallelogram: generically rigid, mobile at its geometry (the Jacobian)
    joints = [{"id": f"O{k}", "links": ["0", str(k)], "at": [k - 1.0, 0.0]} for k in (1, 2, 3)]
    joints += [{"id": f"A{k}", "links": [str(k), "4"], "at": [k - 0.5, 1.0]} for k in (1, 2, 3)]
    src = tmp_path / "para.json"
    src.write_text(json.dumps({"frame": "0", "joints": joints}))
    argv = ["convert", str(src), "--drivers", "O1", "-o", str(out)]
    status, _, err = _cli(argv, capsys)
    assert status == 0, err
    assert json.loads(out.read_text())["drivers"] == ["O1"]
    status, _, err = _cli([*argv[:3], "O1,O2", *argv[4:]], capsys)
    assert status == 2 and "--drivers: " in err and "over-constrained" in err

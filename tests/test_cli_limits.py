"""Hostile flags of the commands: overflowing values and unbounded runs are refused."""

from __future__ import annotations

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

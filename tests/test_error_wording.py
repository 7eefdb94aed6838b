"""Library errors name parameters; the command line names its flags."""

from __future__ import annotations

import sys

import pytest

from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.exchange.pyslvs import mechanism_from_pyslvs
from mjstruct.synthesis.atlas import atlas

PIN_SLOT = "M[J[R, P[0, 0], L[ground, a]], J[RP, A[0], P[2, 0], L[ground, a]]]"


def test_scheduler_without_dask_names_the_parameter(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails as if absent
    with pytest.raises(MechanismError, match=r"^scheduler: needs dask"):
        atlas(1, 4, scheduler="tcp://127.0.0.1:1")


def test_scheduler_without_dask_names_the_flag(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "dask.distributed", None)
    assert main(["atlas", "--links", "4", "--scheduler", "tcp://127.0.0.1:1"]) == 2
    assert "--scheduler: needs dask" in capsys.readouterr().err


def test_pin_slot_refusal_names_the_parameter() -> None:
    with pytest.raises(MechanismError) as info:
        mechanism_from_pyslvs(PIN_SLOT)
    assert "pin_slot='block'" in str(info.value) and "--" not in str(info.value)


def test_pin_slot_refusal_names_the_flag(capsys: pytest.CaptureFixture[str], tmp_path) -> None:
    src = tmp_path / "rp.pmks"
    src.write_text(PIN_SLOT)
    assert main(["convert", str(src), "-o", str(tmp_path / "out.json")]) == 2
    err = capsys.readouterr().err
    assert "convert with --pin-slot block to put" in err


def test_kinematics_memory_limit_names_flags(capsys: pytest.CaptureFixture[str]) -> None:
    from mjstruct.catalog_files import example_path

    f = str(example_path("four-bar"))
    assert main(["kinematics", f, "--frames", "100", "--max-memory", "1000"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("mjstruct: --frames: ") or "--frames: 100 frames" in err
    assert "(--max-memory, or" in err and "max_memory" not in err

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
    from mjstruct.singular.analysis import singular_analysis

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


FOUR_BAR = str(example_path("four-bar"))


def test_plot_refuses_frames_beyond_the_memory_limit_with_the_estimate(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    out = str(tmp_path / "c.svg")
    argv = ["plot", FOUR_BAR, "--what", "angles", "-o", out, "--frames", "10000000"]
    status, stdout, err = _cli(argv, capsys)
    assert (status, stdout) == (2, "") and err.count("\n") == 1
    assert "--frames: 10000000 frames need about 4.5e+09 bytes" in err
    assert "--max-memory, or MJSTRUCT_MAX_MEMORY_BYTES" in err and "frames fit" in err
    fits = int(err.split("at most ")[1].split()[0])
    assert 10**6 < fits < 10**7 and list(tmp_path.iterdir()) == []
    # the limit is raised (or lowered) by the flag and the environment
    small = ["plot", FOUR_BAR, "--what", "angles", "-o", out, "--frames", "2000"]
    assert _cli([*small, "--max-memory", "100000"], capsys)[0] == 2
    monkeypatch.setenv("MJSTRUCT_MAX_MEMORY_BYTES", "100000")
    assert _cli(small, capsys)[0] == 2
    status, _, err = _cli([*small, "--max-memory", str(10**9)], capsys)
    assert status == 0, err


def test_plot_of_many_frames_prints_no_matplotlib_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    import warnings

    from matplotlib.figure import Figure

    # matplotlib warns when placing the legend took over a second (many points): a
    # matter of time, so the warning is raised here as matplotlib would
    real = Figure.savefig

    def slow_legend(self: Figure, *args: object, **kwargs: object) -> None:
        warnings.warn(
            'Creating legend with loc="best" can be slow with large amounts of data.',
            UserWarning,
            stacklevel=2,
        )
        real(self, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", slow_legend)
    argv = ["plot", FOUR_BAR, "--what", "angles", "-o", str(tmp_path / "c.png")]
    status, _, err = _cli([*argv, "--frames", "50"], capsys)
    assert (status, err) == (0, "")


def test_animate_caps_frames_unless_long_and_estimates_memory(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from mjstruct.cli.animate import MAX_FRAMES

    out = str(tmp_path / "a.gif")
    status, _, err = _cli(["animate", FOUR_BAR, "-o", out, "--frames", "1000000"], capsys)
    assert status == 2 and err.count("\n") == 1
    assert f"at most {MAX_FRAMES}); pass --long" in err and "1000000 frames (5e+04 s" in err
    # with --long the images a .gif keeps are estimated: 1e6 frames of 480 x 1008 RGBA
    argv = ["animate", FOUR_BAR, "-o", out, "--frames", "1000000", "--long"]
    status, _, err = _cli(argv, capsys)
    assert status == 2 and "need about 1.9e+12 bytes" in err and "--max-memory" in err
    assert list(tmp_path.iterdir()) == []
    status, _, err = _cli(["animate", FOUR_BAR, "-o", out, "--frames", "4", "--json"], capsys)
    assert status == 0, err


@pytest.mark.parametrize("kmax", ["17", "1000", "1000000"])
def test_cells_refuses_kmax_beyond_the_limit_with_the_count(
    kmax: str, capsys: pytest.CaptureFixture[str]
) -> None:
    status, out, err = _cli(["cells", "--kmax", kmax], capsys)
    assert (status, out) == (2, "") and err.count("\n") == 1
    assert f"--kmax: K <= {kmax} gives about " in err and "pass --large" in err
    assert "71183 at K = 16" in err


def test_cells_at_the_limit_and_beyond_with_large(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    from mjstruct.cli.cells import COUNT_AT_MAX, MAX_KMAX

    status, out, _ = _cli(["cells", "--kmax", str(MAX_KMAX), "--json"], capsys)
    assert status == 0
    assert sum(len(c["MJA"]) for c in json.loads(out)["cells"]) == COUNT_AT_MAX
    status, out, _ = _cli(["cells", "--kmax", str(MAX_KMAX + 1), "--large", "--json"], capsys)
    assert status == 0 and json.loads(out)["kmax"] == MAX_KMAX + 1


@pytest.mark.parametrize("number", ["1e400", "1" * 5000])
def test_convert_refuses_a_pyslvs_coordinate_beyond_a_double(
    number: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    src = tmp_path / "big.pmks"
    src.write_text(
        f"M[J[R, P[{number}, 0], L[ground, a]], J[R, P[1, 0], L[a, b]],"
        " J[R, P[2, 1], L[b, c]], J[R, P[3, 0], L[c, ground]]]"
    )
    out = tmp_path / "out.json"
    status, stdout, err = _cli(["convert", str(src), "-o", str(out)], capsys)
    assert (status, stdout) == (2, "")
    assert err.startswith(f"mjstruct convert: {src}: line 1 column 10: the x coordinate ")
    assert err.count("\n") == 1 and "beyond a double" in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.pmks"]

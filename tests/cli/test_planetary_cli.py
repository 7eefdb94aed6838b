"""``mjstruct planetary``: text and JSON output, bad input naming the flag."""

from __future__ import annotations

import json

import pytest

from mjstruct.cli.main import main


def test_json_keys_and_best_set(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["planetary", "--ratio", "12", "--satellites", "3", "--json", "--limit", "3"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert set(out) == {
        "scheme", "ratio", "satellites", "t1", "t2", "y", "ratio_tolerance",
        "coaxial_tolerance", "z_min", "z_max", "range", "count", "sets",
    }  # fmt: skip
    assert set(out["range"]) == {"lower", "upper", "upper_2", "upper_3", "t2_limit_paper"}
    assert out["count"] >= len(out["sets"]) == 3
    best = out["sets"][0]
    assert [best[k] for k in ("Z1", "Z2", "Z3", "Z4")] == [18, 90, 90, 198]
    assert (best["Z1"] + best["Z4"]) % 3 == 0 and best["assembly_number"] == 72


def test_text_lists_the_sets(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["planetary", "--ratio", "4", "--t2", "1.05", "--limit", "2"]) == 0
    text = capsys.readouterr().out
    assert "admissible ratios" in text and "the best 2 shown" in text
    assert len(text.strip().splitlines()) == 6  # 3 header lines, column titles, 2 sets


@pytest.mark.parametrize(
    ("argv", "start"),
    [
        (["--ratio", "20"], "--ratio: 20 is impossible: (9)"),
        (["--ratio", "1.8"], "--ratio: 1.8 is impossible: (7)"),
        (["--ratio", "3", "--satellites", "1"], "--satellites: must be >= 2"),
        (["--ratio", "3", "--t2", "0"], "--t2: must be > 0"),
        (["--ratio", "3", "--z-max", "5"], "--z-max: must be >= 18"),
        (["--ratio", "3", "--limit", "-1"], "--limit: must be >= 0"),
        (["--ratio", "x"], "mjstruct planetary: error: argument --ratio"),
    ],
)
def test_bad_input_exit_2_naming_the_flag(
    argv: list[str], start: str, capsys: pytest.CaptureFixture[str]
) -> None:
    try:
        status = main(["planetary", *argv])
    except SystemExit as exc:  # argparse's own errors leave through SystemExit
        status = int(str(exc.code))
    assert status == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert start in captured.err and len(captured.err.strip().splitlines()) == 1

"""The analyze and iso commands: reports, JSON keys of the contract, bad input."""

from __future__ import annotations

import itertools
import json
import math
import re
import subprocess
import sys

import pytest

from mjstruct.cli.main import main

CONTRACT_KEYS = {
    "n",
    "LA",
    "MJA",
    "V",
    "K",
    "L",
    "AVC",
    "F",
    "N",
    "rc",
    "S_L",
    "loops",
    "code",
    "code_star",
    "canonical",
}


def run(capsys, *argv):
    status = main(list(argv))
    out, err = capsys.readouterr()
    return status, out, err


def test_analyze_json_has_contract_keys(capsys, examples):
    status, out, _ = run(
        capsys, "analyze", str(examples / "seed002-ex1-needle-drive.json"), "--json"
    )
    d = json.loads(out)
    assert status == 0 and set(d) >= CONTRACT_KEYS
    assert d["loops"] == [4, 4, 5, 5, 5]


def test_analyze_text_shows_both_formulas(capsys, examples):
    status, out, _ = run(capsys, "analyze", str(examples / "seed002-ex1-needle-drive.json"))
    assert status == 0
    assert "K = 1 + (V + n3 + 2n4)/2 = 1 + (3 + 1 + 2·1)/2 = 4" in out
    assert "cycle rank of the link–joint graph = 4" in out
    assert "F = n2 − 3 − V − n4 = 8 − 3 − 3 − 1 = 1" in out
    assert "V = ν2 = 3;" not in out and "• MJ factor: V = ν2 = 3\n" in out
    assert "F = (n − 1) − 2K = 9 − 8 = 1" in out
    assert "S_L = 2(F + 3K) − V = 2(1 + 3·4) − 3 = 23" in out
    assert "S_L = Σ i·n_i = 2·8 + 3·1 + 4·1 = 23" in out
    assert "[L] = [4 4 5 5 5]" in out
    assert "Code* = [8110]/[3·0·0]" in out


@pytest.mark.parametrize(
    "argv",
    [
        ["four-bar.json"],
        ["watt.json"],
        ["radial-engine-5.json"],
        ["seed002-ex1-needle-drive.json"],
        ["--code", "[4]/0", "--dof", "1"],
        ["--code", "[51]/[1]"],
    ],
    ids=lambda a: " ".join(a),
)
def test_each_formula_written_once_and_its_numbers_add_up(capsys, examples, argv):
    """No filler (``V = 0 = 0 = 0``, ``− (0)``): consecutive forms of an equality
    differ, and every numeric form evaluates to the value the line states."""
    if not argv[0].startswith("--"):
        argv = [str(examples / argv[0])]
    status, out, _ = run(capsys, "analyze", *argv)
    assert status == 0
    checked = 0
    for line in out.splitlines():
        if not line.startswith("• ") or ":" not in line:
            continue
        for formula in line.split(": ", 1)[1].split("; "):
            forms = [f.strip() for f in formula.split(" = ")]
            if len(forms) < 2:
                continue
            assert all(a != b for a, b in itertools.pairwise(forms)), line
            assert "(0)" not in formula and "+ 0)/2" not in formula, line
            value = forms[-1].split()[0]
            for form in forms[1:-1]:
                arithmetic = re.sub(r"(\d)\(", r"\1*(", form.replace("·", "*").replace("−", "-"))
                if re.fullmatch(r"[\d\s()+*/-]+", arithmetic):
                    assert eval(arithmetic) == float(value), (form, line)
                    checked += 1
    assert checked >= 6


def test_nonplanar_loops_null(capsys, examples):
    status, out, _ = run(capsys, "analyze", str(examples / "seed002-ex5-24-link.json"), "--json")
    d = json.loads(out)
    assert status == 0 and d["loops"] is None and "not planar" in d["loops_note"]


def test_code_only(capsys):
    status, out, _ = run(capsys, "analyze", "--code", "[8110]/[3·0·0]", "--dof", "1", "--json")
    d = json.loads(out)
    assert status == 0
    assert (d["K"], d["AVC"], d["F"], d["S_L"], d["rc"]) == (4, 0, 1, 23, 0)
    status, out, _ = run(capsys, "analyze", "--code", "[11.0001]/4", "--dof", "1", "--json")
    d = json.loads(out)
    assert (d["K"], d["L"], d["S_L"], d["code"]) == (5, 6, 28, "[11.0001]/4")


@pytest.mark.parametrize(
    "code, dof, fragment",
    [
        ("[8110]/3", "2", "AVC"),
        ("[4]/[0·1]", "1", "j <= K"),  # a joint of multiplicity 3 in a 1-loop chain
        ("[4]/3", "1", "V <= 2(K - 1)"),
    ],
)
def test_code_violations_reported(capsys, code, dof, fragment):
    status, out, _ = run(capsys, "analyze", "--code", code, "--dof", dof, "--json")
    assert status == 0
    assert any(fragment in v for v in json.loads(out)["violations"])


def test_iso(capsys, examples):
    status, out, _ = run(
        capsys, "iso", str(examples / "zhivago.json"), str(examples / "stephenson.json"), "--json"
    )
    d = json.loads(out)
    assert status == 0 and d["isomorphic"] is True and d["canonical_a"] == d["canonical_b"]
    status, out, _ = run(
        capsys, "iso", str(examples / "watt.json"), str(examples / "stephenson.json"), "--json"
    )
    assert status == 0 and json.loads(out)["isomorphic"] is False


GOOD = {
    "frame": "0",
    "joints": [
        {"id": "a", "links": ["0", "1"]},
        {"id": "b", "links": ["1", "2"]},
        {"id": "c", "links": ["2", "3"]},
        {"id": "d", "links": ["3", "0"]},
    ],
    "drivers": ["a"],
}


def variant(**change):
    d = json.loads(json.dumps(GOOD))
    d.update(change)
    return json.dumps(d)


BAD = [
    ("not-json", "{joints: ]", "not valid JSON"),
    ("missing-joints", json.dumps({"frame": "0"}), "joints: missing"),
    (
        "one-link-joint",
        variant(joints=[*GOOD["joints"], {"id": "e", "links": ["1"]}]),
        "joints[4].links",
    ),
    (
        "link-twice",
        variant(joints=[*GOOD["joints"], {"id": "e", "links": ["1", "2", "1"]}]),
        "appears twice",
    ),
    (
        "duplicate-joint-id",
        variant(joints=[*GOOD["joints"], {"id": "a", "links": ["1", "3"]}]),
        "duplicate joint id",
    ),
    ("duplicate-link-id", variant(links=["0", "1", "2", "3", "3"]), "duplicate link id"),
    ("unknown-link", variant(links=["0", "1", "2"]), "unknown link '3'"),
    (
        "disconnected",
        variant(joints=[*GOOD["joints"], {"id": "e", "links": ["7", "8"]}]),
        "disconnected",
    ),
    (
        "unknown-type",
        variant(joints=[{"id": "a", "links": ["0", "1"], "type": "Q"}, *GOOD["joints"][1:]]),
        "unknown joint type",
    ),
    ("driver-not-joint", variant(drivers=["zz"]), "drivers"),
    ("frame-unknown", variant(frame="9"), "frame"),
    ("links-not-list", variant(joints=[{"id": "a", "links": "01"}]), "joints[0].links"),
]


@pytest.mark.parametrize("text, fragment", [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_bad_input_one_line_exit_2(tmp_path, capsys, text, fragment):
    f = tmp_path / "bad.json"
    f.write_text(text)
    status, out, err = run(capsys, "analyze", str(f), "--json")
    assert status == 2
    assert out == ""
    assert err.count("\n") == 1 and fragment in err
    assert "Traceback" not in err


def test_bad_input_in_a_real_process_has_no_traceback(tmp_path):
    f = tmp_path / "bad.json"
    f.write_text(BAD[2][1])
    p = subprocess.run(
        [sys.executable, "-m", "mjstruct.cli.main", "analyze", str(f)],
        capture_output=True,
        text=True,
    )
    assert p.returncode == 2 and p.stdout == ""
    assert p.stderr.count("\n") == 1 and "Traceback" not in p.stderr


def test_missing_file_and_bad_usage(capsys, tmp_path):
    status, out, err = run(capsys, "analyze", str(tmp_path / "nope.json"))
    assert status == 2 and "no such file" in err and out == ""
    status, out, err = run(capsys, "analyze")
    assert status == 2 and "either" in err and out == ""
    with pytest.raises(SystemExit) as exc:
        main(["frobnicate"])
    assert exc.value.code == 2


def test_toml_equals_json(tmp_path, capsys, examples):
    toml = tmp_path / "four.toml"
    toml.write_text(
        'frame = "0"\ndrivers = ["O1"]\n'
        + "".join(
            f'[[joints]]\nid = "{j}"\nlinks = [{a}, {b}]\n'
            for j, a, b in [("O1", 0, 1), ("A", 1, 2), ("B", 2, 3), ("O2", 0, 3)]
        )
    )
    _, a, _ = run(capsys, "analyze", str(toml), "--json")
    _, b, _ = run(capsys, "analyze", str(examples / "four-bar.json"), "--json")
    da, db = json.loads(a), json.loads(b)
    da.pop("name"), db.pop("name")
    assert da == db


@pytest.mark.parametrize(
    "command, heavy",
    [
        # analyze: none of the heavy libraries (scipy above all: the singular-position
        # and dynamics modules use it)
        (["analyze", "radial-engine-5.json", "--json"], ("sympy", "matplotlib", "scipy")),
        (["iso", "four-bar.json", "watt.json", "--json"], ("sympy", "matplotlib", "scipy")),
        (["atlas", "--links", "6", "--json"], ("sympy", "matplotlib", "scipy")),
        (
            ["cells", "--kmax", "2", "--dof", "1", "--count", "--json"],
            ("sympy", "matplotlib", "scipy"),
        ),
        (["lookup", "watt.json", "--json"], ("sympy", "matplotlib", "scipy")),
        (["convert", "four-bar.json", "--to", "toml"], ("sympy", "matplotlib", "scipy")),
    ],
)
def test_structural_path_leaves_heavy_libraries_out(examples, command, heavy):
    argv = [str(examples / a) if a.endswith(".json") else a for a in command]
    probe = (
        "import sys, io, contextlib\n"
        "from mjstruct.cli.main import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    code = main({argv!r})\n"
        f"print(code, sorted(m for m in {heavy!r} if m in sys.modules))"
    )
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert p.stdout.strip() == "0 []", p.stdout + p.stderr


def test_analyze_leaves_networkx_out(examples):
    probe = (
        "import sys, io, contextlib\n"
        "from mjstruct.cli.main import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    main(['analyze', {str(examples / 'radial-engine-5.json')!r}, '--json'])\n"
        "print('networkx' in sys.modules)"
    )
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert p.stdout.strip() == "False"


def test_only_the_command_that_runs_is_imported(examples):
    probe = (
        "import sys, io, contextlib\n"
        "from mjstruct.cli.main import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    main(['analyze', {str(examples / 'four-bar.json')!r}])\n"
        "print(sorted(m for m in sys.modules if m.startswith(('mjstruct.cli.', 'mjstruct.plot',"
        " 'mjstruct.kinematics', 'mjstruct.dynamics')) or m == 'numpy'))"
    )
    p = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    assert (
        p.stdout.strip() == "['mjstruct.cli.analyze', 'mjstruct.cli.main', 'mjstruct.cli.output']"
    )


def test_analyze_reports_generic_mobility(tmp_path, capsys):
    # five-bar (F = 2) carrying a rigid, over-constrained double four-bar: formula F = 1
    joints = [
        ("O1", 0, 1),
        ("A", 1, 2),
        ("B", 2, 3),
        ("C", 3, 4),
        ("O2", 4, 0),
        ("D", 4, 5),
        ("E", 5, 6),
        ("G", 6, 7),
        ("H", 7, 4),
        ("I", 5, 7),
    ]
    f = tmp_path / "m.json"
    f.write_text(
        json.dumps(
            {
                "frame": "0",
                "drivers": ["O1"],
                "joints": [{"id": j, "links": [a, b]} for j, a, b in joints],
            }
        )
    )
    status, out, _ = run(capsys, "analyze", str(f), "--json")
    d = json.loads(out)
    assert status == 0 and d["F"] == 1
    g = d["generic_mobility"]
    assert g["F_generic"] == 2 and g["redundant_constraints"] == 1
    assert g["overconstrained"] == [{"links": ["4", "5", "6", "7"], "redundant": 1}]
    status, out, _ = run(capsys, "analyze", str(f))
    assert "F_generic = 2" in out and "over-constrained sub-chain {4, 5, 6, 7}" in out


def test_library_parameters_become_flags_on_the_command_line(capsys):
    assert main(["analyze", "--code", "[4 x]/0"]) == 2
    assert capsys.readouterr().err.startswith("mjstruct analyze: --code: ")
    assert main(["atlas", "--links", "30"]) == 2
    assert capsys.readouterr().err.startswith("mjstruct atlas: --links: ")


def test_singular_text_speaks_degrees_within_a_turn_and_says_what_labels_mean(capsys, examples):
    ms4 = str(examples / "fourbar-ms4.json")
    status, out, _ = run(capsys, "singular", ms4, "--clearance", "0.01", "--json")
    d = json.loads(out)
    status, text, _ = run(capsys, "singular", ms4, "--clearance", "0.01")
    assert status == 0
    rows = [line.split() for line in text.splitlines() if line.startswith("  ") and "_" in line]
    rows = [r for r in rows if r[0] in {"input_limit", "output_extreme", "change_point"}]
    assert len(rows) == len(d["singular"]) == 3
    # each position's q, from the JSON (radians, continued past 2π), within one turn
    expected = sorted(round(math.degrees(p["q"]), 4) % 360.0 for p in d["singular"])
    shown = [float(r[1]) for r in rows]
    assert shown == sorted(shown) and all(0 <= q < 360 for q in shown)
    assert shown == pytest.approx(expected, abs=5e-5)
    assert all(re.fullmatch(r"-?\d+\.\d{4}", r[1]) for r in rows)  # 4 decimals
    assert max(p["q"] for p in d["singular"]) > 2 * math.pi - 1e-9  # the JSON goes on
    # the paper's labels said in words
    assert "change point: 1 + P2 = P1 + P3 (system (4) of [Four-bar clearances]" in text
    assert "four-bar formula (3), lambda 0.5, delta 0.01" in text
    assert "formula-3" not in text and "system (4): (4.2)" not in text
    assert "output_extreme: the output reverses" in text


def test_singular_text_of_a_range_across_zero(capsys, examples):
    status, text, _ = run(capsys, "singular", str(examples / "triad-class-iii.json"))
    assert status == 0
    assert "input range: 346.2075 to 71.8053 deg (through 0)" in text

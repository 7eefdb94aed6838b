"""Graph model conversions and the seed-000 incidence matrix."""

from __future__ import annotations

import json

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mjstruct.io import from_link_graph, mechanism_from_dict, mechanism_to_dict, read_mechanism
from mjstruct.mechanism import JOINT, LINK
from mjstruct.structure.incidence import incidence_matrix
from mjstruct.structure.isomorphism import canonical_code
from strategies import field_paths


def test_round_trip_keeps_everything(examples):
    for f in sorted(examples.glob("*.json")):
        m = read_mechanism(f)
        again = mechanism_from_dict(json.loads(json.dumps(mechanism_to_dict(m))))
        assert again == m and again.extra == m.extra


def test_mj_stays_whole_in_the_bipartite_graph(examples):
    m = read_mechanism(examples / "radial-engine-5.json")
    g = m.graph()
    assert g.degree((JOINT, "A")) == 6
    assert nx.is_bipartite(g)
    assert sum(1 for node in g if node[0] == LINK) == 12


def test_from_link_graph_matches_file(examples):
    g = nx.cycle_graph(4)
    m = from_link_graph(g, frame=0)
    assert canonical_code(m) == canonical_code(read_mechanism(examples / "four-bar.json"))


def test_zhivago_incidence_matches_seed_table_2(examples):
    m = read_mechanism(examples / "zhivago.json")
    inc = incidence_matrix(m)
    seed = np.array(
        [  # seed 000, Table 2 (rows: frame, links 1-5; columns k = 1..7)
            [-1, 0, 0, 0, 0, 0, -1],
            [1, -1, -1, 0, 0, 0, 0],
            [0, 1, 0, 0, -1, 0, 0],
            [0, 0, 1, -1, 0, 0, 0],
            [0, 0, 0, 1, 1, 1, 0],
            [0, 0, 0, 0, 0, -1, 1],
        ]
    )
    assert inc.matrix.tolist() == seed.tolist()
    assert inc.H.tolist() == [1] * 7
    assert not inc.matrix.sum(axis=0).any()


def test_mj_expands_into_simple_joints(examples):
    inc = incidence_matrix(read_mechanism(examples / "radial-engine-5.json"))
    a_cols = [c for c, j in zip(inc.columns, inc.joints, strict=True) if j == "A"]
    assert len(a_cols) == 5  # j = 5 simple-joint equivalents
    assert inc.matrix.shape == (12, 16)
    assert not inc.matrix.sum(axis=0).any()
    assert inc.H.tolist().count(2) == 5


def test_toml_round_trip_of_every_example(examples):
    from mjstruct.io import mechanism_to_toml, parse_mechanism

    def without_nulls(v):  # TOML has no null: such keys are left out
        if isinstance(v, dict):
            return {k: without_nulls(x) for k, x in v.items() if x is not None}
        return [without_nulls(x) for x in v] if isinstance(v, list) else v

    for f in sorted(examples.glob("*.json")):
        m = read_mechanism(f)
        again = parse_mechanism(mechanism_to_toml(m), toml=True)
        assert again == m and again.extra == without_nulls(dict(m.extra))


# -- hostile input: what is read, how much, and what it may contain -------------------

FOUR_BAR = {
    "frame": "0",
    "drivers": ["O1"],
    "joints": [
        {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
        {"id": "A", "links": ["1", "2"], "at": [0, 1]},
        {"id": "B", "links": ["2", "3"], "at": [2, 1.5]},
        {"id": "O2", "links": ["3", "0"], "at": [2, 0]},
    ],
}


def _cli(argv, capsys):
    from mjstruct.cli.main import main

    status = main(argv)
    out = capsys.readouterr()
    return status, out.out, out.err


def test_non_regular_files_are_refused_before_reading(tmp_path, capsys):
    import os

    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)  # no writer: opening it would block forever
    for path in ("/dev/zero", str(fifo), str(tmp_path)):
        status, out, err = _cli(["analyze", path], capsys)
        assert (status, out) == (2, "") and "not a regular file" in err and err.count("\n") == 1


def test_files_over_the_size_limit_are_refused(tmp_path, capsys, monkeypatch):
    import pytest

    from mjstruct.errors import MechanismError
    from mjstruct.io import MAX_FILE_BYTES

    path = tmp_path / "m.json"
    path.write_text(json.dumps(FOUR_BAR))
    size = path.stat().st_size
    with pytest.raises(MechanismError, match="exceeds 100 bytes; set MJSTRUCT_MAX_FILE_BYTES"):
        read_mechanism(path, max_bytes=100)
    assert read_mechanism(path, max_bytes=size).n == 4
    monkeypatch.setenv("MJSTRUCT_MAX_FILE_BYTES", str(size - 1))
    status, _, err = _cli(["analyze", str(path)], capsys)
    assert status == 2 and "exceeds" in err
    monkeypatch.setenv("MJSTRUCT_MAX_FILE_BYTES", "lots")
    status, _, err = _cli(["analyze", str(path)], capsys)
    assert status == 2 and err.startswith("mjstruct analyze: MJSTRUCT_MAX_FILE_BYTES:")
    assert MAX_FILE_BYTES == 16 * 2**20  # the documented default


def test_dash_reads_standard_input(capsys, monkeypatch):
    import io
    import sys

    from mjstruct.io import mechanism_to_toml

    for text in (json.dumps(FOUR_BAR), mechanism_to_toml(mechanism_from_dict(FOUR_BAR))):
        monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(text.encode())))
        status, out, _ = _cli(["analyze", "-", "--json"], capsys)
        assert status == 0 and json.loads(out)["F"] == 1
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(b"{" * 20)))
    status, _, err = _cli(["analyze", "-"], capsys)
    assert status == 2 and "standard input: not valid JSON" in err
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(b"")))
    status, _, err = _cli(["analyze", "-"], capsys)
    assert status == 2 and "standard input is empty" in err


def test_deep_nesting_and_huge_numbers_are_bad_input(tmp_path, capsys):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    status, _, err = _cli(["analyze", str(deep)], capsys)
    assert status == 2 and "nested too deeply" in err and err.count("\n") == 1
    big = json.loads(json.dumps(FOUR_BAR))
    big["joints"][1]["at"] = [10**400, 0]
    path = tmp_path / "big.json"
    path.write_text(json.dumps(big))
    status, _, err = _cli(["analyze", str(path)], capsys)
    assert status == 2 and "joints[1].at[0]: number too large for a double" in err
    assert len(err) < 200  # the number is not echoed in full
    path.write_text(json.dumps(FOUR_BAR).replace('"at": [0, 1]', '"at": [' + "9" * 5000 + ", 1]"))
    status, _, err = _cli(["analyze", str(path)], capsys)
    assert status == 2 and "unreadable number" in err


DYNAMICS_EXAMPLE = "slider-crank-seed000-dynamics.json"


@pytest.mark.parametrize(
    ("where", "literal", "named"),
    [
        (("parameters", "p"), "9" * 400, "parameters.p: number too large for a double"),
        (("parameters", "M"), "-1e400", "parameters.M: not a finite number"),
        (("inertia", "1", "J"), "1" + "0" * 400, "inertia.1.J: number too large for a double"),
        (("inertia", "3", "mass"), "1e400", "inertia.3.mass: not a finite number"),
        (("gravity", 1), "-1e999", "gravity[1]: not a finite number"),
        (("joints", 0, "at", 1), "NaN", "joints[0].at[1]: not a finite number"),
        (("energy_change",), "Infinity", "energy_change: not a finite number"),
    ],
)
@pytest.mark.parametrize("command", ["analyze", "kinematics", "dynamics", "singular"])
def test_numbers_beyond_a_double_are_bad_input_naming_the_field(
    examples, tmp_path, capsys, where, literal, named, command
):
    data = json.loads((examples / DYNAMICS_EXAMPLE).read_text())
    cur = data
    for k in where[:-1]:
        cur = cur[k]
    cur[where[-1]] = "@@"  # replaced by the literal: json.dumps cannot write 10**400 as text
    path = tmp_path / "m.json"
    path.write_text(json.dumps(data).replace('"@@"', literal))
    extra = {"kinematics": ["--frames", "4"], "dynamics": ["--frames", "4", "--speed", "1"]}
    status, out, err = _cli([command, str(path), *extra.get(command, [])], capsys)
    assert (status, out) == (2, "")
    assert named in err and err.count("\n") == 1 and len(err) < 200


def test_numbers_beyond_a_double_in_toml_and_ids_of_any_size(tmp_path, capsys):
    from mjstruct.errors import MechanismError
    from mjstruct.io import mechanism_to_toml, parse_mechanism

    toml = mechanism_to_toml(mechanism_from_dict(FOUR_BAR))
    for bad, named in [("inf", "x: not a finite"), ("1_" + "0" * 400, "x: number too large")]:
        with pytest.raises(MechanismError, match=named):
            parse_mechanism(toml.replace("\n", f"\nx = {bad}\n", 1), toml=True)
    # an id is read as a string: a long integer is a valid id, not an overflowing number
    big_id = json.dumps(FOUR_BAR).replace('"O1"', "1" + "0" * 400)
    m = parse_mechanism(big_id)
    assert "1" + "0" * 400 in {j.id for j in m.joints}
    # a name that merely contains "inf" passes the gate's walk unharmed
    assert parse_mechanism(json.dumps(dict(FOUR_BAR, name="info nan"))).name == "info nan"


def test_point_ids_are_unique_and_distinct_from_joint_ids():
    import pytest

    from mjstruct.errors import MechanismError

    twice = dict(FOUR_BAR, points=[{"id": "P", "link": "2", "at": [1, 1]}] * 2)
    with pytest.raises(MechanismError, match=r"^points\[1\]\.id: point id 'P' is used twice$"):
        mechanism_from_dict(twice)
    clash = dict(FOUR_BAR, points=[{"id": "A", "link": "2", "at": [1, 1]}])
    with pytest.raises(MechanismError, match=r"^points\[0\]\.id: 'A' is already a joint id$"):
        mechanism_from_dict(clash)


FUZZ_BASE = dict(FOUR_BAR, name="four-bar", points=[{"id": "P", "link": "2", "at": [1, 2]}])
JSON_VALUES = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(10**400), 10**400)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=5),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=4), inner, max_size=4)
    ),
    max_leaves=8,
)


@settings(max_examples=120, deadline=None)
@given(
    st.sampled_from(list(field_paths(FUZZ_BASE))),
    JSON_VALUES,
    st.sampled_from(["analyze", "assur", "iso"]),
)
def test_any_value_in_any_field_is_an_answer_or_bad_input(tmp_path_factory, where, value, command):
    """Fuzz: exit 0 or 2, never 1 (internal error), and strict JSON on success."""
    import contextlib
    import io

    from mjstruct.cli.main import main

    data = json.loads(json.dumps(FUZZ_BASE))
    if where:
        cur = data
        for k in where[:-1]:
            cur = cur[k]
        cur[where[-1]] = value
    else:
        data = value
    path = tmp_path_factory.mktemp("fuzz") / "m.json"
    path.write_text(json.dumps(data))
    argv = ["iso", str(path), str(path)] if command == "iso" else [command, str(path), "--json"]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = main(argv)
    assert status in (0, 2), err.getvalue()
    assert err.getvalue().count("\n") == (status == 2)
    if status == 0 and command != "iso":
        json.loads(out.getvalue(), parse_constant=lambda c: pytest.fail(f"{c} in JSON"))


@pytest.mark.parametrize(
    ("call", "parameter"),
    [
        (lambda mj, m: mj.assur_groups(m, "O1"), "drivers"),
        (lambda mj, m: mj.assur_groups("four-bar.json"), "m"),
        (lambda mj, m: mj.canonical_code(m, "bogus"), "level"),
        (lambda mj, m: mj.is_isomorphic(m, None), "b"),
        (lambda mj, m: mj.driver_choices(m, count="2"), "count"),
        (lambda mj, m: mj.structural_report(None), "m"),
        (lambda mj, m: mj.generic_mobility(3), "m"),
        (lambda mj, m: mj.atlas("1", 8), "F"),
        (lambda mj, m: mj.atlas(1, 8.0), "n"),
        (lambda mj, m: mj.lookup("x"), "m"),
        (lambda mj, m: mj.parse_code(None), "code"),
        (lambda mj, m: mj.Mechanism.build(None), "joints"),
        (lambda mj, m: mj.Mechanism.build([("a", 5)]), "joints[0].links"),
        (lambda mj, m: mj.read_mechanism(None), "path"),
        (lambda mj, m: mj.cells("3"), "kmax"),
        (lambda mj, m: mj.loop_assortment("x"), "m"),
        (lambda mj, m: mj.pebble_rank(None), "m"),
        (lambda mj, m: mj.code_report(5), "code"),
        (lambda mj, m: mj.kinematic_analysis("x"), "model"),
        (lambda mj, m: mj.kinematic_analysis(m, frames="10"), "frames"),
        (lambda mj, m: mj.kinematic_analysis(m, frames=2.5), "frames"),
        (lambda mj, m: mj.kinematic_analysis(m, speed="1"), "speed"),
        (lambda mj, m: mj.kinematic_analysis(m, tol=None), "tol"),
        (lambda mj, m: mj.kinematic_analysis(m, stroke=[1]), "stroke"),
        (lambda mj, m: mj.kinematic_analysis(m, drivers="O1"), "drivers"),
        (lambda mj, m: mj.dynamic_analysis("x", speed=1.0), "mechanism"),
        (lambda mj, m: mj.dynamic_analysis(m, speed="1"), "speed"),
        (lambda mj, m: mj.dynamic_analysis(m, qdot0=[1]), "qdot0"),
        (lambda mj, m: mj.dynamic_analysis(m, speed=1.0, frames=2.5), "frames"),
        (lambda mj, m: mj.dynamic_analysis(m, speed=1.0, drivers="O1"), "drivers"),
        (lambda mj, m: mj.dynamic_analysis(m, speed=1.0, model=3), "model"),
        (lambda mj, m: mj.plan_kinematics("x"), "m"),
        (lambda mj, m: mj.plan_kinematics(m, drivers="O1"), "drivers"),
        (lambda mj, m: mj.read_geometry("x"), "m"),
        (lambda mj, m: mj.jacobian_at_reference("x"), "m"),
        (lambda mj, m: mj.singular_analysis("x"), "mechanism"),
        (lambda mj, m: mj.mechanism_to_dict("x"), "m"),
        (lambda mj, m: mj.mechanism_to_toml("x"), "m"),
        (lambda mj, m: mj.link_assortment("x"), "m"),
        (lambda mj, m: mj.mj_assortment("x"), "m"),
        (lambda mj, m: mj.mj_factor("x"), "m"),
        (lambda mj, m: mj.simple_joint_count("x"), "m"),
        (lambda mj, m: mj.to_networkx("x"), "m"),
        (lambda mj, m: mj.from_link_graph("x"), "g"),
        (lambda mj, m: mj.is_admissible("x"), "m"),
        (lambda mj, m: mj.rigid_subchain("x"), "m"),
        (lambda mj, m: mj.structural_code("x", 2), "a"),
        (lambda mj, m: mj.structural_code(mj.assortment(m), "2"), "K"),
        (lambda mj, m: mj.full_code("x", 2), "a"),
        (lambda mj, m: mj.fourbar_theory("a", 1, 1), "P1"),
        (lambda mj, m: mj.fourbar_theory(0.5, None, 1), "P2"),
        (lambda mj, m: mj.parse_mechanism(None), "text"),
        (lambda mj, m: mj.Mechanism(links=5, joints=3), "links"),
        (lambda mj, m: mj.Mechanism(links=("0", "1"), joints=3), "joints"),
        (lambda mj, m: mj.Mechanism(links=m.links, joints=m.joints, frame=0), "frame"),
    ],
)
def test_public_functions_name_the_parameter_on_wrong_types(call, parameter):
    import mjstruct
    from mjstruct.errors import MechanismError

    m = mechanism_from_dict(FOUR_BAR)
    with pytest.raises(MechanismError) as info:
        call(mjstruct, m)
    assert str(info.value).startswith(parameter + ": ")
    assert "\n" not in str(info.value) and len(str(info.value)) < 200


def test_right_types_in_other_spellings_are_accepted():
    import mjstruct

    m = mechanism_from_dict(FOUR_BAR)
    r = mjstruct.kinematic_analysis(m, drivers=("O1",), frames=np.int64(8), speed=np.float64(2))
    assert len(r.q) == 8 and r.speed == 2.0
    assert mjstruct.structural_code(mjstruct.assortment(m), np.int64(2)) == "[40]/0"


TOML_PIECES = st.sampled_from(
    [
        'frame = "0"\n',
        "frame = 0\n",
        'drivers = ["O1"]\n',
        "drivers = [1, 2]\n",
        '[[joints]]\nid = "O1"\nlinks = ["0", "1"]\n',
        '[[joints]]\nid = "A"\nlinks = ["1", "2"]\nat = [0, 1]\n',
        '[[joints]]\nid = "B"\nlinks = ["2", "0"]\ntype = "P"\n',
        "[[joints]]\nid = 7\nlinks = []\n",
        '[[points]]\nid = "P"\nlink = "1"\nat = [1e400, 0]\n',
        "x = 1979-05-27T07:32:00Z\n",
        "nan = nan\n",
        "[masses]\n",
        '"joints" = 3\n',
        "= broken\n",
    ]
)


@settings(max_examples=80, deadline=None)
@given(st.lists(TOML_PIECES, max_size=8), st.sampled_from(["analyze", "assur", "lookup"]))
def test_any_toml_file_is_an_answer_or_bad_input(tmp_path_factory, pieces, command):
    import contextlib
    import io

    from mjstruct.cli.main import main

    path = tmp_path_factory.mktemp("fuzz") / "m.toml"
    path.write_text("".join(pieces))
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        status = main([command, str(path)])
    assert status in (0, 2), err.getvalue()
    assert err.getvalue().count("\n") == (status == 2)


@pytest.mark.parametrize("command", ["analyze", "lookup", "kinematics", "singular", "convert"])
def test_paths_in_error_messages_cannot_drive_the_terminal(tmp_path, capsys, command):
    name = str(tmp_path / "nonexist\x1b[31m\x07\nsecond line\x9b.json")
    extra = ["--to", "toml"] if command == "convert" else []
    status, out, err = _cli([command, name, *extra], capsys)
    assert (status, out) == (2, "")
    assert err.count("\n") == 1 and err.endswith("no such file\n")
    assert not any(c in err for c in "\x1b\x07\x9b")
    assert "nonexist\\x1b[31m\\x07\\x0asecond line\\x9b" in err


def test_ids_in_error_messages_are_shown_escaped(tmp_path, capsys):
    bad = dict(FOUR_BAR, drivers=["\x1b]0;owned\x07"])
    path = tmp_path / "m.json"
    path.write_text(json.dumps(bad))
    status, _, err = _cli(["assur", str(path)], capsys)
    assert status == 2 and "\x1b" not in err and "\x07" not in err
    assert "\\x1b]0;owned\\x07" in err and err.count("\n") == 1

"""pyslvs expressions: reading what pyslvs writes, round trips over the shipped examples,
the kinds that cannot be represented."""

from __future__ import annotations

import math

import pytest

from mjstruct.errors import MechanismError
from mjstruct.exchange.pyslvs import (
    mechanism_from_pyslvs,
    mechanism_from_pyslvs_project,
    mechanism_to_pyslvs,
    mechanism_to_pyslvs_project,
    parse_pyslvs,
    pyslvs_inputs,
)
from mjstruct.io import mechanism_to_dict, read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.structure.isomorphism import canonical_code
from project_paths import DATA, EXAMPLES

PYSLVS_DATA = DATA / "pyslvs"
LEVELS = ("chain", "kinds", "mechanism")


def _representable(m: Mechanism) -> bool:
    return all(
        j.at is not None and (j.kind == "R" or (j.axis is not None and len(j.links) == 2))
        for j in m.joints
    )


def _unit(v: tuple[float, float]) -> tuple[float, float]:
    n = math.hypot(*v)
    return (v[0] / n, v[1] / n)


def _same_geometry(a: Mechanism, b: Mechanism, tol: float, signed: bool = True) -> None:
    assert len(a.joints) == len(b.joints)
    for ja, jb in zip(a.joints, b.joints, strict=True):
        assert ja.kind == jb.kind
        assert ja.at is not None and jb.at is not None
        assert math.dist(ja.at, jb.at) <= tol, (ja.id, ja.at, jb.at)
        if ja.kind == "P":
            assert ja.axis is not None and jb.axis is not None
            ua, ub = _unit(ja.axis), _unit(jb.axis)
            cross = ua[0] * ub[1] - ua[1] * ub[0]
            dot = ua[0] * ub[0] + ua[1] * ub[1]
            assert abs(cross) <= 1e-12, (ja.id, ja.axis, jb.axis)
            assert dot > 0 or not signed, (ja.id, ja.axis, jb.axis)
    assert len(a.points) == len(b.points)
    for pa, pb in zip(a.points, b.points, strict=True):
        assert math.dist(pa.at, pb.at) <= tol, (pa.id, pa.at, pb.at)


def test_round_trip_over_every_representable_example():
    done = []
    for path in sorted(EXAMPLES.glob("*.json")):
        m = read_mechanism(path)
        if not _representable(m):
            with pytest.raises(MechanismError, match=r"joints\[\d+\]\.(at|axis|links)"):
                mechanism_to_pyslvs(m)
            continue
        text = mechanism_to_pyslvs(m)
        back = mechanism_from_pyslvs(text)
        for level in LEVELS:
            assert canonical_code(back, level) == canonical_code(m, level), (path.name, level)
        _same_geometry(m, back, tol=0.0)  # positions are written exactly
        assert back.links == m.links and back.frame == m.frame
        assert [j.id for j in back.joints] == [j.id for j in m.joints]
        assert [j.links for j in back.joints] == [j.links for j in m.joints]
        assert back.drivers == m.drivers and back.name == m.name
        assert dict(back.extra) == dict(m.extra)
        # a second trip moves nothing (slot angles may change in the last bit)
        again = mechanism_from_pyslvs(mechanism_to_pyslvs(back))
        _same_geometry(back, again, tol=0.0)
        assert again.joints == back.joints or any(j.kind == "P" for j in m.joints)
        done.append(path.stem)
    # the examples with geometry: R and P joints, MJs, coupler points
    assert {"four-bar", "slider-crank", "kin-radial-engine-5", "scotch-yoke"} <= set(done)
    assert len(done) >= 8


def test_round_trip_without_header_keeps_structure_and_geometry():
    m = read_mechanism(EXAMPLES / "kin-radial-engine-5.json")
    back = mechanism_from_pyslvs(mechanism_to_pyslvs(m, header=False))
    assert back.frame == "ground"
    assert [j.id for j in back.joints] == [f"P{i}" for i in range(len(m.joints))]
    assert canonical_code(back, "kinds") == canonical_code(m, "kinds")
    assert back.drivers == ()
    _same_geometry(m, back, tol=0.0)


def test_reads_the_radial_engine_as_pyslvs_writes_it():
    """pyslvs rounds to 4 decimals and keeps slot angles modulo 180 degrees."""
    m = read_mechanism(EXAMPLES / "kin-radial-engine-5.json")
    got = mechanism_from_pyslvs((PYSLVS_DATA / "kin-radial-engine-5.pmks").read_text())
    assert canonical_code(got, "kinds") == canonical_code(m, "kinds")
    mj = [j for j in got.joints if j.is_multiple]
    assert len(mj) == 1 and mj[0].multiplicity == 5
    _same_geometry(m, got, tol=1e-4 * math.sqrt(2), signed=False)


@pytest.mark.parametrize("name", ["zhivago", "scotch-yoke"])
def test_reads_shipped_examples_as_pyslvs_writes_them(name):
    m = read_mechanism(EXAMPLES / f"{name}.json")
    got = mechanism_from_pyslvs((PYSLVS_DATA / f"{name}.pmks").read_text())
    for level in ("chain", "kinds"):
        assert canonical_code(got, level) == canonical_code(m, level)
    _same_geometry(m, got, tol=1e-4 * math.sqrt(2), signed=False)


def test_editor_layout_comments_colours_and_coupler_point():
    got = mechanism_from_pyslvs((PYSLVS_DATA / "four-bar-coupler.pmks").read_text())
    assert got.frame == "ground"
    assert got.links == ("ground", "L1", "L2", "L3")
    assert [j.id for j in got.joints] == ["P0", "P1", "P2", "P4"]
    assert [(p.id, p.link, p.at) for p in got.points] == [("P3", "L2", (33.3, 66.95))]
    four_bar = read_mechanism(EXAMPLES / "four-bar.json")
    assert canonical_code(got, "kinds") == canonical_code(four_bar, "kinds")
    colours = [j.color for j in parse_pyslvs((PYSLVS_DATA / "four-bar-coupler.pmks").read_text())]
    assert colours == ["Green", "Green", "Dark-Red", "(255, 128, 0)", "Green"]


def test_block_comment_and_a_multiple_joint_on_a_slider():
    got = mechanism_from_pyslvs((PYSLVS_DATA / "offset-slider.pmks").read_text())
    mj = got.joint("P2")
    assert mj.links == ("L2", "L3", "L4") and mj.multiplicity == 2
    slider = got.joint("P3")
    assert slider.kind == "P" and slider.axis == (1.0, 0.0)
    assert got.n == 6 and len(got.joints) == 6


def test_pin_in_slot_is_refused_or_replaced_by_a_slider_block():
    text = (PYSLVS_DATA / "crank-slider-rp.pmks").read_text()
    with pytest.raises(MechanismError, match=r"J\[RP\] #2 is a pin in a slot"):
        mechanism_from_pyslvs(text)
    got = mechanism_from_pyslvs(text, pin_slot="block")
    assert got.n == 4 and [j.kind for j in got.joints] == ["R", "R", "P", "R"]
    assert got.joint("P2").links == ("ground", "ground_block2")
    assert got.joint("P2_pin").links == ("ground_block2", "L2")
    slider_crank = read_mechanism(EXAMPLES / "slider-crank.json")
    assert canonical_code(got, "kinds") == canonical_code(slider_crank, "kinds")


def test_kinematics_accepts_an_imported_mechanism():
    from mjstruct.kinematics.solver import kinematic_analysis

    got = mechanism_from_pyslvs(
        (PYSLVS_DATA / "crank-slider-rp.pmks").read_text(), pin_slot="block", drivers=["P0"]
    )
    result = kinematic_analysis(got, frames=12, speed=1.0)
    # the pin stays on the slot line y = -10 through the whole turn
    ys = result.joints["P2_pin"]["y"]
    assert max(abs(y + 10.0) for y in ys) < 1e-9


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("J[R, P[0, 0], L[a, b]]", r"expected 'M\['"),
        ("M[J[R, P[0, 0], L[a, b]]", "expected ',' or ']' after a joint, found the end"),
        ("M[J[Q, P[0, 0], L[a, b]]]", "line 1 column 5: expected a joint kind R, P or RP"),
        ("M[J[P, P[0, 0], L[a, b]]]", r"a P joint needs its slot angle"),
        ("M[J[R, A[3], P[0, 0], L[a, b]]]", r"no A\[...\] in an R joint"),
        ("M[J[R, P[0], L[a, b]]]", "expected ','"),
        ("M[J[R, P[0, 0], L[a, b]]] x", "expected the end"),
        ("M[J[R, P[0, 0], L[a, b]], J[R, P[1, 1], L[]]]", r"J\[R\] #1 joins no link"),
        ("M[J[P, A[0], P[0, 0], L[a, b, c]]]", "lists 3 links; a prismatic joint joins"),
        ("M[J[R, P[0, 0], L[a, b]], J[R, P[1, 1], L[c, d]]]", "disconnected"),
        ("M[J[R, P[0, 0], L[a, a]]]", "appears twice"),
        ("M[J[R, P[0, $], L[a, b]]]", r"unexpected character '\$'"),
        # numbers a double cannot hold: bad input at their place, never inf in a file
        ("M[J[R, P[1e400, 0], L[a, b]]]", "column 10: the x coordinate 1e400 is beyond a double"),
        (
            "M[J[R, P[0, " + "9" * 5000 + "], L[a, b]]]",
            r"column 13: the y coordinate 999999999999…\(5000 characters\) is beyond a double",
        ),
        ("M[J[P, A[-1e999], P[0, 0], L[a, b]]]", "the slot angle in degrees -1e999 is beyond"),
        ("M[J[R, color[(1e309, 0, 0)], P[0, 0], L[a, b]]]", "a colour component 1e309 is beyond"),
    ],
)
def test_bad_expressions_give_one_line_errors(text, message):
    with pytest.raises(MechanismError, match=message) as info:
        mechanism_from_pyslvs(text)
    assert "\n" not in str(info.value)


def test_writer_refuses_what_pyslvs_cannot_hold():
    m = Mechanism.build([("a", [0, 1]), ("b", [1, 2, 0], "P")], frame=0)
    with pytest.raises(MechanismError, match=r"joints\[0\]\.at"):
        mechanism_to_pyslvs(m)
    geo = read_mechanism(EXAMPLES / "slider-crank.json")
    d = mechanism_to_dict(geo)
    del d["joints"][3]["axis"]
    from mjstruct.io import mechanism_from_dict

    with pytest.raises(MechanismError, match=r"joints\[3\]\.axis: missing"):
        mechanism_to_pyslvs(mechanism_from_dict(d))


def test_odd_link_ids_get_pyslvs_names_and_come_back():
    m = Mechanism.build(
        [
            ("o", ["frame 0", "1"]),
            ("a", ["1", "ground"]),
            ("b", ["ground", "2x"]),
            ("c", ["2x", "frame 0"]),
        ],
        frame="frame 0",
    )
    m = Mechanism(
        links=m.links,
        joints=tuple(
            type(j)(j.id, j.links, j.kind, (float(k), float(k * k)))
            for k, j in enumerate(m.joints)
        ),
        frame=m.frame,
    )
    text = mechanism_to_pyslvs(m)
    names = {j.links for j in parse_pyslvs(text)}
    assert ("ground", "link_1") in names  # the frame is ground; a link called ground is not
    assert all(name.isidentifier() for pair in names for name in pair)
    assert mechanism_from_pyslvs(text) == m


def test_pyslvs_inputs_name_the_driven_link():
    m = read_mechanism(EXAMPLES / "four-bar.json")
    ((base, driven),) = pyslvs_inputs(m)
    vps = parse_pyslvs(mechanism_to_pyslvs(m))
    driver = m.joint(m.drivers[0])
    assert driver.links[:2] == ("0", "1")
    assert vps[base].links == ("ground", "link_1")
    assert "link_1" in vps[driven].links and driven != base
    slider = read_mechanism(EXAMPLES / "seed002-ex3-excavator.json")
    with pytest.raises(MechanismError, match=r"drivers: .* is prismatic"):
        pyslvs_inputs(slider)


def test_a_chain_without_frame_stays_without_frame():
    chain = Mechanism.build(
        [("a", ["ground", "x"]), ("b", ["x", "y"]), ("c", ["y", "z"]), ("d", ["z", "ground"])]
    )
    placed = Mechanism(
        links=chain.links,
        joints=tuple(
            type(j)(j.id, j.links, j.kind, (float(k), 1.0 - k)) for k, j in enumerate(chain.joints)
        ),
    )
    text = mechanism_to_pyslvs(placed)
    assert "L[ground" not in text  # a link called ground is not pyslvs's frame
    assert mechanism_from_pyslvs(text) == placed


@pytest.mark.parametrize("name", ["crank-rocker.pyslvs", "crank-rocker-compressed.pyslvs"])
def test_reads_pyslvs_projects_block_and_compressed(name):
    m = mechanism_from_pyslvs_project((PYSLVS_DATA / name).read_text())
    assert m.frame == "ground" and m.drivers == ("P0",)
    assert [j.id for j in m.joints] == ["P0", "P1", "P2", "P4"]
    assert m.points[0].at == (33.3, 66.95)
    assert canonical_code(m, "mechanism") == canonical_code(
        read_mechanism(EXAMPLES / "four-bar.json"), "mechanism"
    )


def test_project_round_trip_keeps_every_driver():
    for stem in ("four-bar", "kin-five-bar", "slider-crank", "zhivago-dynamics", "scotch-yoke"):
        m = read_mechanism(EXAMPLES / f"{stem}.json")
        text = mechanism_to_pyslvs_project(m)
        back = mechanism_from_pyslvs_project(text)
        assert back == m  # axes along x or y come back exact
        assert back.drivers == m.drivers and dict(back.extra) == dict(m.extra)
        _same_geometry(m, back, tol=0.0)


def test_bad_projects_name_the_key():
    with pytest.raises(MechanismError, match="mechanism: missing"):
        mechanism_from_pyslvs_project("input: [[0, 1]]\n")
    with pytest.raises(MechanismError, match=r"input: expected \[base, driven\]"):
        mechanism_from_pyslvs_project("mechanism: M[J[R, P[0, 0], L[a, b]]]\ninput: [0, 1]\n")
    with pytest.raises(MechanismError, match=r"input\[0\]: point 3 or 1 does not exist"):
        mechanism_from_pyslvs_project("mechanism: M[J[R, P[0, 0], L[a, b]]]\ninput: [[3, 1]]\n")
    with pytest.raises(MechanismError, match="not a YAML pyslvs project"):
        mechanism_from_pyslvs_project("mechanism: [unclosed\n")

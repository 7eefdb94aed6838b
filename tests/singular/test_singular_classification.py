"""The extended classification of singular positions of [Four-bar clearances] (types
I-V, traps A-E, useful П or harmful В): the paper's examples, the behaviour each class
claims checked by geometry written out here, the closed form against the traced
analysis, and the outputs that show it."""

from __future__ import annotations

import cmath
import json
import math

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.singular.analysis import SingularAnalysis, singular_analysis
from mjstruct.singular.classification import TYPES, fourbar_classes
from mjstruct.singular.clearance import formula3
from mjstruct.singular.curve import ClosureEquations

D = 0.01


def _analysis(name: str, clearance: float | None = D) -> SingularAnalysis:
    return singular_analysis(read_mechanism(example_path(name)), clearance=clearance)


def _notations(r: SingularAnalysis) -> dict[str, set[str]]:
    """Notation of each kind of position and fold arc."""
    out: dict[str, set[str]] = {}
    for p in r.singular:
        assert p.classification is not None
        out.setdefault(p.kind, set()).add(p.classification.notation)
    for a in r.fold_arcs:
        assert a.classification is not None
        out.setdefault(f"fold:{a.kind}", set()).add(a.classification.notation)
    return out


def test_the_papers_examples_carry_its_notations() -> None:
    # MS1 (parallelogram/antiparallelogram) and MS4 (doubled swing): II/B//П at the
    # change points; MS2 exact dwell III/C//П; MS5 alternating input IV/D//П
    assert _notations(_analysis("fourbar-ms1")) == {"change_point": {"II/B//П"}}
    ms4 = _notations(_analysis("fourbar-ms4"))
    assert ms4["change_point"] == {"II/B//П"} and ms4["output_extreme"] == {"II/B//В"}
    assert _notations(_analysis("fourbar-ms2"))["fold:output_extreme"] == {"III/C//П"}
    ms5 = _notations(_analysis("fourbar-ms5"))
    assert ms5["fold:input_limit"] == {"IV/D//П"}
    assert ms5["fold:output_extreme"] == {"III/C//П"}
    assert _notations(_analysis("fourbar-ms3"))["change_point"] == {"II/B//П"}
    # the rows the paper's examples leave out: a dead position of a triple-rocker, an
    # Assur point of a class-III triad
    assert _notations(_analysis("fourbar-triple-rocker"))["input_limit"] == {"I/A//В"}
    assert _notations(_analysis("triad-class-iii"))["input_limit"] == {"V/E//В"}


def test_json_keys_follow_the_table() -> None:
    d = _analysis("fourbar-ms2").to_dict()
    json.dumps(d, allow_nan=False)
    for item in [*d["singular"], *d["fold_arcs"]]:
        c = item["classification"]
        row = TYPES[c["type"]]
        assert (c["trap"], c["W1"], c["W2"]) == (row.trap, row.W1, row.W2)
        assert c["notation"] == f"{c['type']}/{c['trap']}//{'П' if c['use'] == 'useful' else 'В'}"
        assert c["reason"]
    p = d["singular"][0]
    assert p["classification"]["phi"] == [p["q"], p["q"]]
    a = d["fold_arcs"][0]
    assert a["classification"]["phi"] == [a["q_from"], a["q_to"]]
    # without a clearance there is no zone angle
    for p in _analysis("fourbar-ms2", None).to_dict()["singular"]:
        assert p["classification"]["theta"] is None


def test_theta_is_the_widest_zone_and_a_full_turn_on_a_fold_arc() -> None:
    r = _analysis("fourbar-ms4")
    for p in r.singular:
        assert p.zone and p.classification is not None
        assert p.classification.theta == max(z.psi for z in p.zone if z.psi is not None)
    # MS2's dwell: B on O1, the equal input and coupler folded with coinciding
    # pivots; formula (3) of the second kind at lambda = 1 is a full turn
    assert formula3(0.5, 0.5, D, stretched=False) == 2 * math.pi
    for a in _analysis("fourbar-ms2").fold_arcs:
        assert a.classification is not None and a.classification.theta == 2 * math.pi
    # the type-II zone of a plain output extreme is far below a turn (the table: << 2 pi)
    extremes = [p for p in r.singular if p.kind == "output_extreme"]
    assert all(p.classification and p.classification.theta < 0.2 for p in extremes)


def test_type_iii_input_turns_while_the_output_stands() -> None:
    # MS2 [0.5 0.5 1]: along its dwell arcs B sits on O1, so the loop closes with the
    # output fixed for every input angle of the arc (W1 = 1, W2 = 0), by geometry alone
    r = _analysis("fourbar-ms2")
    (arc, *_) = r.fold_arcs
    assert arc.classification is not None and arc.classification.type == "III"
    l1, l2, l3 = 0.5, 0.5, 1.0
    B = 0j  # on O1
    for q in np.linspace(arc.q_from, arc.q_to, 13):
        A = l1 * cmath.exp(1j * q)
        assert abs(abs(B - A) - l2) < 1e-15 and abs(abs(B - 1) - l3) < 1e-15
    assert arc.q_to - arc.q_from == pytest.approx(math.pi, abs=1e-9)


def test_type_iv_output_turns_while_the_input_stands() -> None:
    # MS5 [1 1 1]: A on O2 closes the loop with the input fixed for every output angle
    r = _analysis("fourbar-ms5")
    (arc,) = [a for a in r.fold_arcs if a.kind == "input_limit"]
    assert arc.classification is not None and arc.classification.type == "IV"
    A = cmath.exp(1j * arc.q_from)
    assert abs(A - 1) < 1e-12  # A on O2
    for theta in np.linspace(0, 2 * math.pi, 13):
        B = 1 + cmath.exp(1j * theta)
        assert abs(abs(B - A) - 1) < 1e-12


def _ms1_branches(q: float) -> tuple[complex, complex]:
    """B of MS1 [0.5 1 0.5] at input q on its two smooth branches, written out: the
    parallelogram (B = A + 1) and the antiparallelogram (that B reflected in the line
    A-O2, the other intersection of the circles about A and O2)."""
    A = 0.5 * cmath.exp(1j * q)
    par = A + 1
    u = (1 - A) / abs(1 - A)
    return par, A + ((par - A) / u).conjugate() * u


def test_type_ii_the_output_bifurcates_while_the_input_passes() -> None:
    # MS1 at its change point q = pi: both branches close on both sides (the input
    # passes, W1 = 1) and meet there with different output speeds (the output may leave
    # along either: two motions, W2 = 2)
    r = _analysis("fourbar-ms1")
    p = next(p for p in r.singular if abs(p.q - math.pi) < 1e-9)
    assert p.classification is not None and p.classification.type == "II"
    h = 1e-6
    for q in (math.pi - 0.01, math.pi + 0.01):
        A = 0.5 * cmath.exp(1j * q)
        for B in _ms1_branches(q):
            assert abs(abs(B - A) - 1) < 1e-12 and abs(abs(B - 1) - 0.5) < 1e-12
    par, anti = _ms1_branches(math.pi)
    assert abs(par - anti) < 1e-12
    assert abs(math.remainder(cmath.phase(par - 1) - p.output_angle, math.pi)) < 1e-9
    slopes = [
        math.remainder(cmath.phase(hi - 1) - cmath.phase(lo - 1), 2 * math.pi) / (2 * h)
        for lo, hi in zip(_ms1_branches(math.pi - h), _ms1_branches(math.pi + h), strict=True)
    ]
    # the parallelogram turns its output with the input, the antiparallelogram back
    assert slopes == pytest.approx([1.0, -1 / 3], abs=1e-6)


def test_type_i_the_input_stops_with_the_coupler_in_line_with_the_output() -> None:
    # triple-rocker [1.2 0.8 1.5]: at each input limit |A O2| = l2 + l3 or |l2 - l3|
    # (transmission angle 0 or 180 deg), and just beyond it the loop does not close
    r = _analysis("fourbar-triple-rocker")
    l1, l2, l3 = 1.2, 0.8, 1.5
    limits = [p for p in r.singular if p.kind == "input_limit"]
    assert len(limits) == 2
    for p in limits:
        assert p.classification is not None and p.classification.type == "I"
        reach = abs(l1 * cmath.exp(1j * p.q) - 1)
        assert min(abs(reach - (l2 + l3)), abs(reach - abs(l2 - l3))) < 1e-9
    lo, hi = r.input_range.intervals[0]
    for q in (lo - 1e-4, hi + 1e-4):
        reach = abs(l1 * cmath.exp(1j * q) - 1)
        assert not abs(l2 - l3) <= reach <= l2 + l3


def test_type_v_the_triads_legs_meet_in_one_point() -> None:
    # class-III triad (ternary link 2 on legs 3: A-B, 4: C-O2, 5: D-O3): at its input
    # limits no two moving links are in line, and the three legs' lines are concurrent
    m = read_mechanism(example_path("triad-class-iii"))
    r = singular_analysis(m, clearance=D)
    eq = ClosureEquations.build(m, m.drivers[0])
    limits = [p for p in r.singular if p.kind == "input_limit"]
    assert limits
    for p in limits:
        assert p.classification is not None and p.classification.type == "V"
        assert not p.pairs
        x = np.array(p.configuration)
        P = {j: eq.joint_position(x, j) for j in ("A", "B", "C", "D", "O2", "O3")}
        # the meeting point of lines A-B and O2-C, then its distance from line O3-D
        a, u = P["A"], P["B"] - P["A"]
        b, v = P["O2"], P["C"] - P["O2"]
        s = ((b - a).conjugate() * v).imag / ((u.conjugate() * v).imag)
        meet = a + s * u
        w = P["D"] - P["O3"]
        dist = abs(((meet - P["O3"]).conjugate() * w).imag) / abs(w)
        assert dist < 1e-7 * abs(meet - P["O3"]) + 1e-9
        assert p.classification.theta is not None and 0 < p.classification.theta < 1


def _random_fourbars(n: int) -> list[tuple[float, float, float]]:
    rng = np.random.default_rng(35)
    out: list[tuple[float, float, float]] = []
    while len(out) < n:
        P1, P2 = (float(v) for v in rng.uniform(0.3, 2.0, 2))
        pick = len(out) % 3
        # a third on a line of system (4) (change points), the rest anywhere
        P3 = float(rng.uniform(0.3, 2.0)) if pick else 1 + P2 - P1
        lengths = (1.0, P1, P2, P3)
        if P3 <= 0.2 or max(lengths) >= sum(lengths) - max(lengths) - 0.05:
            continue
        out.append((P1, P2, P3))
    return out


@pytest.mark.parametrize(
    "P",
    [
        (0.5, 1.0, 0.5),
        (0.5, 0.5, 1.0),
        (0.5, 1.5, 1.0),
        (0.5, 1.0, 1.5),
        (1.0, 1.0, 1.0),
        (1.2, 0.8, 1.5),
        *_random_fourbars(18),
    ],
)
def test_closed_form_classes_equal_the_traced_ones(P: tuple[float, float, float]) -> None:
    from mjstruct.design.fourbar_ms import fourbar_mechanism

    m = fourbar_mechanism(P, 1.0, None, 1, None, "four-bar")
    found = _notations(singular_analysis(m))
    traced = {n for ns in found.values() for n in ns}
    assert traced == set(fourbar_classes(*P))


def test_ms1_antiparallelogram_coupler_curve_is_booths_lemniscate() -> None:
    # The paper calls the curve of the coupler's midpoint on the antiparallelogram
    # branch a lemniscate of Bernoulli. Swept by the kinematics on the other assembly of
    # the shipped MS1 (B reflected in the line A-O2), about the frame's midpoint it
    # satisfies (x^2 + y^2)^2 = x^2/4 - 3y^2/4 exactly: Booth's lemniscate, whose
    # Bernoulli case would need the two coefficients opposite.
    from mjstruct.kinematics.model import KinematicModel

    d = json.loads(example_path("fourbar-ms1").read_text(encoding="utf-8"))
    at = {j["id"]: complex(*j["at"]) for j in d["joints"]}
    A, B, O2 = at["A"], at["B"], at["O2"]
    assert abs(B - A - 1) < 1e-12  # the shipped reference is the parallelogram
    u = (O2 - A) / abs(O2 - A)
    anti = A + ((B - A) / u).conjugate() * u
    for j in d["joints"]:
        if j["id"] == "B":
            j["at"] = [anti.real, anti.imag]
    # with the assembly mode fixed, each file runs a parallelogram for half a turn and
    # an antiparallelogram for the other (the modes swap at the change points)
    X, Y = [], []
    for m in (read_mechanism(example_path("fourbar-ms1")), mechanism_from_dict(d)):
        model = KinematicModel.build(m)
        for q in (np.linspace(0.05, math.pi - 0.05, 40), np.linspace(math.pi + 0.05, 6.23, 40)):
            mo = model.motion(q, order=0)
            assert mo.valid.all()
            zA, zB = mo.centre("A")[0], mo.centre("B")[0]
            mid = (zA + zB) / 2 - 0.5
            if np.abs(zB - zA - 1).max() < 1e-9:  # parallelogram: a circle of radius 1/2
                assert np.abs(np.abs(mid) - 0.5).max() < 1e-12
            else:
                X.append(mid.real)
                Y.append(mid.imag)
    assert len(X) == 2  # one antiparallelogram half of each
    x, y = np.concatenate(X), np.concatenate(Y)
    G = np.c_[x**2, y**2]
    rhs = (x**2 + y**2) ** 2
    c, *_ = np.linalg.lstsq(G, rhs, rcond=None)
    assert np.abs(G @ c - rhs).max() < 1e-12
    assert c == pytest.approx([0.25, -0.75], abs=1e-12)
    # the best Bernoulli form a (x^2 - y^2) misses by about a tenth of the curve's (x^2 + y^2)^2
    g = x**2 - y**2
    a = float(g @ rhs / (g @ g))
    assert np.abs(a * g - rhs).max() > 0.05 * rhs.max()


def test_the_cli_shows_the_classes(capsys: pytest.CaptureFixture[str]) -> None:
    path = str(example_path("fourbar-ms2"))
    assert main(["singular", path, "--clearance", "0.01"]) == 0
    out = capsys.readouterr().out
    assert "II/B//П" in out and "II/B//В" in out
    assert "O1 B coinciding: III/C//П, zone 360.0000 deg" in out
    assert "III/C: closed chain degenerates into an open one" in out
    assert main(["singular", path, "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["fold_arcs"][0]["classification"]["notation"] == "III/C//П"


def test_the_fourbar_ms_report_and_the_explorer_show_the_classes(
    tmp_path: object, capsys: pytest.CaptureFixture[str]
) -> None:
    from pathlib import Path

    from mjstruct.design.fourbar_ms import synthesize_fourbar_ms

    r = synthesize_fourbar_ms({"task": "fourbar-ms", "ms": "MS5"})
    assert r.details["classes"] == ["II/B//П", "III/C//П", "IV/D//П"]
    arcs = r.details["singular"]["fold_arcs"]
    assert {a["classification"]["notation"] for a in arcs} == {"III/C//П", "IV/D//П"}
    task = Path(str(tmp_path)) / "ms2.json"
    task.write_text('{"task": "fourbar-ms", "ms": "MS2"}', encoding="utf-8")
    assert main(["synthesize", str(task), "-o", str(Path(str(tmp_path)) / "out.json")]) == 0
    out = capsys.readouterr().out
    # the built four-bar's singular report, as `singular` prints it, classes included
    assert (
        "fold arc: output dwells at 0.0000 deg for q from 0.0000 to 180.0000 deg, "
        "O1 B coinciding: III/C//П" in out
    )

    from mjstruct.plot.explorer_view import ExplorerView

    view = ExplorerView(read_mechanism(example_path("fourbar-ms2")), ["O2"], dpi=40)
    summary = "\n".join(view.summary())
    assert "change point at 180.0° (II/B//П)" in summary
    assert "fold arc: output dwells from" in summary and "(III/C//П)" in summary

"""Singular positions: the MS1-MS5 reference four-bars, random four-bars against the
closed form and against dense sweeps of the kinematic model, a six-bar, invariance, and
the CLI's contract."""

from __future__ import annotations

import cmath
import json
import math

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main
from mjstruct.errors import MechanismError
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.singular.analysis import classify_singular_frames, singular_analysis
from mjstruct.singular.fourbar import fourbar_singular_angles

TWO_PI = 2 * math.pi


def _ms(n: int):
    return singular_analysis(read_mechanism(example_path(f"fourbar-ms{n}")))


def _mod(a: float, b: float) -> float:
    """|a - b| on the circle."""
    return abs(math.remainder(a - b, TWO_PI))


def _kinds(r, kind):
    return [p for p in r.singular if p.kind == kind]


# ---------------------------------------------------------------- MS1 ... MS5


def test_ms4_swings_141_degrees_through_its_change_point():
    r = _ms(4)
    ext = _kinds(r, "output_extreme")
    (cp,) = _kinds(r, "change_point")
    # the two extremes lie on the two circuits that meet at the change point
    swing = max(p.output_angle for p in ext) - min(p.output_angle for p in ext)
    assert swing == pytest.approx(2 * math.acos(1 / 3), abs=1e-9)
    assert math.degrees(swing) == pytest.approx(141.06, abs=0.005)
    assert r.fourbar.swing == pytest.approx(swing, abs=1e-9)
    assert _mod(cp.q, 0.0) < 1e-9 and cp.collinear == ("O1", "A", "B", "O2")
    assert r.fourbar.system4 == (2,) and r.fourbar.motion == "crank-rocker"


def test_ms2_dwells_half_a_turn_and_swings_60_degrees_per_side():
    r = _ms(2)
    cps = _kinds(r, "change_point")
    assert sorted(round(_mod(p.q, 0.0), 9) for p in cps) == [0.0, round(math.pi, 9)]
    # the dwell branch (B on O1) meets the moving one at q = 0 and pi: half a turn
    (w,) = [w for w in r.warnings if w.startswith("fold arc")]
    assert "output dwells" in w and "B sits on O1" in w
    dwell = cps[0].output_angle
    for p in _kinds(r, "output_extreme"):
        assert _mod(p.output_angle, dwell) == pytest.approx(math.pi / 3, abs=1e-9)
    assert r.fourbar.system4 == (1, 2)
    assert r.fourbar.swing == pytest.approx(2 * math.pi / 3, abs=1e-9)


def test_ms3_swings_120_per_side_and_has_time_ratio_2():
    r = _ms(3)
    (cp,) = _kinds(r, "change_point")
    ext = _kinds(r, "output_extreme")
    for p in ext:
        assert _mod(p.output_angle, cp.output_angle) == pytest.approx(2 * math.pi / 3, abs=1e-9)
    # strokes: from the change point (an extreme of both circuits) to the other extreme
    strokes = sorted(_mod(p.q, cp.q) for p in ext)
    assert strokes[0] == pytest.approx(2 * math.pi / 3, abs=1e-9)
    assert (TWO_PI - strokes[0]) / strokes[0] == pytest.approx(2.0, abs=1e-9)
    assert r.fourbar.time_ratio == pytest.approx(2.0)
    assert r.fourbar.swing == pytest.approx(4 * math.pi / 3, abs=1e-9)


def test_ms1_switches_at_180_and_360_degrees():
    r = _ms(1)
    assert [p.kind for p in r.singular] == ["change_point", "change_point"]
    assert sorted(round(_mod(p.q, 0.0), 9) for p in r.singular) == [0.0, round(math.pi, 9)]
    assert r.branches == 2 and r.fourbar.motion == "double-crank" and r.fourbar.swing is None
    assert r.input_range.full_turn


def test_ms5_hinged_square_has_three_branches_and_two_fold_arcs():
    r = _ms(5)
    assert r.branches == 3
    assert [p.kind for p in r.singular] == ["change_point"] * 3
    folds = [w for w in r.warnings if w.startswith("fold arc")]
    assert len(folds) == 2
    assert any("input stays" in w and "O2 sits on A" in w for w in folds)
    assert any("output dwells" in w and "B sits on O1" in w for w in folds)
    assert r.fourbar.system4 == (1, 2, 3)


def test_change_points_located_to_1e_9():
    for n in (1, 2, 4):
        for p in _kinds(_ms(n), "change_point"):
            assert min(_mod(p.q, 0.0), _mod(p.q, math.pi)) < 1e-9


# ---------------------------------------------------------------- random four-bars


def fourbar_file(P, phi=1.0, upper=True, rot=0.0, shift=0j, scale=1.0):
    """A four-bar [P1 P2 P3] (frame 1) at input angle phi, optionally moved."""
    p1, p2, p3 = P
    A = p1 * cmath.exp(1j * phi)
    d = abs(1 - A)
    c = (p2 * p2 + d * d - p3 * p3) / (2 * p2 * d)
    assert -1 < c < 1, "reference does not assemble"
    B = A + p2 * (1 - A) / d * cmath.exp((1 if upper else -1) * 1j * math.acos(c))

    def at(z):
        w = (z * cmath.exp(1j * rot) + shift) * scale
        return [w.real, w.imag]

    return mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["O1"],
            "joints": [
                {"id": "O1", "links": ["0", "1"], "at": at(0j)},
                {"id": "A", "links": ["1", "2"], "at": at(A)},
                {"id": "B", "links": ["2", "3"], "at": at(B)},
                {"id": "O2", "links": ["3", "0"], "at": at(1 + 0j)},
            ],
        }
    )


def _motion_by_grashof(P):
    """The motion by the Grashof inequality and which link is shortest, written out:
    non-Grashof (s + l > p + q) is a triple-rocker; otherwise the shortest link turns
    fully relative to both neighbours, so a shortest frame gives a double-crank, a
    shortest input a crank-rocker, a shortest output a rocker-crank and a shortest
    coupler a double-rocker."""
    lengths = {"frame": 1.0, "input": P[0], "coupler": P[1], "output": P[2]}
    v = sorted(lengths.values())
    if v[0] + v[3] > v[1] + v[2]:
        return "triple-rocker"
    shortest = min(lengths, key=lengths.get)
    return {
        "frame": "double-crank",
        "input": "crank-rocker",
        "output": "rocker-crank",
        "coupler": "double-rocker",
    }[shortest]


def _sample(rng, motion, gap):
    """Lengths of a random four-bar with the given motion whose distance from the
    change-point condition (|s + l - p - q|) lies in ``gap``, and an assembling phi."""
    while True:
        P = rng.uniform(0.2, 2.5, size=3)
        lengths = sorted([1.0, *P])
        if not gap[0] <= abs(lengths[0] + lengths[3] - lengths[1] - lengths[2]) < gap[1]:
            continue
        if lengths[1] - lengths[0] < 0.02 or lengths[3] >= sum(lengths[:3]) - 0.02:
            continue  # a tie of the shortest links, or a loop that barely closes
        if _motion_by_grashof(P) != motion:
            continue
        for phi in rng.uniform(0, TWO_PI, size=20):
            d = abs(1 - P[0] * cmath.exp(1j * phi))
            if abs(P[1] - P[2]) + 0.02 < d < P[1] + P[2] - 0.02:
                return P, float(phi)


MOTIONS = ["crank-rocker", "double-crank", "double-rocker", "triple-rocker", "rocker-crank"]


@pytest.mark.parametrize("motion", MOTIONS)
@pytest.mark.parametrize("gap", [(0.05, 10.0), (2e-3, 2e-2)], ids=["generic", "near-change"])
def test_random_fourbars_agree_with_closed_form_and_dense_sweep(motion, gap):
    rng = np.random.default_rng(MOTIONS.index(motion) + (11 if gap[0] > 0.01 else 57))
    for _ in range(2):
        P, phi = _sample(rng, motion, gap)
        m = fourbar_file(P, phi)
        r = singular_analysis(m)
        assert r.fourbar.motion == motion
        assert r.fourbar.grashof == (motion != "triple-rocker")
        closed = fourbar_singular_angles(*P)
        lim = _kinds(r, "input_limit")
        ext = _kinds(r, "output_extreme")
        assert not _kinds(r, "change_point")
        # the model's angles: q = phi; the output link points from B to O2 (theta + pi)
        for p in lim:
            assert min(_mod(p.q, a) for a in closed.input_limits) < 1e-9
            assert p.collinear == ("A", "B", "O2")
        for p in ext:
            assert min(_mod(p.output_angle, t + math.pi) for t in closed.output_extremes) < 1e-9
            assert p.collinear == ("O1", "A", "B")
        one_circuit = motion == "triple-rocker"
        n_lim, n_ext = len(closed.input_limits), len(closed.output_extremes)
        assert len(lim) == (n_lim if one_circuit else n_lim // 2)
        assert len(ext) == (n_ext if one_circuit else n_ext // 2)
        assert r.input_range.full_turn == (motion in ("crank-rocker", "double-crank"))
        _check_both_ways(P, phi, r, frames=4000 if gap[0] > 0.01 else 12000)


def _circuit_sign(P, mo):
    """Sign of a joint angle that never passes 0 or pi on a circuit of a Grashof
    four-bar: at a joint of the link opposite the shortest one, not shared with the
    shortest (links 0 frame, 1 input, 2 coupler, 3 output around the loop)."""
    s = int(np.argmin([1.0, *P]))
    c = (s + 2) % 4
    a = (c + 1) % 4 if (c + 1) % 4 != s else (c + 3) % 4
    return np.sign(np.sin(mo.angle(str(a))[0] - mo.angle(str(c))[0]))


def _check_both_ways(P, phi, r, frames):
    """Every listed output extreme is a sign flip of the model's output analog in a
    dense sweep, and every flip on the traced curve is listed (same q to two grid
    steps, same output angle).  Both assembly modes are swept; on a Grashof four-bar
    the traced curve is the reference's circuit, told by :func:`_circuit_sign`."""
    q = phi + np.linspace(0.0, TWO_PI, frames)
    step = float(q[1] - q[0])
    ref = _circuit_sign(P, KinematicModel.build(fourbar_file(P, phi)).motion([phi], 0))[0]
    flips = []  # (q, output angle, on the traced curve)
    for upper in (True, False):
        mo = KinematicModel.build(fourbar_file(P, phi, upper=upper)).motion(q, order=1)
        out, sig = mo.angle(r.output)[:2]
        ok = mo.valid
        circ = _circuit_sign(P, mo)
        for i in np.nonzero(ok[:-1] & ok[1:] & (sig[:-1] * sig[1:] < 0))[0]:
            on = r.fourbar.motion == "triple-rocker" or circ[i] == ref
            flips.append((0.5 * (q[i] + q[i + 1]), out[i], on))
    ext = _kinds(r, "output_extreme")
    # not vacuous: a rocking output has extremes, and on a Grashof four-bar the other
    # circuit's flips are seen and left out
    rocks = r.fourbar.motion in ("crank-rocker", "double-rocker", "triple-rocker")
    assert bool(ext) == rocks and bool([f for f in flips if f[2]]) == rocks
    assert bool([f for f in flips if not f[2]]) == (rocks and r.fourbar.grashof)
    for p in ext:  # listed -> seen
        assert any(_mod(f, p.q) < 2 * step and _mod(o, p.output_angle) < 1e-3 for f, o, _ in flips)
    for f, o, on in flips:  # seen on the traced curve -> listed, and only there
        listed = any(_mod(f, p.q) < 2 * step and _mod(o, p.output_angle) < 1e-3 for p in ext)
        assert listed == on


# ---------------------------------------------------------------- six-bar


def stephenson_six_bar():
    pts = {"O1": (0, 0), "A": (0.15, 0.26), "B": (0.83, 0.68), "O2": (1, 0)}
    pts |= {"C": (0.4, 0.9), "D": (1.25, 1.35), "O3": (1.7, 0.6)}
    links = {
        "O1": ["0", "1"],
        "A": ["1", "2"],
        "B": ["2", "3"],
        "O2": ["3", "0"],
        "C": ["2", "4"],
        "D": ["4", "5"],
        "O3": ["5", "0"],
    }
    return mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["O1"],
            "joints": [{"id": j, "links": links[j], "at": list(pts[j])} for j in pts],
        }
    )


def test_six_bar_against_dense_sweep():
    m = stephenson_six_bar()
    r = singular_analysis(m)
    assert r.output == "5"
    ext = _kinds(r, "output_extreme")
    assert ext, "the output rocker must have extremes"
    # one smooth branch over a full turn with no input limit: the model's sweep of the
    # reference's assembly modes covers the whole traced curve, so the comparison
    # holds both ways
    assert r.branches == 1 and r.input_range.full_turn and not _kinds(r, "input_limit")
    model = KinematicModel.build(m)
    q = model.sweep(4000)[:, 0]
    step = float(q[1] - q[0])
    mo = model.motion(q, order=1)
    assert mo.valid.all()
    out, sig = mo.angle("5")[:2]
    flips = [(0.5 * (q[i] + q[i + 1]), out[i]) for i in np.nonzero(sig[:-1] * sig[1:] < 0)[0]]
    assert len(flips) == len(ext)
    for p in ext:  # listed -> seen, with the same output angle
        assert any(_mod(f, p.q) < 2 * step and _mod(o, p.output_angle) < 1e-4 for f, o in flips)
    for f, o in flips:  # seen -> listed
        assert any(_mod(f, p.q) < 2 * step and _mod(o, p.output_angle) < 1e-4 for p in ext)
    # at each located extreme the model's output angle is the listed one, and its
    # analog vanishes there (to the closure's accuracy)
    at = model.motion([p.q for p in ext], order=1)
    for k, p in enumerate(ext):
        assert _mod(at.angle("5")[0][k], p.output_angle) < 1e-9
        assert abs(at.angle("5")[1][k]) < 1e-8


# ---------------------------------------------------------------- invariance


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_invariant_under_translation_rotation_scale(scale):
    P, phi = (0.5, 1.0, 1.5), 1.0
    base = singular_analysis(fourbar_file(P, phi), clearance=0.01)
    rot = 0.7
    moved = singular_analysis(
        fourbar_file(P, phi, rot=rot, shift=3 - 2j, scale=scale), clearance=0.01 * scale
    )
    assert [p.kind for p in moved.singular] == [p.kind for p in base.singular]
    for a, b in zip(base.singular, moved.singular, strict=True):
        # the frame is the x axis of every angle: q and link angles turn with the file
        assert _mod(b.q, a.q + rot) < 1e-9
        assert _mod(b.output_angle, a.output_angle + rot) < 1e-9
        for za, zb in zip(a.zone, b.zone, strict=True):
            assert zb.psi == pytest.approx(za.psi, abs=1e-12)


# ---------------------------------------------------------------- zones


def _brute_force_half_angle(long, r, pins, stretched, samples, rng):
    """Largest turn of link long (about its pivot) over random pin offsets on the
    clearance circles, with the chain closed exactly (circle intersection)."""
    d = long + r if stretched else long - r
    best = 0.0
    for _ in range(samples):
        e = [c * cmath.exp(1j * rng.uniform(0, TWO_PI)) for c in pins]
        # pivot of long at e0, long's far end + e1 must lie at distance r from (d + e2)
        centre = d + e[2] - e[0] - e[1]
        # |long e^{ia} - centre| = r: cos(a - arg centre) = (long^2 + |c|^2 - r^2) / (2 long |c|)
        c = (long * long + abs(centre) ** 2 - r * r) / (2 * long * abs(centre))
        if -1 <= c <= 1:
            best = max(best, abs(cmath.phase(centre)) + math.acos(c))
    return best


@pytest.mark.parametrize(
    ("lam", "delta", "stretched"),
    [(0.5, 0.01, True), (0.5, 0.01, False), (0.8, 0.02, True), (0.3, 0.005, False)],
)
def test_formula3_against_pin_in_hole_brute_force(lam, delta, stretched):
    from mjstruct.singular.clearance import formula3

    rng = np.random.default_rng(3)
    pins = [delta / 3] * 3
    psi = formula3(1.0, lam, delta, stretched)
    brute = 2 * _brute_force_half_angle(1.0, lam, pins, stretched, 20000, rng)
    assert brute <= psi + 1e-12
    assert brute == pytest.approx(psi, rel=1e-2)
    # the offsets all along the chain's line reach it exactly
    aligned = 2 * _brute_force_aligned(1.0, lam, delta, stretched)
    assert aligned == pytest.approx(psi, abs=1e-12)


def _brute_force_aligned(long, r, delta, stretched):
    d = long + r if stretched else long - r
    best = 0.0
    for a in np.linspace(0, math.pi, 20001):
        if abs(abs(long * cmath.exp(1j * a) - d) - r) <= delta:
            best = a
        elif best > 0:
            break
    lo, hi = best, best + math.pi / 20000
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if abs(abs(long * cmath.exp(1j * mid) - d) - r) <= delta:
            lo = mid
        else:
            hi = mid
    return lo


def test_seed_example_values_of_formula3():
    from mjstruct.singular.clearance import formula3

    assert math.degrees(formula3(1, 0.5, 0.01, True)) == pytest.approx(9.41, abs=0.005)
    assert math.degrees(formula3(1, 0.5, 0.01, False)) == pytest.approx(16.30, abs=0.005)
    assert formula3(1, 1, 0.001, False) == pytest.approx(TWO_PI)
    assert formula3(1, 0.5, 0.0, True) == 0.0


def test_leading_order_zone_on_six_bar_matches_exact_to_its_order():
    r = singular_analysis(stephenson_six_bar(), clearance=1e-4, exact=True)
    for p in r.singular:
        for z in p.zone:
            assert z.method == "leading-order"
            # leading order: relative error of the order of sqrt(clearance / size)
            assert z.psi == pytest.approx(z.psi_exact, rel=1e-3)


# ---------------------------------------------------------------- API and CLI


def test_classify_singular_frames():
    r = _ms(4)
    names = classify_singular_frames(r, [0.0, 1e-8, 0.3, r.singular[0].q + TWO_PI], 1e-6)
    assert names == ["change_point", "change_point", None, "output_extreme"]


def test_cli_json_contract(capsys):
    assert (
        main(["singular", str(example_path("fourbar-ms4")), "--clearance", "0.01", "--json"]) == 0
    )
    d = json.loads(capsys.readouterr().out)
    assert {"input", "output", "singular", "input_range", "fourbar", "warnings"} <= set(d)
    assert d["input"] == "O1" and d["output"] == "3"
    assert set(d["fourbar"]) >= {"MS", "grashof", "motion", "system4", "swing"}
    for p in d["singular"]:
        assert set(p) >= {"kind", "q", "output_angle", "collinear", "zone"}
        for z in p["zone"]:
            assert set(z) >= {"pair", "link", "psi"}
    qs = [p["q"] for p in d["singular"]]
    assert qs == sorted(qs)


def test_cli_text_report(capsys):
    assert main(["singular", str(example_path("fourbar-ms2"))]) == 0
    out = capsys.readouterr().out
    assert "crank-rocker" in out and "fold arc" in out and "change_point" in out


def _locked(tmp_path):
    path = tmp_path / "locked.json"
    path.write_text(
        json.dumps(
            {
                "frame": "0",
                "drivers": ["O1"],
                "joints": [
                    {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
                    {"id": "A", "links": ["1", "2"], "at": [1, 0]},
                    {"id": "B", "links": ["2", "3"], "at": [2, 0]},
                    {"id": "O2", "links": ["3", "0"], "at": [-1, 0]},
                ],
            }
        )
    )
    return str(path)


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["{kin-five-bar}"], "F = 2"),
        (["{fourbar-ms4}", "--clearance", "-0.1"], "--clearance"),
        (["{fourbar-ms4}", "--output", "9"], "--output"),
        (["{locked}"], "cannot move"),
    ],
)
def test_bad_input_exits_2_with_one_line(argv, needle, capsys, tmp_path):
    args = [
        _locked(tmp_path) if a == "{locked}" else str(example_path(a[1:-1])) if a[0] == "{" else a
        for a in argv
    ]
    assert main(["singular", *args]) == 2
    err = capsys.readouterr().err
    assert needle in err and err.count("\n") == 1


def test_library_raises_with_parameter_names():
    m = read_mechanism(example_path("fourbar-ms4"))
    with pytest.raises(MechanismError, match=r"^clearance:"):
        singular_analysis(m, clearance=-1)
    with pytest.raises(MechanismError, match=r"^output:"):
        singular_analysis(m, output="nope")


def test_zone_drawing_has_one_wedge_per_zone():
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.patches import Wedge

    from mjstruct.plot.ms_diagram import ms_point, plot_ms_diagram, plot_singular_zones

    m = read_mechanism(example_path("fourbar-ms4"))
    r = singular_analysis(m, clearance=0.02)
    fig = plot_singular_zones(m, r)
    # one axes, or one panel per position: the wedges of all of them, in order
    wedges = [p for ax in fig.axes for p in ax.patches if isinstance(p, Wedge)]
    assert len(wedges) == sum(len(p.zone) for p in r.singular)
    for w, z in zip(wedges, [z for p in r.singular for z in p.zone], strict=True):
        assert w.theta2 - w.theta1 == pytest.approx(math.degrees(z.psi))
    P = ms_point(m)
    assert list(P) == pytest.approx([0.5, 1.0, 1.5])
    fig2 = plot_ms_diagram(P[0], point=P[1:])
    assert len(fig2.axes[0].lines) >= 3 + 4 + 1  # system (4), M1-M4, the mechanism

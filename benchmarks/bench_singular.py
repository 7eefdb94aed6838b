"""Speed and accuracy of the singular-position analysis, measured side by side in one run.

* Time (CPU, medians of runs in rotation): ``singular_analysis`` (tracing every branch
  through change points in blocks of stations corrected together, Brent refinement)
  against a dense sweep of the kinematic model (3600 frames, sign changes of the
  output's velocity analog) on the four-bar MS4 (goal: within 10x) and a Stephenson
  six-bar; the error of each in q against the closed form (four-bar).
* Accuracy of the leading-order zone ``2 sqrt(2E/|c|)`` against formula (3) (exact for
  a four-bar's pin-in-hole chain) over the MS matrices and clearances 1e-4 .. 1e-1.

Run: ``python benchmarks/bench_singular.py [--repeat N]``; prints medians, ratios and
the error table (the table in docs/singular.md comes from this script).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.model import KinematicModel
from mjstruct.singular.analysis import singular_analysis
from mjstruct.singular.clearance import formula3, leading_order_zone
from mjstruct.singular.curve import ClosureEquations
from mjstruct.singular.fourbar import REFERENCE_MATRICES, fourbar_singular_angles
from timing import race

FRAMES = 3600


def six_bar():
    pts = {"O1": (0, 0), "A": (0.15, 0.26), "B": (0.83, 0.68), "O2": (1, 0)}
    pts |= {"C": (0.4, 0.9), "D": (1.25, 1.35), "O3": (1.7, 0.6)}
    links = {"O1": ["0", "1"], "A": ["1", "2"], "B": ["2", "3"], "O2": ["3", "0"]}
    links |= {"C": ["2", "4"], "D": ["4", "5"], "O3": ["5", "0"]}
    joints = [{"id": j, "links": links[j], "at": list(pts[j])} for j in pts]
    return mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints})


def dense_sweep(m, output):
    """Output extremes as the midpoints of sign changes of sigma on a frame grid."""
    model = KinematicModel.build(m)
    q = model.sweep(FRAMES)[:, 0]
    mo = model.motion(q, order=1)
    s = mo.angle(output)[1]
    i = np.nonzero((s[:-1] * s[1:] < 0) & mo.valid[:-1] & mo.valid[1:])[0]
    return 0.5 * (q[i] + q[i + 1])


#: the goal: singular_analysis on MS4 within this factor of the dense sweep
GOAL = 10.0


def timing(repeat: int) -> None:
    print(
        f"CPU time (median of {repeat}), dense sweep = {FRAMES} frames of the kinematic model; "
        f"goal: MS4 ratio <= {GOAL:g}"
    )
    for name, m in (
        ("MS4 four-bar", read_mechanism(example_path("fourbar-ms4"))),
        ("six-bar", six_bar()),
    ):
        out = singular_analysis(m).output
        t_trace, t_sweep = race(
            [lambda m=m: singular_analysis(m), lambda m=m, o=out: dense_sweep(m, o)],
            repeat,
            clock=time.process_time,
        )
        verdict = ""
        if name.startswith("MS4"):
            verdict = "  (goal met)" if t_trace / t_sweep <= GOAL else "  (goal MISSED)"
        print(
            f"  {name:<14} singular_analysis {t_trace * 1e3:8.1f} ms   "
            f"dense sweep {t_sweep * 1e3:8.1f} ms   ratio {t_trace / t_sweep:5.2f}{verdict}"
        )
    m = read_mechanism(example_path("fourbar-ms4"))
    r = singular_analysis(m)
    closed = fourbar_singular_angles(0.5, 1.0, 1.5)
    # q of an output extreme (input along the coupler): arg of B at the extreme
    q_true = []
    for t in closed.output_extremes:
        b = 1 + 1.5 * complex(math.cos(t), math.sin(t))
        q_true.append(math.atan2(b.imag, b.real) % (2 * math.pi))
    err_trace = max(
        min(abs(math.remainder(p.q - t, 2 * math.pi)) for t in q_true)
        for p in r.singular
        if p.kind == "output_extreme"
    )
    flips = dense_sweep(m, r.output)
    # the swept circuit reverses its output at the change point (q = 0) too
    seen = [*q_true, 0.0]
    err_sweep = max(min(abs(math.remainder(f - t, 2 * math.pi)) for t in seen) for f in flips)
    print(
        f"  MS4 output extremes, error in q: refined {err_trace:.1e} rad, "
        f"dense sweep {err_sweep:.1e} rad"
    )


def zone_table() -> None:
    print("leading-order zone vs formula (3): relative error of psi")
    clearances = (1e-4, 1e-3, 1e-2, 1e-1)
    print(
        "  "
        + f"{'four-bar':<32}{'position':<26}"
        + "".join(f"{'D = ' + format(d, 'g'):>16}" for d in clearances)
    )
    cases = dict(REFERENCE_MATRICES)
    cases |= {"crank-rocker": (0.3, 1.1, 0.9), "triple-rocker": (1.2, 0.8, 1.5)}
    rows_seen: set[str] = set()
    for name, (p1, p2, p3) in cases.items():
        P = (p1, p2, p3)
        A = p1 * complex(math.cos(1.0), math.sin(1.0))
        d = abs(1 - A)
        c = (p2 * p2 + d * d - p3 * p3) / (2 * p2 * d)
        if not -1 < c < 1:
            continue
        B = A + p2 * (1 - A) / d * complex(math.cos(math.acos(c)), math.sin(math.acos(c)))
        joints = [
            {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
            {"id": "A", "links": ["1", "2"], "at": [A.real, A.imag]},
            {"id": "B", "links": ["2", "3"], "at": [B.real, B.imag]},
            {"id": "O2", "links": ["3", "0"], "at": [1, 0]},
        ]
        m = mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints})
        r = singular_analysis(m)
        eq = ClosureEquations.build(m, "O1")
        for p in r.singular:
            if p.kind == "change_point":
                continue
            x = np.array(p.configuration)
            a, b = p.pairs[0]  # the moving links in line, and the joints of each
            jid, ja, jb = _in_line(m, a, b)
            cen = eq.geometry.centres
            la, lb = abs(cen[ja] - cen[jid]), abs(cen[jb] - cen[jid])
            longer = a if la >= lb else b
            u = eq.joint_position(x, ja) - eq.joint_position(x, jid)
            v = eq.joint_position(x, jb) - eq.joint_position(x, jid)
            stretched = (u.conjugate() * v).real < 0
            fixed = "output" if p.kind == "output_extreme" else "input"
            row = []
            for D in clearances:
                exact = formula3(max(la, lb), min(la, lb), D, stretched)
                pins = {j.id: D / 4 for j in m.joints}
                lo = leading_order_zone(eq, x, fixed, longer, pins)
                row.append(f"{(lo - exact) / exact:+16.2e}")
            kind = "stretched" if stretched else "folded"
            line = f"  {name + ' ' + str(list(P)):<32}{p.kind + ', ' + kind:<26}" + "".join(row)
            if line not in rows_seen:  # mirror positions repeat the same numbers
                rows_seen.add(line)
                print(line)


def _in_line(m, a, b):
    """The joint of links a and b, and the other joint of each (links of a four-bar have
    two joints): the three joint centres in line at a singular position."""
    jid = next(j.id for j in m.joints if {a, b} <= set(j.links))
    ja = next(j for j in m.link_joints[a] if j != jid)
    jb = next(j for j in m.link_joints[b] if j != jid)
    return jid, ja, jb


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    timing(args.repeat)
    zone_table()


if __name__ == "__main__":
    main()

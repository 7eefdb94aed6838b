"""Partial assembly: where only a later group fails, the groups that assemble keep their values.

A Grashof crank-rocker (crank O1 A, coupler A B, rocker B O2) turns fully; a dyad C F O3
hung on the crank's third joint C assembles only on part of the turn.  On the frames
where that dyad does not, the four-bar's joints and links are given (JSON, CSV and the
Python result) at their closed-form positions and rates, and only the dyad's are null.
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.kinematics.report import write_csv
from mjstruct.kinematics.solver import kinematic_analysis

CRANK, COUPLER, ROCKER, O2 = 0.3, 1.0, 0.8, 1.0
C0, O3, CF, FO3 = 0.5j, complex(-0.9, 0.3), 0.6, 0.5


def _meet(P: complex, Q: complex, rp: float, rq: float, side: int) -> complex:
    """The point at ``rp`` from P and ``rq`` from Q, left (+1) or right (-1) of P→Q."""
    d = abs(Q - P)
    a = (d * d + rp * rp - rq * rq) / (2 * d)
    return P + (a + 1j * side * math.sqrt(rp * rp - a * a)) * (Q - P) / d


def _mechanism():
    A, C = complex(CRANK, 0), C0
    B = _meet(A, O2, COUPLER, ROCKER, 1)
    F = _meet(C, O3, CF, FO3, 1)

    def at(z: complex) -> list[float]:
        return [z.real, z.imag]

    return mechanism_from_dict(
        {
            "frame": "0",
            "drivers": ["O1"],
            "joints": [
                {"id": "O1", "links": ["0", "1"], "at": [0.0, 0.0]},
                {"id": "A", "links": ["1", "2"], "at": at(A)},
                {"id": "B", "links": ["2", "3"], "at": at(B)},
                {"id": "O2", "links": ["3", "0"], "at": [O2, 0.0]},
                {"id": "C", "links": ["1", "4"], "at": at(C)},
                {"id": "F", "links": ["4", "5"], "at": at(F)},
                {"id": "O3", "links": ["5", "0"], "at": at(O3)},
            ],
        }
    )


def test_a_later_dyad_that_fails_leaves_the_four_bar_given():
    r = kinematic_analysis(_mechanism(), frames=72, speed=2.0)
    q = r.q[:, 0]
    # the dyad reaches |C - O3| <= CF + FO3 only: an independent count of its frames
    reach = np.abs(C0 * np.exp(1j * q) - O3) <= CF + FO3
    assert reach.any() and not reach.all()
    assert np.array_equal(r.placed, reach)
    part = ~reach
    assert r.partial is not None and np.array_equal(r.partial, part)
    d = r.to_dict()
    # closed form of the four-bar on the frames where the dyad fails
    A = CRANK * np.exp(1j * q)
    B = np.array([_meet(a, O2, COUPLER, ROCKER, 1) for a in A])
    for name, z in (("A", A), ("B", B), ("C", C0 * np.exp(1j * q))):
        x = np.array(d["joints"][name]["x"], dtype=float)
        y = np.array(d["joints"][name]["y"], dtype=float)
        assert np.abs(x + 1j * y - z).max() < 1e-12, name
        assert np.abs(r.joints[name]["x"] + 1j * r.joints[name]["y"] - z).max() < 1e-12
    # velocities too: A turns at W = 2 on radius CRANK; B's from central differences
    vA = np.array(d["joints"]["A"]["vx"], dtype=float) + 1j * np.array(d["joints"]["A"]["vy"])
    assert np.abs(vA - 2j * A).max() < 1e-12
    h = 1e-6
    Bp = np.array([_meet(CRANK * np.exp(1j * (x + h)), O2, COUPLER, ROCKER, 1) for x in q])
    Bm = np.array([_meet(CRANK * np.exp(1j * (x - h)), O2, COUPLER, ROCKER, 1) for x in q])
    vB = np.array(d["joints"]["B"]["vx"], dtype=float) + 1j * np.array(d["joints"]["B"]["vy"])
    assert np.abs(vB - 2.0 * (Bp - Bm) / (2 * h)).max() < 1e-7
    for link in ("1", "2", "3"):
        assert all(v is not None for k in ("angle", "omega", "eps") for v in d["links"][link][k])
    # only the failing dyad is null, and only where it fails
    for name in ("F",):
        for k in ("x", "y", "vx", "vy", "ax", "ay"):
            col = d["joints"][name][k]
            assert [v is None for v in col] == part.tolist(), (name, k)
    for link in ("4", "5"):
        assert [v is None for v in d["links"][link]["angle"]] == part.tolist()
    # the CSV: empty cells for the dyad only
    rows = list(csv.reader(io.StringIO(write_csv(r))))
    head, body = rows[0], rows[1:]
    i_b, i_f = head.index("B.vx"), head.index("F.x")
    assert all((row[i_f] == "") == p for row, p in zip(body, part, strict=True))
    assert all(row[i_b] != "" for row in body)
    # the warning names what is null
    assert any(w.startswith("no assembly for q in") and "of joints F:" in w for w in r.warnings), (
        r.warnings
    )


def test_the_crank_of_a_class_iii_group_that_does_not_close_is_given():
    m = read_mechanism(example_path("triad-class-iii"))
    r = kinematic_analysis(m, frames=36)
    d = r.to_dict()
    missing = [v is None for v in d["joints"]["C"]["x"]]
    assert any(missing) and not all(missing)
    # the crank O1 A turns on every frame (from its reference at frame 0)
    o1, a = complex(*m.joint("O1").at), complex(*m.joint("A").at)
    A = o1 + (a - o1) * np.exp(1j * (r.q[:, 0] - r.q[0, 0]))
    ax = np.array(d["joints"]["A"]["x"], dtype=float)
    ay = np.array(d["joints"]["A"]["y"], dtype=float)
    assert np.abs(ax + 1j * ay - A).max() < 1e-12
    assert all(v is not None for v in d["links"]["1"]["omega"])
    # the triad's joints are null exactly where the closure did not close
    assert r.closure is not None
    assert missing == (~r.closure.converged).tolist()

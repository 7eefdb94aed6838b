"""The batched closure equations and the block continuation of the configuration curve:
the Jacobian against central differences of the residual, batched rows equal to single
ones, and a four-bar whose branches pass within 1e-5 of a second change point."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict, read_mechanism
from mjstruct.singular.analysis import singular_analysis
from mjstruct.singular.curve import ClosureEquations, correct_many, tangents


@pytest.mark.parametrize("name", ["four-bar", "slider-crank", "scotch-yoke", "zhivago"])
def test_batched_equations_against_differences_and_single_rows(name):
    m = read_mechanism(example_path(name))
    eq = ClosureEquations.build(m, m.drivers[0])
    X = np.random.default_rng(3).normal(scale=0.7, size=(5, eq.n))
    R, J = eq.residuals(X), eq.jacobians(X)
    q, gq = eq.inputs(X)
    e = 1e-6
    for k, x in enumerate(X):
        assert np.array_equal(R[k], eq.residual(x)) and np.array_equal(J[k], eq.jacobian(x))
        fd = np.column_stack(
            [(eq.residual(x + e * u) - eq.residual(x - e * u)) / (2 * e) for u in np.eye(eq.n)]
        )
        assert np.abs(fd - J[k]).max() < 1e-8
        gd = [(eq.input(x + e * u)[0] - eq.input(x - e * u)[0]) / (2 * e) for u in np.eye(eq.n)]
        assert np.abs(np.array(gd) - gq[k]).max() < 1e-8 and q[k] == eq.input(x)[0]


def test_corrected_stations_close_and_tangents_span_the_null_space():
    eq = ClosureEquations.build(read_mechanism(example_path("fourbar-ms4")), "O1")
    x0 = eq.reference()
    (t0,), _ = tangents(eq, x0[None, :], np.ones(eq.n))
    s = 0.05 * np.arange(1, 9)
    Y, ok = correct_many(eq, x0 + s[:, None] * t0, t0)
    assert ok.all() and np.abs(eq.residuals(Y)).max() < 1e-13
    assert np.allclose((Y - x0) @ t0, s, atol=1e-14)  # each on its hyperplane
    V, _ = tangents(eq, Y, t0)
    assert np.allclose(np.linalg.norm(V, axis=1), 1.0)
    assert np.abs(np.einsum("kmn,kn->km", eq.jacobians(Y), V)).max() < 1e-13


def test_branches_passing_close_by_are_not_taken_for_a_crossing():
    # [0.5, 0.9999937, 0.5000063] lies on (4.1) and misses (4.3) by 1.3e-5: near
    # q = 360 deg its two circuits pass that close without crossing.  A step that
    # hopped from one to the other flipped the bordered determinant's sign, and the
    # search for the change point there failed ("Newton failed inside a located step")
    p1, p2 = 0.5, 0.9999936537634802
    p3 = 1 + p1 - p2
    A = p1 * complex(math.cos(1.0), math.sin(1.0))
    d = abs(1 - A)
    c = (p2 * p2 + d * d - p3 * p3) / (2 * p2 * d)
    B = A + p2 * (1 - A) / d * complex(c, math.sqrt(1 - c * c))
    joints = [
        {"id": "O1", "links": ["0", "1"], "at": [0, 0]},
        {"id": "A", "links": ["1", "2"], "at": [A.real, A.imag]},
        {"id": "B", "links": ["2", "3"], "at": [B.real, B.imag]},
        {"id": "O2", "links": ["3", "0"], "at": [1, 0]},
    ]
    r = singular_analysis(mechanism_from_dict({"frame": "0", "drivers": ["O1"], "joints": joints}))
    kinds = [p.kind for p in r.singular]
    assert kinds.count("change_point") == 1 and kinds.count("output_extreme") == 2
    (cp,) = [p for p in r.singular if p.kind == "change_point"]
    assert cp.q == pytest.approx(math.pi, abs=1e-9)  # (4.1): A beyond O1
    ext = sorted(p.q for p in r.singular if p.kind == "output_extreme")
    assert ext[0] + ext[1] == pytest.approx(4 * math.pi, abs=1e-9)  # symmetric about 360
    assert math.degrees(r.fourbar.swing) == pytest.approx(359.0, abs=1e-6)

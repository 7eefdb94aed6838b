"""The closure's fast paths: the window of stations, the quintic guess and the path's runs.

Each could be wrong without a test of the results failing loudly (a poorer guess only
costs Newton rounds), so they are checked against slower references: a continuation
on much finer stations, the analytic t'' of :func:`~mjstruct.kinematics.closure.derivatives`,
and polynomials the Hermite interpolation must reproduce.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics import closure, closure_continuation, closure_newton, closure_path
from mjstruct.kinematics.closure_modes import reference_modes
from mjstruct.kinematics.model import KinematicModel


def _model(name: str) -> KinematicModel:
    return KinematicModel.build(read_mechanism(example_path(name)))


def test_class_iv_closes_in_few_evaluations_and_two_rounds(
    closure_evaluations: list[int], scan_evaluations: list[int]
) -> None:
    model = _model("class-iv-seed003")
    calls, scans = closure_evaluations, scan_evaluations
    sol = closure.close(model, model.sweep(3600))
    assert sol.converged.all() and sol.error.max() <= closure.NEWTON_TOL
    assert sol.jumps == () and sol.reseeded == ()
    # the whole turn in one window: one scan for its first guesses and a few rounds
    # (4; 8 from held guesses), one evaluation for the stations' t'', two Newton
    # rounds on the frames and one for t''
    assert scans[0] == 1
    assert calls[0] + scans[0] <= 11, (calls[0], scans[0])
    assert sol.iterations == 2


def test_scanned_roots_guess_the_class_iv_turn_near_its_roots() -> None:
    model = _model("class-iv-seed003")
    only = closure_newton.closing_steps(model)
    path = closure_path.ClosurePath(model.q_ref, model.sweep(3600))
    qv = path.at(np.arange(1, 51) * closure_continuation.WINDOW_STEP)
    g = closure_continuation.scanned_roots(model, qv, None, only, 0.0)
    assert g is not None
    # the roots by Newton on each station from the reference's continuation
    err = np.abs(g - closure.close(model, qv).t)[:, 0]
    # (a held guess is 0.1-0.5 off on the second half of the turn, and does not
    # assemble at s = 4.6-5.1)
    assert err.max() <= 1e-2 and np.median(err) <= 1e-3, (err.max(), np.median(err))
    # the dyad's modes, per station or one for all, give the same scan as the
    # reference's (its modes along this turn)
    (dyad,) = [k for k, s in enumerate(model.plan.steps) if s.kind == "RRR"]
    mode = reference_modes(model, (dyad,))[dyad]
    for K in ({dyad: mode}, {dyad: np.full(qv.shape[0], mode)}):
        assert np.array_equal(closure_continuation.scanned_roots(model, qv, K, only, 0.0), g)
    # the other mode: another curve of roots, or none (then no guesses)
    other = closure_continuation.scanned_roots(model, qv, {dyad: -mode}, only, 0.0)
    assert other is None or np.abs(other - g).max() > 1e-2


def test_a_slide_unknown_takes_no_scan_of_one_turn(monkeypatch: pytest.MonkeyPatch) -> None:
    # the scan covers one turn of an angle: a closure whose unknown is a slide (a
    # random dyad pair closed along a guide, driven by a full turn) keeps the guesses
    # of the nearest stations, and closes as before
    from mjstruct.testing import random_geometry, random_mechanism

    model = KinematicModel.build(random_geometry(random_mechanism(1, seed=219), 219))
    assert [s.kind for s in model.plan.steps if s.kind.startswith("assume")] == ["assume-slide"]

    def refuse(*args: Any, **kwargs: Any) -> Any:
        raise AssertionError("scanned a slide over one turn")

    monkeypatch.setattr(closure_continuation, "scanned_roots", refuse)
    sol = closure.close(model, model.sweep(720))
    assert sol.converged.any()


def test_window_agrees_with_fine_steps_on_the_class_iv_example(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    model = _model("class-iv-seed003")
    q = model.sweep(720)
    coarse = closure.close(model, q, tol=1e-15)
    monkeypatch.setattr(closure_continuation, "WINDOW_STEP", 0.02)
    fine = closure.close(model, q, tol=1e-15)
    assert coarse.converged.all() and fine.converged.all()
    assert np.abs(coarse.t - fine.t).max() <= 1e-12
    assert np.abs(coarse.t2 - fine.t2).max() <= 1e-10 * np.abs(fine.t2).max()


def test_station_curvature_is_the_analytic_second_derivative():
    model = _model("class-iv-seed003")
    q = model.sweep(360)
    path = closure_path.ClosurePath(model.q_ref, q)
    only = closure.closing_steps(model)
    S, TT, DD, _, _ = closure_continuation.continue_stations(model, path, None, 1e-13, 30, only)
    d2 = closure_continuation.station_curvature(model, path, S, TT, DD, None, only)
    assert d2 is not None and d2.shape == TT.shape
    qs = path.at(S)
    t1, _ = closure.derivatives(model, qs, TT, path.dirs[0])
    # a station taken at its predicted Newton point keeps the tangent of the point
    # evaluated before it (stations only guide the frames)
    assert np.abs(t1 - DD).max() <= 1e-6 * max(1.0, float(np.abs(t1).max()))
    # t'' of the stations' own (t, t'): the second derivative of the closure equations
    _, J, _ = closure.closure_jets(model, qs, TT, None, None, only)
    t2 = closure_newton.curvature(model, qs, TT, DD, path.dirs[0], None, J, only)
    assert np.abs(t2 - d2).max() <= 1e-9 * max(1.0, float(np.abs(t2).max()))


def test_hermite_reproduces_quintics_with_curvature_and_cubics_without():
    rng = np.random.default_rng(3)
    x = np.sort(rng.uniform(0.0, 2.0, 7))
    xi = np.linspace(x[0], x[-1], 101)
    c5 = rng.normal(size=6)
    p5 = np.polynomial.Polynomial(c5)
    y, dy, d2y = (p5.deriv(m)(x)[:, None] for m in range(3))
    got = closure_path.hermite(x, y, dy, xi, d2y)
    assert np.abs(got[:, 0] - p5(xi)).max() <= 1e-12 * np.abs(p5(xi)).max()
    p3 = np.polynomial.Polynomial(c5[:4])
    got3 = closure_path.hermite(x, p3(x)[:, None], p3.deriv()(x)[:, None], xi)
    assert np.abs(got3[:, 0] - p3(xi)).max() <= 1e-12 * np.abs(p3(xi)).max()


def test_cubic_interpolates_and_extrapolates_a_cubic():
    p = np.polynomial.Polynomial([0.3, -1.0, 0.5, 2.0])
    s = np.array([0.1, 0.45, 0.8, 1.7])  # inside and beyond [0.2, 0.7]
    got = closure_path.cubic(
        0.2, np.array([p(0.2)]), np.array([p.deriv()(0.2)]), 0.7,
        np.array([p(0.7)]), np.array([p.deriv()(0.7)]), s,
    )  # fmt: skip
    assert np.allclose(got[:, 0], p(s), rtol=0, atol=1e-12)


def test_path_runs_end_where_the_direction_changes():
    # the reference at 0, two frames along q0, then three along q1 (one standing still)
    q = np.array([[0.1, 0.0], [0.2, 0.0], [0.2, 0.1], [0.2, 0.3], [0.2, 0.3]])
    path = closure_path.ClosurePath(np.zeros(2), q)
    assert path.total == pytest.approx(0.5)
    assert path.run_end(0.05) == pytest.approx(0.2)
    assert path.run_end(0.2) == pytest.approx(0.2)  # a run's end belongs to it
    assert path.run_end(0.25) == pytest.approx(0.5)
    dirs = path.directions(np.array([0.0, 0.2, 0.25, 0.5]))
    assert np.array_equal(dirs, [[1, 0], [1, 0], [0, 1], [0, 1]])
    # the modes of the last frame reached (frame 0 before it)
    assert list(path.frames_at(np.array([0.05, 0.2, 0.25, 0.5]))) == [0, 1, 1, 4]
    still = closure_path.ClosurePath(np.zeros(1), np.zeros((2, 1)))
    assert still.total == 0 and still.run_ends.size == 0 and still.run_end(0.0) == 0


def test_agreement_flags_a_hop_and_a_tangent_that_is_not_finite():
    t0 = np.zeros((3, 1))
    d = np.ones((3, 1))
    t1 = np.array([[0.1], [0.5], [0.1]])
    d1 = np.array([[1.0], [1.0], [np.nan]])
    assert list(closure_path.agreement(t0, d, t1, d1, np.full(3, 0.1))) == [True, False, False]


@pytest.mark.parametrize("name", ["class-iv-seed003", "triad-class-iii"])
def test_checks_reuse_the_closure_jacobian_bit_for_bit(
    name: str, closure_evaluations: list[int]
) -> None:
    # the plan determinant takes dR/dt from Newton's last round where the closure has
    # it (the triad: frames closed by reseeding or not at all have none) and is the
    # same, bit for bit, as the closure Jacobian evaluated afresh on every frame
    import dataclasses

    from mjstruct.kinematics import checks

    model = _model(name)
    motion = model.motion(model.sweep(360))
    sol = motion.closure
    assert sol is not None and sol.jacobian is not None
    have = np.isfinite(sol.jacobian).all(axis=(1, 2))
    assert have.any() and not (have & ~sol.converged).any()
    closure_evaluations[0] = 0
    sign, logf = checks.plan_determinant(motion)
    assert closure_evaluations[0] == (0 if have.all() else 1)
    fresh = dataclasses.replace(motion, closure=dataclasses.replace(sol, jacobian=None))
    sign0, log0 = checks.plan_determinant(fresh)
    assert np.array_equal(sign, sign0, equal_nan=True)
    assert np.array_equal(logf, log0, equal_nan=True)

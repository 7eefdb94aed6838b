"""Batched closure: evaluations independent of the frame count, same roots as one station
at a time."""

from __future__ import annotations

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics import closure, closure_continuation
from mjstruct.kinematics.model import KinematicModel


def _model(name: str) -> KinematicModel:
    return KinematicModel.build(read_mechanism(example_path(name)))


@pytest.mark.parametrize("name", ["class-iv-seed003", "zhivago"])
def test_evaluations_do_not_grow_with_frames(name: str, closure_evaluations: list[int]) -> None:
    model = _model(name)
    calls = closure_evaluations
    counts = []
    for frames in (36, 360, 3600):
        calls[0] = 0
        sol = closure.close(model, model.sweep(frames))
        assert sol.converged.all() and sol.error.max() <= 1e-13
        counts.append(calls[0])
    # the continuation is the same path whatever the frames; the final Newton may take
    # one more round on a finer sampling
    assert max(counts) - min(counts) <= 3, counts
    assert max(counts) <= 160, counts


def test_one_station_at_a_time_costs_more(
    monkeypatch: pytest.MonkeyPatch, closure_evaluations: list[int]
) -> None:
    model = _model("class-iv-seed003")
    q = model.sweep(3600)
    calls = closure_evaluations
    closure.close(model, q)
    batched = calls[0]
    monkeypatch.setattr(closure_continuation, "MAX_BLOCK", 1)
    calls[0] = 0
    closure.close(model, q)
    assert batched < 0.8 * calls[0], (batched, calls[0])


@pytest.mark.parametrize("name", ["class-iv-seed003", "zhivago", "triad-class-iii"])
def test_batched_equals_one_station_at_a_time(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    model = _model(name)
    q = model.sweep(720)
    with np.errstate(all="ignore"):
        # closed to the rounding floor, so that both paths meet the same roots
        batched = closure.close(model, q, tol=1e-15)
        monkeypatch.setattr(closure_continuation, "MAX_BLOCK", 1)
        single = closure.close(model, q, tol=1e-15)
    assert np.array_equal(batched.converged, single.converged)
    assert batched.jumps == single.jumps
    ok = batched.converged
    assert ok.any()
    assert np.abs(batched.t[ok] - single.t[ok]).max() <= 1e-12
    assert np.abs(batched.t1[ok] - single.t1[ok]).max() <= 1e-12 * max(
        1.0, np.abs(single.t1[ok]).max()
    )


def test_stacked_jacobian_matches_columns() -> None:
    """The tangent from stacked seeds equals J⁻¹ of separate evaluations."""
    model = _model("triad-class-iii")
    q = model.sweep(12)[:3]
    t = np.zeros((3, model.plan.unknowns))
    R, J, Rd = closure.closure_jets(model, q, t, rates=np.ones(1))
    R2, J2 = closure.closure_jacobian(model, q, t)
    assert Rd is not None
    assert np.allclose(R, R2, rtol=0, atol=1e-15)
    assert np.allclose(J, J2, rtol=0, atol=1e-13 * np.abs(J2).max())


@pytest.mark.parametrize("name", ["class-iv-seed003", "triad-class-iii"])
def test_order_one_skips_only_the_second_derivative(
    name: str, closure_evaluations: list[int]
) -> None:
    model = _model(name)
    q = model.sweep(360)
    calls = closure_evaluations
    full = closure.close(model, q)
    with_t2 = calls[0]
    calls[0] = 0
    first = closure.close(model, q, order=1)
    # the same roots and tangents, one evaluation (of order 2) fewer per close (the
    # reseeding past a gap closes again), t'' not computed
    assert calls[0] < with_t2
    assert np.array_equal(first.t, full.t, equal_nan=True)
    assert np.array_equal(first.t1, full.t1, equal_nan=True)
    assert np.isnan(first.t2).all() and np.isfinite(full.t2[full.converged]).all()
    assert model.motion(q, order=1).valid.sum() == model.motion(q).valid.sum()


def test_tangent_from_the_last_newton_round_is_the_analytic_one() -> None:
    # t' comes with Newton's last round (a seed along the path there): it must equal
    # t' solved afresh at the converged unknowns, rates included
    model = _model("triad-class-iii")
    q = model.sweep(90)
    rate = np.array([-2.5])
    sol = closure.close(model, q, rate)
    ok = sol.converged
    t1, t2 = closure.derivatives(model, q[ok], sol.t[ok], rate)
    scale = max(1.0, float(np.abs(t1).max()))
    assert np.abs(sol.t1[ok] - t1).max() <= 1e-12 * scale
    assert np.abs(sol.t2[ok] - t2).max() <= 1e-10 * max(1.0, float(np.abs(t2).max()))

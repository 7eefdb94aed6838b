"""Kinematics at scale: cheap checks, the planner on large and random mechanisms."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from mjstruct.catalog_files import example_path
from mjstruct.cli.main import main as cli_main
from mjstruct.io import read_mechanism
from mjstruct.kinematics.checks import batched_det, plan_determinant
from mjstruct.kinematics.closure import closure_jacobian
from mjstruct.kinematics.evaluate import evaluate
from mjstruct.kinematics.jacobian import check_jacobian
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.structure.assur import assur_groups
from mjstruct.testing import random_geometry, random_mechanism, shared_crank


@pytest.mark.parametrize(
    "name", ["four-bar", "slider-crank", "zhivago", "class-iv-seed003", "triad-class-iii"]
)
def test_determinant_from_the_plan_equals_the_direct_one(name):
    model = KinematicModel.build(read_mechanism(example_path(name)))
    motion = model.motion(model.sweep(180))
    m, g, poses = model.mechanism, model.geometry, motion.evaluation.poses
    with np.errstate(all="ignore"):
        fast = check_jacobian(m, g, poses, model.drivers, factor=plan_determinant(motion))
        direct = check_jacobian(m, g, poses, model.drivers)
    assert fast.factor_error is not None and fast.factor_error < 1e-12
    ok = np.isfinite(direct.det)
    assert ok.any() and (np.isfinite(fast.det) == ok).all()
    assert np.abs(fast.det[ok] - direct.det[ok]).max() <= 1e-12 * np.abs(direct.det[ok]).max()
    both = (fast.rank >= 0) & (direct.rank >= 0)
    assert both.any() and (fast.rank[both] == direct.rank[both]).all()
    # the dense Jacobian is kept on a few frames only (memory linear in the frames)
    assert fast.J.shape[0] <= 5 + 36


def test_batched_determinant_matches_numpy():
    rng = np.random.default_rng(3)
    for k in (1, 2, 3, 5):
        A = rng.normal(size=(50, k, k))
        A[7] = 0.0  # singular: sign 0, log -inf
        sign, logabs = batched_det(A)
        with np.errstate(divide="ignore"):
            ref_sign, ref_log = np.linalg.slogdet(A)
        assert (sign == ref_sign).all()
        fin = np.isfinite(ref_log)
        assert np.abs(logabs[fin] - ref_log[fin]).max() < 1e-12
        assert not np.isfinite(logabs[~fin]).any()


def test_near_singular_frames_found_without_the_dense_jacobian_everywhere():
    # the slider-crank near its dead centre: frames flagged from the plan's product
    m = read_mechanism(example_path("slider-crank"))
    r = kinematic_analysis(m, frames=3600, checks="full")
    jac = r.checks["jacobian"]
    assert jac["det_from_plan_error"] < 1e-12
    assert r.jacobian is not None and r.jacobian.J.shape[0] <= 41
    # every frame has a determinant; the extremes agree with the closed form of the
    # slider-crank (|det| = L2 |cos phi_rod|, extreme at the crank's dead centres)
    assert np.isfinite(r.jacobian.det).all()
    # the default (O(frames)) check flags the same frames from the product alone
    cheap = kinematic_analysis(m, frames=3600)
    assert cheap.jacobian is None and cheap.checks["jacobian"]["full"] is False
    for key in ("near_singular_frames", "near_singular_kinds", "equations", "coordinates"):
        assert cheap.checks["jacobian"][key] == jac[key], key
    assert cheap.warnings == r.warnings


def test_no_checks_flag_gives_the_same_motion(tmp_path, capsys):
    path = str(example_path("four-bar"))
    assert cli_main(["kinematics", path, "--frames", "24", "--json", "--no-checks"]) == 0
    fast = json.loads(capsys.readouterr().out)
    assert cli_main(["kinematics", path, "--frames", "24", "--json", "--full-checks"]) == 0
    full = json.loads(capsys.readouterr().out)
    assert fast["checks"] == {} and full["checks"]["jacobian"]["rank"] == [8]
    assert cli_main(["kinematics", path, "--frames", "24", "--json"]) == 0
    default = json.loads(capsys.readouterr().out)
    # the default's Jacobian entry has the full one's keys (what it did not compute null)
    assert set(default["checks"]["jacobian"]) == set(full["checks"]["jacobian"])
    jac = default["checks"]["jacobian"]
    assert jac["rank"] == [] and not jac["full"]
    assert fast["joints"] == full["joints"] and fast["links"] == full["links"]


def test_one_step_evaluated_with_its_dependencies_only():
    model = KinematicModel.build(shared_crank(6))
    q = model.sweep(36)
    full = evaluate(model, q, order=0)
    for k, s in enumerate(model.plan.steps):
        if s.kind == "RRR":
            deps = model.step_dependencies[k]
            # crank, driver, the dyad: not the other five four-bars
            assert len(deps) == 3
            part = evaluate(model, q, order=0, only=deps)
            assert np.array_equal(part.diag[k][1], full.diag[k][1])


def test_shared_crank_plans_one_triangle_and_one_diagonal_per_four_bar():
    k = 200  # 402 links, one multiple joint of 201 links
    model = KinematicModel.build(shared_crank(k))
    # each dyad's base A-O2_i runs A - crank - O1 - frame - O2_i: one triangle to find it
    assert model.plan.complexity() == {"general": 2 * k, "right": 0, "checks": 0, "unknowns": 0}
    assert [s.kind for s in model.plan.steps[:2]] == ["reference", "driver-R"]
    r = kinematic_analysis(model, frames=90, checks="full")
    assert r.valid.all() and r.checks["link_lengths"]["max_error"] < 1e-12
    assert r.checks["jacobian"]["det_from_plan_error"] < 1e-9


@settings(
    max_examples=12,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(groups=st.integers(1, 70), seed=st.integers(0, 10**6))
@example(groups=28, seed=156)  # a closure near singular at the reference
def test_every_decomposable_mechanism_plans_and_closes_at_its_reference(groups, seed):
    """Random mechanisms (dyads, triads, class-IV groups, multiple joints, sliders) with
    random geometry, up to about 200 links: a plan, and the reference reproduced."""
    m = random_geometry(random_mechanism(groups, seed=seed), seed)
    assert assur_groups(m).groups  # the decomposition accepts it
    model = KinematicModel.build(m)
    # as many closure equations as unknowns (generic geometry: no redundant constraint)
    assert model.plan.equations == model.plan.unknowns
    with np.errstate(all="ignore"):
        motion = model.motion(model.q_ref[None, :])
    assert motion.valid.all()
    # reproduced to first order: rounding (1e-12 of the size) plus the residual the
    # closure accepted (error e of the size) through its Jacobian in the unknowns
    # (δt ≈ e·size / σ_min), amplified by the worst-conditioned dyad (1 / its sine);
    # measured at most 1e-3 of this bound on the cases drawn here
    sines = [abs(float(det[0])) for _, det in motion.evaluation.diag.values()]
    S = model.scale
    closure = 0.0
    if motion.closure is not None:
        _, Rt = closure_jacobian(model, model.q_ref[None, :], motion.closure.t[:1])
        smallest = float(np.linalg.svd(Rt[0], compute_uv=False).min())
        closure = float(motion.closure.error.max()) * S / smallest
    bound = S * (1e-12 + closure) * (1.0 + 1.0 / min(sines, default=1.0))
    for j in m.joints:
        if j.kind == "R":
            assert abs(motion.centre(j.id)[0][0] - complex(*j.at)) < bound


@pytest.mark.parametrize("name", ["fourbar-ms5", "class-iv-seed003", "slider-crank"])
def test_a_table_read_row_by_row_equals_its_stacked_columns(name):
    # rows are made one at a time when read, columns all at once: the same bits (at a
    # speed below 1, where no overflow check reads the columns first)
    m = read_mechanism(example_path(name))
    by_row = kinematic_analysis(m, frames=90, speed=0.5, checks=False)
    by_column = kinematic_analysis(m, frames=90, speed=0.5, checks=False)
    for table in ("joints", "points", "links"):
        rows, cols = getattr(by_row, table), getattr(by_column, table)
        for key in cols.keys_of_rows() if len(cols) else ():
            col = cols.column(key)
            for k, ident in enumerate(cols):
                assert rows[ident][key].tobytes() == np.ascontiguousarray(col[k]).tobytes()
    frames = np.array([0, 45, 89])
    fresh = kinematic_analysis(m, frames=90, speed=0.5, checks=False)
    xy = by_column.joints.column("x") + 1j * by_column.joints.column("y")
    assert np.array_equal(fresh.joints.values_at(frames), xy[:, frames])


def test_the_model_of_a_mechanism_is_planned_once():
    from mjstruct.kinematics.model import model_of

    m = read_mechanism(example_path("zhivago"))
    assert model_of(m) is model_of(m) is model_of(m, ["O"])
    assert model_of(m, ["E"]) is not model_of(m)
    a = kinematic_analysis(m, frames=12)
    b = kinematic_analysis(m, frames=12)
    assert a.model is b.model is model_of(m)
    assert kinematic_analysis(m, drivers=["E"], frames=12).model is model_of(m, ["E"])

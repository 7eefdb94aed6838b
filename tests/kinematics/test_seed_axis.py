"""Seed axis of ``evaluate``: one call with many seed rows equals one call per row.

With ``rates`` seeds × drivers and ``t1``, ``t2`` seeds × frames (or 1) × unknowns,
every derivative jet (link positions, rotation rates, closure residuals) carries a
leading seed axis whose row i equals, to rounding, a plain evaluation with
``rates[i]``, ``t1[i]`` broadcast to the frames and ``t2[i]``, while values stay per
frame; ``closure_jets``, built on it, gives dR/dt and dR/dτ equal to central
differences of the residuals.  The cases meet every registered step kind, some in
shipped files given other drivers or joints made prismatic.
Not in any shipped example as shipped: driver-P, assume-slide, RPR, PRP, close-point, close-slide.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache

import numpy as np
import numpy.typing as npt
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from mjstruct.catalog_files import example_path
from mjstruct.io import mechanism_from_dict
from mjstruct.kinematics.closure import close, closing_steps, closure_jets
from mjstruct.kinematics.evaluate import Evaluation, evaluate
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.steps import STEP_KINDS

FloatArray = npt.NDArray[np.float64]

#: a slanted guide for the joints made prismatic (no guide parallel to another)
AXIS = [1.0, 0.37]
#: rows run the same arithmetic as a plain call: agreement to rounding of magnitudes
ROUNDING = 1e-12
#: central differences with step H: truncation ~H², cancellation ~1e-16 / H
H = 1e-6
FD_TOL = 1e-6


@dataclass(frozen=True)
class Case:
    """A shipped example, optionally with other drivers and some joints prismatic."""

    example: str
    drivers: tuple[str, ...] = ()
    sliders: tuple[str, ...] = ()
    #: the kinds this case is here for (its plan must contain them)
    kinds: tuple[str, ...] = ()

    @property
    def id(self) -> str:
        extra = [f"drivers {' '.join(self.drivers)}"] if self.drivers else []
        extra += [f"{' '.join(self.sliders)} prismatic"] if self.sliders else []
        return ", ".join([self.example, *extra])


CASES = [
    Case("class-iv-seed003", kinds=("driver-R", "assume", "RRR", "place", "close-distance")),
    Case("slider-crank", kinds=("RRP",)),
    Case("scotch-yoke", kinds=("RPP",)),
    Case("kin-five-bar", kinds=("driver-R", "RRR")),  # two drivers
    # an inner driver: the cluster is solved in link 1's coordinates and carried to the
    # frame's: a seed axis must survive that change of coordinates too
    Case("kin-five-bar", drivers=("A", "C"), kinds=("assume", "place", "close-distance")),
    Case("slider-crank", sliders=("A",), kinds=("PRP",)),
    Case("triad-class-iii", sliders=("O1", "O3"), kinds=("driver-P", "assume-slide")),
    Case("triad-class-iii", sliders=("C", "D"), kinds=("RPR", "close-slide")),
    Case("planetary-2aa", kinds=("gear",)),  # every link turned by Willis' equations
    Case("geared-five-bar", kinds=("gear", "RRR")),
    Case("sun-and-planet", kinds=("gear-link", "RRR")),
    Case(
        "zhivago",
        drivers=("G",),
        sliders=("A", "E"),
        kinds=("assume", "assume-slide", "RRP", "close-point"),
    ),
]
IDS = [c.id for c in CASES]


@cache
def _model(case: Case) -> KinematicModel:
    d = json.loads(example_path(case.example).read_text(encoding="utf-8"))
    if case.drivers:
        d["drivers"] = list(case.drivers)
    for j in d["joints"]:
        if j["id"] in case.sliders:
            j["type"], j["axis"] = "P", AXIS
    return KinematicModel.build(mechanism_from_dict(d))


@cache
def _frames(case: Case) -> tuple[FloatArray, FloatArray]:
    """Frames near the reference (every dyad assembles) and their closure unknowns."""
    model = _model(case)
    drivers = model.q_ref.size
    offsets = np.array([0.0, 0.03, -0.05, 0.08, -0.02])[:, None]
    q = model.q_ref + offsets * np.linspace(1.0, -0.7, drivers)
    if not model.plan.unknowns:
        return q, np.zeros((q.shape[0], 0))
    sol = close(model, q, order=1)
    assert sol.converged.all()
    return q, sol.t


def _rows(a: FloatArray, seeds: int, frames: int) -> FloatArray:
    """A jet's seed rows (a derivative that depends on no seed has no seed axis)."""
    return np.broadcast_to(a, (seeds, frames))


def _agree(seeded: FloatArray, plain: FloatArray, what: str) -> float:
    """Relative discrepancy of one seed row from the plain call (asserted to rounding)."""
    assert seeded.shape == plain.shape, what
    assert np.isfinite(plain).all(), what  # frames near the reference assemble
    size = max(np.abs(plain).max(initial=0.0), np.abs(seeded).max(initial=0.0))
    gap = float(np.abs(seeded - plain).max(initial=0.0))
    assert gap <= ROUNDING * size, (what, gap, size)
    return gap / size if size else 0.0


def _compare(
    model: KinematicModel,
    q: FloatArray,
    t: FloatArray,
    order: int,
    rates: FloatArray,
    t1: FloatArray,
    t2: FloatArray | None,
    only: tuple[int, ...] | None = None,
) -> float:
    """Evaluate once with a seed axis and once per row; the largest discrepancy."""
    seeds, frames, k = rates.shape[0], q.shape[0], t.shape[1]
    ev = evaluate(model, q, order, rates=rates, t=t, t1=t1, t2=t2, only=only)
    eqs = model.plan.equations if only is None else len(ev.residuals)
    if eqs:
        for j in range(1, order + 1):  # derivatives: seeds × frames × equations
            assert ev.residual_matrix(j).shape == (seeds, frames, eqs)
    worst = 0.0
    for i in range(seeds):
        plain = evaluate(
            model,
            q,
            order,
            rates=rates[i],
            t=t,
            t1=np.broadcast_to(t1[i], (frames, k)),
            t2=None if t2 is None else np.broadcast_to(t2[i], (frames, k)),
            only=only,
        )
        worst = max(worst, _compare_row(ev, plain, i, seeds, frames, order))
    return worst


def _compare_row(
    ev: Evaluation, plain: Evaluation, i: int, seeds: int, frames: int, order: int
) -> float:
    assert ev.poses.keys() == plain.poses.keys()
    worst = 0.0
    for link, p in plain.poses.items():
        s = ev.poses[link]
        # values are per frame, computed once for every seed row
        assert s.A[0].shape == s.r.shape == (frames,), link
        worst = max(worst, _agree(s.A[0], p.A[0], f"{link} position"))
        worst = max(worst, _agree(s.r, p.r, f"{link} rotation"))
        for j in range(1, order + 1):
            worst = max(worst, _agree(_rows(s.A[j], seeds, frames)[i], p.A[j], f"{link} A{j}"))
            worst = max(
                worst, _agree(_rows(s.w[j - 1], seeds, frames)[i], p.w[j - 1], f"{link} w{j}")
            )
    assert len(ev.residuals) == len(plain.residuals)
    for e, (rs, rp) in enumerate(zip(ev.residuals, plain.residuals, strict=True)):
        assert rs[0].shape == (frames,)
        worst = max(worst, _agree(rs[0], rp[0], f"residual {e}"))
        for j in range(1, order + 1):
            worst = max(worst, _agree(_rows(rs[j], seeds, frames)[i], rp[j], f"residual {e}'{j}"))
    if plain.residuals:
        for j in range(1, order + 1):
            seeded = np.broadcast_to(
                ev.residual_matrix(j), (seeds, *plain.residual_matrix(j).shape)
            )
            worst = max(
                worst, _agree(seeded[i], plain.residual_matrix(j), f"residual_matrix({j})")
            )
    return worst


def test_the_cases_cover_every_step_kind() -> None:
    # a kind registered later and met by no case would go untested with seed rows
    seen: set[str] = set()
    for case in CASES:
        kinds = {s.kind for s in _model(case).plan.steps}
        assert set(case.kinds) <= kinds, case.id
        seen |= kinds
    assert seen == set(STEP_KINDS)


def test_residual_matrix_has_the_seed_axis_in_front() -> None:
    case = CASES[0]  # class-iv-seed003: one unknown, one equation
    model = _model(case)
    q, t = _frames(case)
    rates = np.array([[1.0], [0.0], [-2.0]])
    t1 = np.array([0.0, 1.0, 0.5])[:, None, None]
    ev = evaluate(model, q, 2, rates=rates, t=t, t1=t1, t2=np.zeros((3, 1, 1)))
    frames, eqs = q.shape[0], model.plan.equations
    assert ev.residual_matrix(0).shape == (frames, eqs)  # values: once, per frame
    assert ev.residual_matrix(1).shape == ev.residual_matrix(2).shape == (3, frames, eqs)
    # at rest in q with t' = 1 the first derivative is the Jacobian's column
    _, J, _ = closure_jets(model, q, t)
    assert np.abs(ev.residual_matrix(1)[1] - J[..., 0]).max() <= ROUNDING * np.abs(J).max()


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("per_frame", [False, True], ids=["t1 one row", "t1 per frame"])
@pytest.mark.parametrize("case", CASES, ids=IDS)
def test_each_seed_row_equals_a_plain_evaluation(case: Case, per_frame: bool, order: int) -> None:
    model = _model(case)
    q, t = _frames(case)
    rng = np.random.default_rng(7)
    seeds, frames, k = 3, q.shape[0], t.shape[1]
    rates = rng.normal(size=(seeds, q.shape[1]))
    t1 = rng.normal(size=(seeds, frames if per_frame else 1, k))
    t2 = rng.normal(size=(seeds, 1, k))
    _compare(model, q, t, order, rates, t1, t2)


@pytest.mark.parametrize("case", [c for c in CASES if _model(c).plan.unknowns], ids=lambda c: c.id)
def test_each_seed_row_equals_a_plain_evaluation_of_the_closing_steps(case: Case) -> None:
    # what the closure evaluates: only the steps its equations read
    model = _model(case)
    q, t = _frames(case)
    rng = np.random.default_rng(11)
    k = t.shape[1]
    only = closing_steps(model)
    rates = rng.normal(size=(2, q.shape[1]))
    _compare(model, q, t, 2, rates, rng.normal(size=(2, 1, k)), rng.normal(size=(2, 1, k)), only)


@st.composite
def _seed_rows(
    draw: st.DrawFn, drivers: int, frames: int, unknowns: int
) -> tuple[FloatArray, FloatArray, FloatArray | None, int]:
    """Random seed rows: rates, t1 (one row or one per frame), t2 or None, and the order."""
    seeds = draw(st.integers(1, 4))
    values = st.floats(-5.0, 5.0, allow_nan=False, allow_infinity=False)
    rows = draw(st.sampled_from([1, frames]))
    rates = draw(hnp.arrays(np.float64, (seeds, drivers), elements=values))
    t1 = draw(hnp.arrays(np.float64, (seeds, rows, unknowns), elements=values))
    # no t2: zero for every seed row, without a seed axis of its own
    t2 = draw(st.none() | hnp.arrays(np.float64, (seeds, 1, unknowns), elements=values))
    return rates, t1, t2, draw(st.sampled_from([1, 2]))


# the richest cases: two unknowns with close-point; an inner driver (two drivers)
RANDOM_CASES = [c for c in CASES if "close-point" in c.kinds or c.drivers == ("A", "C")]


@pytest.mark.parametrize("case", RANDOM_CASES, ids=lambda c: c.id)
@settings(max_examples=20, deadline=None)
@given(data=st.data())
def test_random_seed_rows_equal_plain_evaluations(case: Case, data: st.DataObject) -> None:
    model = _model(case)
    q, t = _frames(case)
    rates, t1, t2, order = data.draw(_seed_rows(q.shape[1], q.shape[0], t.shape[1]))
    _compare(model, q, t, order, rates, t1, t2)


@pytest.mark.parametrize("case", [c for c in CASES if _model(c).plan.unknowns], ids=lambda c: c.id)
@pytest.mark.parametrize("restricted", [False, True], ids=["all steps", "closing steps"])
def test_closure_jets_against_central_differences(case: Case, restricted: bool) -> None:
    model = _model(case)
    q, t = _frames(case)
    only = closing_steps(model) if restricted else None
    rates = np.linspace(1.0, -0.6, q.shape[1])
    R, J, Rd = closure_jets(model, q, t, None, rates, only)
    frames, k = t.shape

    def residual(qq: FloatArray, tt: FloatArray) -> FloatArray:
        out: FloatArray = evaluate(model, qq, order=0, t=tt, only=only).residual_matrix(0)
        return out

    assert R.shape == (frames, model.plan.equations)
    assert np.array_equal(R, residual(q, t))
    # dR/dt: one column per unknown
    fd = np.stack(
        [(residual(q, t + H * e) - residual(q, t - H * e)) / (2 * H) for e in np.eye(k)], axis=-1
    )
    assert J.shape == fd.shape == (frames, model.plan.equations, k)
    assert np.abs(J - fd).max() <= FD_TOL * np.abs(J).max()
    # dR/dτ at fixed t: along q' = rates
    assert Rd is not None
    fd_q = (residual(q + H * rates, t) - residual(q - H * rates, t)) / (2 * H)
    assert Rd.shape == fd_q.shape
    assert np.abs(Rd - fd_q).max() <= FD_TOL * np.abs(Rd).max()
    # without rates: no τ direction, the same Jacobian
    _, J0, none = closure_jets(model, q, t, None, None, only)
    assert none is None and np.array_equal(J0, J)

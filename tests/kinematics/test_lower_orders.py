"""An evaluation started from a lower one's positions (and first derivatives) gives the
same numbers, bit for bit, as one computed afresh; the default call starts its final
evaluation from the closure's evaluation of t''."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.kinematics import model as model_module
from mjstruct.kinematics.closure import close
from mjstruct.kinematics.closure_newton import closing_steps
from mjstruct.kinematics.evaluate import Evaluation, evaluate
from mjstruct.kinematics.model import KinematicModel
from mjstruct.kinematics.solver import kinematic_analysis
from mjstruct.testing import random_geometry, random_mechanism


def _arrays(ev: Evaluation) -> dict[str, bytes]:
    """Every number an evaluation holds, as bytes (NaN payloads and zero signs too)."""
    out: dict[str, bytes] = {}
    for link, p in ev.poses.items():
        for name, jet in (("A", p.A), ("w", p.w), ("r", [p.r])):
            for i, x in enumerate(jet):
                out[f"{link}.{name}{i}"] = np.ascontiguousarray(x).tobytes()
    for i, jet in enumerate(ev.residuals):
        for j, x in enumerate(jet):
            out[f"R{i}.{j}"] = np.ascontiguousarray(x).tobytes()
    for k, (disc, det) in ev.diag.items():
        out[f"diag{k}"] = (
            np.ascontiguousarray(disc).tobytes() + np.ascontiguousarray(det).tobytes()
        )
    return out


def _cases() -> list[KinematicModel]:
    models = [KinematicModel.build(read_mechanism(example_path(n))) for n in ("class-iv-seed003",)]
    models.append(KinematicModel.build(read_mechanism(example_path("triad-class-iii"))))
    for seed in (3, 8):
        m = random_geometry(random_mechanism(3, seed=seed), seed)
        models.append(KinematicModel.build(m))
    return [m for m in models if m.plan.unknowns]


@pytest.mark.parametrize("model", _cases(), ids=lambda m: str(len(m.plan.steps)))
def test_higher_orders_from_a_lower_evaluation_are_the_same_numbers(model: KinematicModel) -> None:
    q = model.sweep(97)
    sol = close(model, q)
    t, t1, t2, K = sol.t, sol.t1, sol.t2, sol.modes or None
    only = closing_steps(model)
    rate = np.ones(q.shape[1])
    fresh = evaluate(model, q, order=2, rates=rate, t=t, t1=t1, t2=t2, K=K)
    # positions from an order-0 evaluation of the closing steps, then positions and
    # first derivatives from an order-1 one (as the closure and the default call do)
    pos = evaluate(model, q, order=0, t=t, K=K, only=only, keep_carried=True)
    vel = evaluate(model, q, order=1, rates=rate, t=t, t1=t1, K=K, only=only, keep_carried=True)
    for lower, known in ((pos, 0), (vel, 1)):
        assert lower.reusable
        again = evaluate(
            model, q, order=2, rates=rate, t=t, t1=t1, t2=t2, K=K, lower=lower, known=known
        )
        assert _arrays(again) == _arrays(fresh)
    # an evaluation not asked to keep its centres is not taken as a lower one
    plain = evaluate(model, q, order=1, rates=rate, t=t, t1=t1, K=K, only=only)
    assert not plain.reusable


def test_the_default_call_starts_its_evaluation_from_the_closure(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    seen: list[Any] = []
    real = model_module.evaluate

    def spy(*args: Any, **kwargs: Any) -> Evaluation:
        seen.append(kwargs.get("lower"))
        return real(*args, **kwargs)

    monkeypatch.setattr(model_module, "evaluate", spy)
    m = read_mechanism(example_path("class-iv-seed003"))
    kinematic_analysis(m, frames=72)
    assert seen and seen[0] is not None and seen[0].reusable
    # kept without its second derivatives (t'' was 0 there; they are not reused)
    lower = seen[0]
    assert lower.order == 1 and all(len(p.A) == 2 and len(p.w) == 1 for p in lower.poses.values())

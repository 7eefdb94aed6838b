"""The result of a dynamic analysis over its frames, and its contract JSON.

Owns :class:`DynamicsResult` (the arrays of every output, None where not computed)
and :meth:`DynamicsResult.to_dict`, the JSON object of docs/contract.md.

Examples
--------
>>> import numpy as np
>>> r = DynamicsResult("demo", "speed", ("O1",), np.zeros((2, 1)), np.ones((2, 1)),
...                    np.zeros((2, 1)))
>>> r.to_dict()["q"], "qdot" in r.to_dict()
([0.0, 0.0], False)
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from mjstruct.output_numbers import json_list, json_number
from mjstruct.typing import FloatArray

__all__ = ["OUTPUTS", "DynamicsResult"]


#: what :func:`~mjstruct.dynamics.analysis.dynamic_analysis` can compute
OUTPUTS = ("coefficients", "motion", "reactions", "driving", "check")


@dataclass(frozen=True)
class DynamicsResult:
    """Arrays over the frames of a dynamic analysis (None where not computed).

    Attributes
    ----------
    name : the mechanism's name.
    mode : ``"speed"`` (constant driver speed), ``"free"`` (one-DOF motion from
        ``qdot0``) or ``"prescribed"`` (q(t) given).
    drivers : the driver joints.
    q : driver values, frames × drivers (frames kept).
    qdot, qddot : speeds and accelerations, frames × drivers.
    V, W, Q : reduced inertia, its W term and the generalised force (one driver).
    balance : min V / max V over the frames (one driver).
    parameters : all parameters, the unknown solved.
    cycle_work : work of the loads over one cycle with those parameters.
    integration_error : estimated error of the cycle work (free motion).
    driving : driver joint -> actuator torque or force on its second listed link.
    reactions : joint -> link -> {``x``, ``y`` (and ``m`` for a slider)}: the load the
        joint applies to the link (an MJ: one entry per link, summing to zero).
    residual : per-frame relative residual of the excluded equation.
    check : the largest of ``residual`` (None when no frame was solved).
    condition : per-frame estimate of the condition number κ∞ of the link equations
        (a lower bound within a small factor, from the solve's own factorisation; JSON:
        its largest value); near a singular position the accelerations and reactions
        lose between log10 and 2·log10 of it in digits.  Frames above
        ``SINGULAR_CONDITION`` (1e15) are singular: null loads and a warning.
    accuracy : per-frame estimate of the relative error of the reactions and actuator
        loads: the solve's, condition × machine epsilon, plus the relative error
        estimate of the velocity and acceleration analogs fed into it
        (:func:`~mjstruct.kinematics.accuracy.analog_relative_error`; JSON: its largest
        value).
        ``check`` cannot see this loss (the excluded equation is computed from the
        same rounded loads), ``accuracy`` grows with the conditioning.
    warnings : what the user must know.
    """

    name: str
    mode: str
    drivers: tuple[str, ...]
    q: FloatArray
    qdot: FloatArray
    qddot: FloatArray
    V: FloatArray | None = None
    W: FloatArray | None = None
    Q: FloatArray | None = None
    balance: float | None = None
    parameters: dict[str, float] = field(default_factory=dict)
    cycle_work: float | None = None
    integration_error: float | None = None
    driving: dict[str, FloatArray] | None = None
    reactions: dict[str, dict[str, dict[str, FloatArray]]] | None = None
    residual: FloatArray | None = None
    check: float | None = None
    condition: FloatArray | None = None
    accuracy: FloatArray | None = None
    warnings: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, Any]:
        """The contract's JSON object (lists; NaN as null)."""
        out: dict[str, Any] = {"q": _list(self.q[:, 0])}
        # q is the first driver's (the contract's); every driver's coordinate here
        out["q_drivers"] = {d: _list(self.q[:, i]) for i, d in enumerate(self.drivers)}
        if self.mode != "speed" and self.V is not None:
            out["V"] = _list(self.V)
            out["W"] = _list(self.W)
            out["Q"] = _list(self.Q)
        if self.mode != "speed":
            out["qdot"] = _list(self.qdot[:, 0])
            out["qddot"] = _list(self.qddot[:, 0])
            out["balance"] = json_number(self.balance)
        if self.parameters or self.mode == "free":
            out["parameters"] = {k: json_number(v) for k, v in self.parameters.items()}
        if self.driving is not None:
            out["driving"] = {k: _list(v) for k, v in self.driving.items()}
        if self.reactions is not None:
            out["reactions"] = {
                j: {link: {c: _list(v) for c, v in comps.items()} for link, comps in per.items()}
                for j, per in self.reactions.items()
            }
        if self.residual is not None:
            out["check"] = json_number(self.check)
        for key, arr in (("condition", self.condition), ("accuracy", self.accuracy)):
            if arr is not None and np.isfinite(arr).any():
                out[key] = json_number(float(arr[np.isfinite(arr)].max()))
        out["warnings"] = list(self.warnings)
        return out


def _list(a: FloatArray | None) -> list[float | None]:
    return [] if a is None else json_list(np.asarray(a, float))

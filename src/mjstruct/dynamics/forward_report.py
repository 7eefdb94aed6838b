"""What ``mjstruct dynamics FILE --time T`` prints for a run of :func:`forward_dynamics`.

Owns the JSON object (:func:`forward_json`), the text report (:func:`forward_report`)
and the CSV table (:func:`forward_csv`) of a
:class:`~mjstruct.dynamics.forward.ForwardMotion`: a mechanism with several drivers or
with force elements (one driver without elements keeps the reduced equation's output of
:mod:`mjstruct.dynamics.time`).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.dynamics.forward import forward_dynamics
>>> r = forward_dynamics(read_mechanism(example_path("five-bar-springs-dynamics")), 0.1,
...                      frames=3, estimate=False)
>>> sorted(forward_json(r)["q"]), forward_json(r)["equations"]
(['O1', 'O2'], 'lagrange')
"""

from __future__ import annotations

from typing import Any

import numpy as np

from mjstruct.dynamics.forward import ForwardMotion
from mjstruct.dynamics.time import accuracy_text, solver_account, solver_text
from mjstruct.output_numbers import json_list, json_number
from mjstruct.output_numbers import text_number as _fmt

__all__ = ["forward_csv", "forward_json", "forward_report"]


def forward_json(r: ForwardMotion) -> dict[str, Any]:
    """The JSON object (no NaN: null); per-driver lists under ``q``, ``qdot``, ``qddot``."""
    out: dict[str, Any] = {
        "equations": "lagrange",
        "drivers": list(r.drivers),
        "t": json_list(r.t),
        "q": {d: json_list(r.q[:, i]) for i, d in enumerate(r.drivers)},
        "qdot": {d: json_list(r.qdot[:, i]) for i, d in enumerate(r.drivers)},
        "qddot": {d: json_list(r.qddot[:, i]) for i, d in enumerate(r.drivers)},
        "kinetic": json_list(r.kinetic),
        "potential": json_list(r.potential),
        "work": json_list(r.work),
        **solver_account(r),
        "stopped": r.stopped,
        "events": [{"t": json_number(t), "kind": k, "driver": d} for t, k, d in r.events],
    }
    if r.loads is not None:
        loads = r.loads.to_dict()
        for key in ("reactions", "driving", "check"):
            if key in loads:
                out[key] = loads[key]
    out["warnings"] = list(r.warnings)
    return out


def forward_report(r: ForwardMotion, rows: int = 11) -> str:
    """The text report: the solver's work, the accuracy and a table of ``rows`` times."""
    start = (
        "from rest"
        if not np.any(r.qdot[0])
        else "from qdot = " + ", ".join(_fmt(float(x)) for x in r.qdot[0])
    )
    lines = [
        f"{r.name or 'mechanism'}: motion in time (Lagrange's equations, "
        f"{len(r.drivers)} driver(s) {', '.join(r.drivers)}) {start}, "
        f"t = 0 … {_fmt(float(r.t[-1]))}",
    ]
    lines += solver_text(r)
    lines.append(accuracy_text(r))
    if r.loads is not None and r.loads.driving is not None:
        worst = max(
            (
                float(np.nanmax(np.abs(v)))
                for v in r.loads.driving.values()
                if np.isfinite(v).any()
            ),
            default=float("nan"),
        )
        lines.append(
            f"joint reactions on the output times; actuator loads the link equations need "
            f"beyond the motors: at most {_fmt(worst)} (zero in free motion)"
        )
    n = len(r.t)
    idx = np.unique(np.linspace(0, n - 1, min(rows, n)).round().astype(int))
    head = [f"{'t':>12}"] + [f"{'q ' + d:>12}  {'qdot ' + d:>12}" for d in r.drivers]
    lines.append("  " + "  ".join(head) + f"  {'energy':>12}")
    energy = r.kinetic + r.potential - r.work
    for i in idx:
        cells = [f"{_fmt(float(r.t[i])):>12}"]
        cells += [
            f"{_fmt(float(r.q[i, k])):>12}  {_fmt(float(r.qdot[i, k])):>12}"
            for k in range(len(r.drivers))
        ]
        lines.append("  " + "  ".join(cells) + f"  {_fmt(float(energy[i])):>12}")
    for t, kind_, d in r.events[:10]:
        lines.append(f"event: {kind_} of {d} at t = {_fmt(t)}")
    if len(r.events) > 10:
        lines.append(f"event: … {len(r.events) - 10} more (see --json)")
    lines += [f"warning: {w}" for w in r.warnings]
    return "\n".join(lines)


def forward_csv(r: ForwardMotion) -> str:
    """One row per output time: ``t``, each driver's ``q``, ``qdot``, ``qddot``, the
    energies and the work (empty where not finite)."""
    cols: list[tuple[str, Any]] = [("t", r.t)]
    for k, d in enumerate(r.drivers):
        cols += [(f"q_{d}", r.q[:, k]), (f"qdot_{d}", r.qdot[:, k]), (f"qddot_{d}", r.qddot[:, k])]
    cols += [("kinetic", r.kinetic), ("potential", r.potential), ("work", r.work)]
    lines = [",".join(name for name, _ in cols)]
    for row in zip(*(v for _, v in cols), strict=True):
        lines.append(",".join(repr(float(x)) if np.isfinite(x) else "" for x in row))
    return "\n".join(lines) + "\n"

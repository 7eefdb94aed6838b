"""Readable text and CSV tables of a :class:`~mjstruct.dynamics.analysis.DynamicsResult`.

Owns the wording of ``mjstruct dynamics``: the mode, the solved parameter, the
balance, the largest reactions and where they occur, the actuator loads and the
excluded-equation check.

Examples
--------
>>> import numpy as np
>>> print(_table([("a", 1.5), ("bb", None)]))
  a   1.5
  bb  -
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from mjstruct.dynamics.result import DynamicsResult
from mjstruct.output_numbers import text_number as _fmt


def _table(rows: list[tuple[str, float | None]]) -> str:
    width = max(len(k) for k, _ in rows)
    return "\n".join(f"  {k.ljust(width)}  {_fmt(v)}" for k, v in rows)


def render(r: DynamicsResult) -> str:
    """The text report."""
    q = r.q[:, 0]
    mode = {
        "speed": f"inverse dynamics at constant driver speed {_fmt(float(r.qdot[0, 0]))}",
        "free": f"free motion under the loads from qdot0 = {_fmt(float(r.qdot[0, 0]))}",
        "prescribed": "prescribed motion",
    }[r.mode]
    lines = [
        f"{r.name or 'mechanism'}: {mode}",
        f"  frames {len(q)}, drivers {', '.join(r.drivers)}",
    ]
    if r.parameters:
        lines.append("parameters:")
        lines.append(_table(sorted(r.parameters.items())))
    if r.cycle_work is not None:
        lines.append(
            f"cycle work of the loads {_fmt(r.cycle_work)}"
            + (
                f" (integration error ~ {_fmt(r.integration_error)})"
                if r.integration_error is not None
                else ""
            )
        )
    if r.balance is not None and r.V is not None:
        lines.append(
            f"degree of balance min V / max V = {_fmt(r.balance)} "
            f"(V from {_fmt(float(np.nanmin(r.V)))} to {_fmt(float(np.nanmax(r.V)))})"
        )
    if r.mode == "free":
        qd = r.qdot[:, 0]
        lines.append(f"speed qdot from {_fmt(float(np.min(qd)))} to {_fmt(float(np.max(qd)))}")
    if r.driving is not None and r.mode != "free":
        for d, v in r.driving.items():
            if np.isfinite(v).any():
                k = int(np.nanargmax(np.abs(v)))
                lines.append(
                    f"actuator at {d}: largest {_fmt(float(v[k]))} at q = {_fmt(float(q[k]))}"
                )
    if r.reactions:
        rows = []
        for jid, per in r.reactions.items():
            best: tuple[float, str, float] | None = None
            for link, comp in per.items():
                mag = np.hypot(comp["x"], comp["y"])
                if np.isfinite(mag).any():
                    k = int(np.nanargmax(mag))
                    if best is None or mag[k] > best[0]:
                        best = (float(mag[k]), link, float(q[k]))
            if best is not None:
                rows.append((best[0], jid, best[1], best[2]))
        rows.sort(reverse=True)
        lines.append("largest joint loads |R| (joint, on link, at q):")
        for size, jid, link, qk in rows[:8]:
            lines.append(f"  {jid} on {link}: {_fmt(size)} at q = {_fmt(qk)}")
    if r.residual is not None:
        lines.append(f"check (excluded equation, relative residual): {_fmt(r.check)}")
    if r.accuracy is not None and np.isfinite(r.accuracy).any():
        worst = float(r.accuracy[np.isfinite(r.accuracy)].max())
        lines.append(
            f"accuracy of the joint loads (condition x machine epsilon, relative): {_fmt(worst)}"
        )
    for w in r.warnings:
        lines.append(f"warning: {w}")
    return "\n".join(lines)


def write_csv(r: DynamicsResult, path: str | Path) -> None:
    """One row per frame: q, qdot, qddot, V, W, Q, actuator loads, reactions."""
    cols: list[tuple[str, np.ndarray]] = [
        ("q", r.q[:, 0]),
        ("qdot", r.qdot[:, 0]),
        ("qddot", r.qddot[:, 0]),
    ]
    for name in ("V", "W", "Q"):
        v = getattr(r, name)
        if v is not None:
            cols.append((name, v))
    for d, v in (r.driving or {}).items():
        cols.append((f"driving:{d}", v))
    for jid, per in (r.reactions or {}).items():
        for link, comp in per.items():
            for c, v in comp.items():
                cols.append((f"{jid}:{link}:{c}", v))
    rows = zip(*(v for _, v in cols), strict=True)
    from mjstruct.output_files import replacing

    # whole or not at all, a link followed, the umask's permissions
    with replacing(path) as tmp, open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow([name for name, _ in cols])
        for row in rows:
            w.writerow(["" if not np.isfinite(x) else repr(float(x)) for x in row])

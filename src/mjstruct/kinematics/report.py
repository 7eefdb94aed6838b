"""Writing a kinematic analysis: the text report and the CSV table.

Owns the human-readable side of :class:`~mjstruct.kinematics.solver.KinematicsResult`:
the plan in words with its complexity, closure statistics, the checks, flagged frames
and warnings; and the CSV table (q, then x y vx vy ax ay per joint and point, angle
ω ε per link; empty cells where a frame does not assemble).

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.solver import kinematic_analysis
>>> r = kinematic_analysis(read_mechanism(example_path("four-bar")), frames=36)
>>> print(render(r).splitlines()[0])
kinematics of four-bar: 36 frames, drivers O1, speed 1
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from mjstruct.kinematics.solver import KinematicsResult


def render(r: KinematicsResult) -> str:
    """The text report: plan, complexity, closure, checks, warnings."""
    name = r.mechanism.name or "mechanism"
    out = [
        f"kinematics of {name}: {r.q.shape[0]} frames, drivers {', '.join(r.plan.drivers)}, "
        f"speed {r.speed:g}"
    ]
    out.append(f"plan ({r.plan.source}; solved in link {r.plan.reference}'s frame):")
    out += [f"  {line}" for line in r.plan.describe()]
    c = r.plan.complexity()
    out.append(
        f"complexity: {c['general']} general + {c['right']} right triangle(s) "
        f"(+{c['checks']} check triangle(s)), {c['unknowns']} closure unknown(s)"
    )
    if r.closure is not None:
        cl = r.closure
        ok = cl.converged
        err = float(cl.error[ok].max()) if ok.any() else float("nan")
        out.append(
            f"closure: Newton, tolerance {cl.tol:g} (relative to size), {cl.iterations} "
            f"iteration(s) on all frames, achieved error {err:.3g}, {int(ok.sum())}/{ok.size} "
            "frames closed"
        )
    ch = r.checks
    if "link_lengths" in ch:
        out.append(f"check link lengths: max error {ch['link_lengths']['max_error']:.3g}")
    if "analogs_vs_differences" in ch:
        a = ch["analogs_vs_differences"]
        # no q of the maximum: exact agreement, or no five consecutive valid frames
        at = a["q_of_max_error"]
        out.append(
            f"check analogs vs five-point differences (step {a['step']:.3g}): max error "
            f"{a['max_error']:.3g}{'' if at is None else f' at q = {at:.6g}'} "
            f"(largest analog {a['max_analog']:.3g})"
        )
    if "jacobian" in ch:
        j = ch["jacobian"]
        out.append(
            f"check Jacobian: {j['equations']} equations × {j['coordinates']} coordinates, "
            f"rank {j['rank']} (SVD on {j['rank_frames']} frames), "
            f"redundant {j['redundant_constraints']}, DOF {j['dof']}, "
            f"|det| with drivers fixed in [{_g(j['min_abs_det'])}, {_g(j['max_abs_det'])}], "
            f"near-singular frames {j['near_singular_frames'] or 'none'}"
        )
    placed, valid = int(r.placed.sum()), int(r.valid.sum())
    singular = f" ({placed - valid} singular: positions only)" if placed != valid else ""
    out.append(f"frames assembled: {placed}/{r.valid.size}{singular}")
    if r.warnings:
        out.append("warnings:")
        out += [f"  {w}" for w in r.warnings]
    else:
        out.append("warnings: none")
    return "\n".join(out)


def _g(x: float | None) -> str:
    return "n/a" if x is None else f"{x:.4g}"


def write_csv(r: KinematicsResult, path: str | Path | None = None) -> str:
    """The table as CSV text (and written to ``path`` when given)."""
    names, data = r.table()
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(names)
    for row in data:
        w.writerow(["" if not np.isfinite(x) else repr(float(x)) for x in row])
    text = buf.getvalue()
    if path is not None:
        Path(path).write_text(text, encoding="utf-8")
    return text

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
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TextIO

import numpy as np

from mjstruct.kinematics.solver import KinematicsResult
from mjstruct.output_files import replacing


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
    if "jacobian" in ch and not ch["jacobian"].get("full", True):
        j = ch["jacobian"]
        out.append(
            f"check Jacobian: {j['equations']} equations × {j['coordinates']} coordinates, "
            f"near-singular frames {j['near_singular_frames'] or 'none'} (from the plan's "
            "group determinants; its rank and |det| with --full-checks)"
        )
    elif "jacobian" in ch:
        j = ch["jacobian"]
        out.append(
            f"check Jacobian: {j['equations']} equations × {j['coordinates']} coordinates, "
            f"rank {j['rank']} (SVD on {j['rank_frames']} frames), "
            f"redundant {j['redundant_constraints']}, DOF {j['dof']}, "
            f"|det| with drivers fixed in [{_g(j['min_abs_det'])}, {_g(j['max_abs_det'])}], "
            f"near-singular frames {j['near_singular_frames'] or 'none'}"
        )
    out += _closing_lines(int(r.placed.sum()), int(r.valid.sum()), r.valid.size, r.warnings)
    return "\n".join(out)


def _closing_lines(placed: int, valid: int, frames: int, warnings: Sequence[str]) -> list[str]:
    """The report's last lines: frames assembled (singular ones apart), the warnings."""
    singular = f" ({placed - valid} singular: positions only)" if placed != valid else ""
    lines = [f"frames assembled: {placed}/{frames}{singular}"]
    if warnings:
        return [*lines, "warnings:", *(f"  {w}" for w in warnings)]
    return [*lines, "warnings: none"]


def _g(x: float | None) -> str:
    return "n/a" if x is None else f"{x:.4g}"


#: rows formatted and written at a time (bounds the text held in memory)
CSV_ROWS = 4096


def write_csv(r: KinematicsResult, path: str | Path | None = None) -> str:
    """The table as CSV text, or, given ``path``, written there (atomically; returns "").

    The file is written in blocks of :data:`CSV_ROWS` rows to a temporary file in the
    target directory and renamed into place, so no half-written table is left.
    """
    if path is None:
        buf = io.StringIO()
        _write_rows(buf, r, header=True)
        return buf.getvalue()
    write_csv_chunks([r], path)
    return ""


def _write_rows(out: TextIO, r: KinematicsResult, header: bool) -> None:
    names, data = r.table()
    w = csv.writer(out, lineterminator="\n")
    if header:
        w.writerow(names)
    for lo in range(0, data.shape[0], CSV_ROWS):
        w.writerows(
            ["" if not np.isfinite(x) else repr(float(x)) for x in row]
            for row in data[lo : lo + CSV_ROWS]
        )


def write_csv_chunks(chunks: Iterable[KinematicsResult], path: str | Path) -> StreamSummary:
    """Write the tables of consecutive chunks of one sweep as one CSV file.

    The rows go to a temporary file next to ``path`` (same directory, so the final
    rename is atomic), which replaces ``path`` only when every chunk is written; on
    any error (or interruption) the temporary file is removed and ``path`` is left as
    it was.  Returns what the report needs of the whole sweep.
    """
    summary: StreamSummary | None = None
    # a link is followed, a new file gets the umask's permissions (output_files)
    with (
        replacing(path, suffix=".tmp") as tmp,
        open(tmp, "w", encoding="utf-8", newline="") as out,
    ):
        for r in chunks:
            _write_rows(out, r, header=summary is None)
            summary = StreamSummary.first(r) if summary is None else summary.add(r)
    assert summary is not None
    return summary


@dataclass
class StreamSummary:
    """What the report says of a sweep whose chunks were written and dropped.

    ``frames``, ``assembled``, ``valid``: counts over the sweep; ``chunks``; the
    largest errors of the checks; the near-singular frames (sweep numbers); the
    warnings of every chunk, each once, in order.
    """

    first_chunk: KinematicsResult
    frames: int = 0
    assembled: int = 0
    valid: int = 0
    chunks: int = 0
    closure_iterations: int = 0
    closure_error: float = 0.0
    link_error: float | None = None
    analog_error: float | None = None
    near_singular: list[int] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    @classmethod
    def first(cls, r: KinematicsResult) -> StreamSummary:
        """The summary of the first chunk."""
        return cls(r).add(r)

    def add(self, r: KinematicsResult) -> StreamSummary:
        """Fold in the next chunk (its frames numbered after the ones before)."""
        offset = self.frames
        self.frames += r.valid.size
        self.assembled += int(r.placed.sum())
        self.valid += int(r.valid.sum())
        self.chunks += 1
        if r.closure is not None:
            ok = r.closure.converged
            self.closure_iterations = max(self.closure_iterations, r.closure.iterations)
            if ok.any():
                self.closure_error = max(self.closure_error, float(r.closure.error[ok].max()))
        ch = r.checks
        if "link_lengths" in ch:
            e = ch["link_lengths"]["max_error"]
            self.link_error = e if self.link_error is None else max(self.link_error, e)
        if "analogs_vs_differences" in ch:
            e = ch["analogs_vs_differences"]["max_error"]
            self.analog_error = e if self.analog_error is None else max(self.analog_error, e)
        if "jacobian" in ch:
            self.near_singular += [offset + i for i in ch["jacobian"]["near_singular_frames"]]
        seen = set(self.warnings)
        self.warnings += [w for w in r.warnings if w not in seen]
        return self


def render_stream(s: StreamSummary, path: str | Path) -> str:
    """The text report of a sweep streamed to a CSV file (:func:`write_csv_chunks`)."""
    r = s.first_chunk
    name = r.mechanism.name or "mechanism"
    out = [
        f"kinematics of {name}: {s.frames} frames, drivers {', '.join(r.plan.drivers)}, "
        f"speed {r.speed:g}",
        f"table written to {path} in {s.chunks} chunk(s), each solved from the reference",
    ]
    out.append(f"plan ({r.plan.source}; solved in link {r.plan.reference}'s frame):")
    out += [f"  {line}" for line in r.plan.describe()]
    if r.closure is not None:
        out.append(
            f"closure: Newton, tolerance {r.closure.tol:g} (relative to size), at most "
            f"{s.closure_iterations} iteration(s) per chunk, achieved error "
            f"{s.closure_error:.3g}"
        )
    if s.link_error is not None:
        out.append(f"check link lengths: max error {s.link_error:.3g}")
    if s.analog_error is not None:
        out.append(f"check analogs vs five-point differences: max error {s.analog_error:.3g}")
    if s.link_error is not None:
        ns = s.near_singular
        shown = ", ".join(str(i) for i in ns[:10]) + (", ..." if len(ns) > 10 else "")
        out.append(f"check Jacobian: near-singular frames {shown or 'none'}")
    out += _closing_lines(s.assembled, s.valid, s.frames, s.warnings)
    return "\n".join(out)

"""Does pyslvs read what mjstruct writes?  A check for environments that have pyslvs.

pyslvs is never a dependency of mjstruct.  This script writes every shipped example
that a pyslvs expression can hold, has pyslvs parse it (``pyslvs.parse_vpoints``) and
compares joint by joint: kind, links, position, slot angle.  Where pyslvs can also
solve the linkage (``t_config``/``expr_solving`` with the input pairs of
``mjstruct.exchange.pyslvs.pyslvs_inputs``), it solves it twice: at the reference
input angle (positions must be the file's) and with the crank turned by 0.5 rad
(positions must be mjstruct's kinematics at q = 0.5), and prints the largest
distance of each.

pyslvs needs its own interpreter when it does not install beside mjstruct (on
Python 3.11 pyslvs 22.7.0 builds from source with Cython 3.0.0 and numpy < 2:
``pip install cython==3.0.0 "numpy<2" setuptools wheel`` then
``pip install --no-build-isolation pyslvs``)::

    python benchmarks/check_pyslvs.py                      # pyslvs importable here
    python benchmarks/check_pyslvs.py --python /path/to/python-with-pyslvs

Exit status: 0 all parsed alike (or pyslvs not found: says so), 1 a mismatch.
"""

from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
from pathlib import Path
from typing import Any

from mjstruct.errors import MechanismError
from mjstruct.exchange.pyslvs import (
    PyslvsJoint,
    mechanism_to_pyslvs,
    parse_pyslvs,
    pyslvs_inputs,
)
from mjstruct.io import read_mechanism
from mjstruct.mechanism import Mechanism

ROOT = Path(__file__).resolve().parents[1]

# runs under the interpreter that has pyslvs; reads a JSON list of [expr, inputs]
CHILD = r"""
import json, sys
from pyslvs import parse_vpoints
try:
    from pyslvs import t_config, expr_solving
except ImportError:
    t_config = expr_solving = None
jobs = json.load(sys.stdin)
out = []
for expr, inputs, angle_sets in jobs:
    vps = parse_vpoints(expr)
    row = {"points": [[list(v.links), ("R", "P", "RP")[int(v.type)], v.x, v.y, v.angle]
                      for v in vps]}
    if inputs and t_config is not None:
        row["solved"] = []
        try:
            pairs = [tuple(p) for p in inputs]
            exprs = t_config(vps, pairs)
            for angles in angle_sets:
                res = expr_solving(exprs, vps, {p: a for p, a in zip(pairs, angles)})
                row["solved"].append(
                    [list(c[1]) if isinstance(c[0], tuple) else list(c) for c in res]
                )
        except Exception as exc:
            row["solve_error"] = f"{exc.__class__.__name__}: {exc}"
    out.append(row)
json.dump(out, sys.stdout)
"""


TURN = 0.5  # rad: the second solve turns the crank this far from the reference

Job = tuple[str, str, list[list[int]], list[list[float]], list[list[tuple[float, float]]]]


def _expected(m: Mechanism, vps: list[PyslvsJoint]) -> list[list[tuple[float, float]]]:
    """Positions of every pyslvs point at the reference and at q = TURN (when known)."""
    ref = [vp.at for vp in vps]
    frame_cranks = all(
        m.joint(d).kind == "R" and m.joint(d).links[0] == m.frame for d in m.drivers
    )
    if not frame_cranks:
        return [ref]
    from mjstruct.kinematics.model import KinematicModel
    from mjstruct.kinematics.solver import kinematic_analysis

    model = KinematicModel.build(m)
    q = [float(v) + TURN for v in model.q_ref]  # q is the driver's angle, not its change
    result = kinematic_analysis(model, q=[q], checks=False)
    ids = [j.id for j in m.joints] + [p.id for p in m.points]
    table = {**result.joints, **result.points}
    turned = [(float(table[i]["x"][0]), float(table[i]["y"][0])) for i in ids]
    return [ref, turned]


def _jobs() -> list[Job]:
    jobs = []
    for path in sorted((ROOT / "catalogs" / "examples").glob("*.json")):
        m = read_mechanism(path)
        try:
            expr = mechanism_to_pyslvs(m)
        except MechanismError:
            continue
        try:
            inputs = [list(p) for p in pyslvs_inputs(m)]
        except MechanismError:
            inputs = []
        vps = parse_pyslvs(expr)
        angles = [
            math.degrees(math.atan2(vps[d].at[1] - vps[b].at[1], vps[d].at[0] - vps[b].at[0]))
            for b, d in inputs
        ]
        expected = _expected(m, vps) if inputs else []
        sets = [angles, [a + math.degrees(TURN) for a in angles]][: len(expected)]
        jobs.append((path.stem, expr, inputs, sets, expected))
    return jobs


def _run_pyslvs(python: str | None, payload: list[Any]) -> list[dict[str, Any]] | None:
    text = json.dumps(payload)
    if python is None:
        try:
            import pyslvs  # noqa: F401
        except ImportError:
            return None
        python = sys.executable
    proc = subprocess.run(
        [python, "-c", CHILD], input=text, capture_output=True, text=True, check=False
    )
    if proc.returncode != 0:
        last = (proc.stderr.strip().splitlines() or ["(no message)"])[-1]
        raise SystemExit(f"check_pyslvs: pyslvs failed: {last}")
    result: list[dict[str, Any]] = json.loads(proc.stdout)
    return result


def _gap(solved: list[list[float]], expected: list[tuple[float, float]]) -> str:
    # a solved slider may report its pin or its slot point: both are on the joint
    return f"{max(math.dist(tuple(c), e) for c, e in zip(solved, expected, strict=True)):.1e}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--python", help="an interpreter that has pyslvs installed")
    args = parser.parse_args()
    jobs = _jobs()
    got = _run_pyslvs(args.python, [[e, i, a] for _, e, i, a, _ in jobs])
    if got is None:
        print("check_pyslvs: pyslvs is not installed here (give --python); nothing checked")
        return 0
    bad = 0
    print(f"{'example':<30} {'joints':>6} {'parsed':>7} {'at ref':>9} {'q=0.5':>9}")
    for (name, expr, _, _, expected), row in zip(jobs, got, strict=True):
        mine = parse_pyslvs(expr)
        theirs = row["points"]
        same = len(mine) == len(theirs)
        for a, b in zip(mine, theirs, strict=False):
            angle = 0.0 if a.angle is None else a.angle
            same &= list(a.links) == b[0] and a.kind == b[1]
            same &= a.at == (b[2], b[3]) and (a.kind == "R" or math.isclose(angle, b[4]))
        gaps = ["-", "-"]
        if "solve_error" in row:
            gaps = ["unsolved", "unsolved"]
        for k, (solved, exp) in enumerate(zip(row.get("solved", []), expected, strict=False)):
            gaps[k] = _gap(solved, exp)
        bad += not same
        print(
            f"{name:<30} {len(mine):>6} {'same' if same else 'DIFFER':>7}"
            f" {gaps[0]:>9} {gaps[1]:>9}"
        )
        if "solve_error" in row:
            print(f"{'':<30} pyslvs could not solve it: {row['solve_error']}")
    print(f"{len(jobs) - bad} of {len(jobs)} expressions parsed by pyslvs as written")
    return 1 if bad else 0


if __name__ == "__main__":
    raise SystemExit(main())

"""How many random mechanisms the kinematics plans, closes at the reference, and moves.

Random one-DOF mechanisms grown from a crank by dyads, triads and class-IV groups, with
multiple joints and sliders (:func:`mjstruct.testing.random_mechanism`), each with a
random reference configuration in the unit square (:func:`mjstruct.testing.random_geometry`).
For every one the Assur decomposition accepts (its generic mobility equals the driver
count by construction), the benchmark counts:

* planned: ``KinematicModel.build`` gives a plan (triangles, closure unknowns or both);
* reference closed: the motion at the reference driver value assembles and puts every
  revolute centre back at its reference point (within 1e-9 of the size);
* moves: frames assembled on a short sweep of the driver around the reference (±3° in
  13 frames) -- a random geometry may sit near a dead position, so fewer than all is
  not a failure, but none at all beside the reference would be;
* the time per mechanism (plan and the short sweep), median.

Run: ``python benchmarks/bench_kinematics_completeness.py [--count N] [--max-groups G]``.
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.model import KinematicModel
from mjstruct.structure.assur import assur_groups
from mjstruct.testing import random_geometry, random_mechanism

#: half-width of the short sweep around the reference (radians) and its frames
SPAN, FRAMES = np.radians(3.0), 13


def one(groups: int, seed: int) -> dict[str, object]:
    m = random_geometry(random_mechanism(groups, seed=seed), seed)
    row: dict[str, object] = {"links": len(m.links), "accepted": False}
    try:
        assur_groups(m)
    except MechanismError:
        return row
    row["accepted"] = True
    t0 = time.perf_counter()
    try:
        model = KinematicModel.build(m)
    except MechanismError as exc:
        row.update(planned=False, why=str(exc))
        return row
    row["planned"] = True
    row["unknowns"] = model.plan.unknowns
    q0 = model.q_ref
    q = q0[None, :] + np.linspace(-SPAN, SPAN, FRAMES)[:, None]
    try:
        with np.errstate(all="ignore"):
            ref = model.motion(q0[None, :])
            sweep = model.motion(q)
    except (MechanismError, NumericalError) as exc:
        row.update(closed=False, why=str(exc))
        return row
    row["seconds"] = time.perf_counter() - t0
    gap = max(
        abs(complex(ref.centre(j.id)[0][0]) - complex(*j.at)) for j in m.joints if j.kind == "R"
    )
    row["closed"] = bool(ref.valid.all()) and gap <= 1e-9 * model.scale
    row["moved"] = int(sweep.valid.sum())
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=60, help="random mechanisms")
    ap.add_argument("--max-groups", type=int, default=20, help="Assur groups at most")
    args = ap.parse_args()
    rng = np.random.default_rng(2026)
    rows = []
    for seed in range(args.count):
        rows.append(one(int(rng.integers(1, args.max_groups + 1)), seed))
        print(f"\r{seed + 1}/{args.count} mechanisms", end="", flush=True)
    print()
    acc = [r for r in rows if r["accepted"]]
    planned = [r for r in acc if r.get("planned")]
    closed = [r for r in planned if r.get("closed")]
    moved = [r for r in closed if int(r["moved"]) > 1]  # type: ignore[call-overload]
    whole = [r for r in closed if r["moved"] == FRAMES]
    links = [int(r["links"]) for r in acc]  # type: ignore[call-overload]
    iterated = sum(1 for r in planned if int(r["unknowns"]) > 0)  # type: ignore[call-overload]
    print(
        f"{len(rows)} random mechanisms, {min(links)} to {max(links)} links "
        f"(median {statistics.median(links):.0f}); accepted by the decomposition: {len(acc)}"
    )
    print(f"  planned                       {len(planned):4d} / {len(acc)}")
    print(f"    of which with closure unknowns {iterated:4d}")
    print(f"  reference closed (1e-9)       {len(closed):4d} / {len(planned)}")
    print(f"  assembled beside the reference {len(moved):4d} / {len(closed)}")
    print(f"  all {FRAMES} frames of ±3°          {len(whole):4d} / {len(closed)}")
    secs = [float(r["seconds"]) for r in closed]  # type: ignore[arg-type]
    print(f"  plan + 14 frames, median      {statistics.median(secs) * 1e3:8.1f} ms")
    for r in acc:
        if not r.get("planned") or not r.get("closed"):
            print(f"  FAILED ({r['links']} links): {r.get('why', 'reference not reproduced')}")


if __name__ == "__main__":
    main()

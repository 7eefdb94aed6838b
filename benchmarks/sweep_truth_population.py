"""Full-turn kinematics sweeps of a random population against the independent oracle.

Mechanism ``s`` is ``sweep_truth.population(s)`` (tests/sweep_truth.py): 1 to 4 Assur
groups (dyads, triads, class IV) on a crank, multiple joints, sliders on 10% or 30% of
the new external joints (triads with slider legs), half of them with groups hanging on
one link, a random reference in the unit square.  Each one the kinematics plans is swept
over one turn in ``--frames`` frames with the driver turning both ways (speed +1 and
−1), and compared with the frames the independent continuation of
``tests/full_system_continuation.py`` reaches from the reference either way round.
Four kinds of defect are counted per mechanism and direction:

* ``missed``: a frame the oracle reaches, not returned (or returned elsewhere), or a
  "closure stops … Jacobian is regular" warning between frames the oracle reaches;
* ``unreached``: a frame returned as reached that no motion from the reference reaches;
* ``json``: the JSON object is not strict JSON;
* ``flood``: more than ``sweep_truth.FLOOD`` warnings of one kind for one joint.

``--near-fold`` moves each reference 1e-4 rad inside the first fold the oracle meets
(mechanisms that turn fully are left out then).  ``--workers 2`` uses two processes.
Progress goes to stderr; one line per mechanism with a defect and the totals to stdout.

Run: ``python benchmarks/sweep_truth_population.py [--start S] [--count N] [--frames F]
[--near-fold] [--workers W]``.
"""

from __future__ import annotations

import argparse
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.model import KinematicModel
from mjstruct.structure.assur import assur_groups
from sweep_truth import defects, near_fold, population, turn_reach


def one(seed: int, frames: int, fold: bool) -> tuple[int, str, list[str]]:
    """Seed, status ("planned", "not planned", "turns fully", "oracle failed") and the
    defects found both ways (each "speed ±1: kind (frame i): text")."""
    m = population(seed)
    try:
        if fold:
            moved = near_fold(m, 1e-4)
            if moved is None:
                return seed, "turns fully", []
            m = moved
        assur_groups(m)
        KinematicModel.build(m)
    except (MechanismError, NumericalError):
        return seed, "not planned", []
    try:
        truth = turn_reach(m, frames)
    except (ValueError, ArithmeticError) as exc:
        return seed, f"oracle failed: {exc}", []
    found = []
    for w in (1.0, -1.0):
        try:
            found += [f"speed {w:+g}: {d}" for d in defects(m, frames, w, truth)]
        except Exception as exc:  # an internal error is a defect of its own
            found.append(f"speed {w:+g}: raised ({type(exc).__name__}: {exc})")
    return seed, "planned", found


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--start", type=int, default=0)
    ap.add_argument("--count", type=int, default=100)
    ap.add_argument("--frames", type=int, default=72)
    ap.add_argument("--near-fold", action="store_true")
    ap.add_argument("--workers", type=int, default=1)
    a = ap.parse_args(argv)
    seeds = range(a.start, a.start + a.count)
    t0 = time.perf_counter()
    status: Counter[str] = Counter()
    kinds: Counter[str] = Counter()
    bad = 0
    with ProcessPoolExecutor(a.workers) as pool:
        jobs = [pool.submit(one, s, a.frames, a.near_fold) for s in seeds]
        for n, job in enumerate(jobs, 1):
            seed, st, found = job.result()
            status[st.split(":")[0]] += 1
            if found:
                bad += 1
                mech_kinds = sorted({f.split(": ", 1)[1].split(" ")[0] for f in found})
                kinds.update(mech_kinds)
                print(f"seed {seed}: {len(found)} defect(s) {mech_kinds}; {found[0][:150]}")
            if sys.stderr.isatty():
                sys.stderr.write(f"\r{n}/{len(jobs)} {time.perf_counter() - t0:.0f} s")
    if sys.stderr.isatty():
        sys.stderr.write("\n")
    print(
        f"{len(seeds)} seeds ({a.frames} frames a turn, both ways"
        f"{', reference 1e-4 rad from a fold' if a.near_fold else ''}): "
        + ", ".join(f"{k} {v}" for k, v in sorted(status.items()))
    )
    print(f"mechanisms with a defect: {bad}; by kind: {dict(sorted(kinds.items()))}")
    print(f"time {time.perf_counter() - t0:.0f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""How many random mechanisms the kinematics plans, closes at the reference, and moves.

Random one-DOF mechanisms grown from a crank by dyads, triads and class-IV groups, with
multiple joints and sliders (:func:`mjstruct.testing.random_mechanism`), each with a
random reference configuration in the unit square (:func:`mjstruct.testing.random_geometry`).
Mechanism ``s`` (``s = 0 .. count - 1``) is ``random_geometry(random_mechanism(g, seed=s), s)``
with its group count ``g`` the ``s + 1``-th draw of
``np.random.default_rng(2026).integers(1, max_groups + 1)`` (one draw per mechanism).
For every one the Assur decomposition accepts (its generic mobility equals the driver
count by construction), the benchmark counts:

* planned: ``KinematicModel.build`` gives a plan (triangles, closure unknowns or both);
* reference closed: the motion at the reference driver value alone assembles and puts
  every revolute centre back at its reference point (within 1e-9 of the size);
* moves: frames assembled on a short sweep of the driver around the reference (±3° in
  13 frames, one path through the reference) -- a random geometry may sit near a dead
  position, so fewer than all is not a failure, but none beside the reference would be;
* the time per mechanism (plan, the reference frame and the short sweep): the median,
  the total, and the slowest mechanisms by seed, with their links and closure unknowns;
* with ``--oracle``, the independent continuation of ``tests/full_system_continuation.py``
  (every link's constraints at once, no Assur decomposition, the driver stepped from the
  reference in small adaptive steps both ways, stopping at a fold): the share of the
  frames it reaches that the sweep returns at the same joint centres (1e-9 of the size;
  goal 100%), the frames the sweep misses or places elsewhere, and the frames the sweep
  returns beyond the continuation's stop (only past a frame that does not assemble, which
  the sweep reports; joined to the reference's run they would be another branch).

``--span DEG`` and ``--frames N`` widen the sweep (default ±3° in 13 frames).

Progress (the mechanism being solved, the elapsed time) goes to stderr when it is a
terminal; the results go to stdout.

Run: ``python benchmarks/bench_kinematics_completeness.py [--count N] [--max-groups G]
[--slowest K] [--span DEG] [--frames N] [--oracle]``.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from full_system_continuation import FullSystem, reach
from mjstruct.errors import MechanismError, NumericalError
from mjstruct.kinematics.model import KinematicModel, Motion
from mjstruct.mechanism import Mechanism
from mjstruct.structure.assur import assur_groups
from mjstruct.testing import random_geometry, random_mechanism

#: half-width of the short sweep around the reference (radians) and its frames
SPAN, FRAMES = np.radians(3.0), 13
#: seed of the group counts' generator
GROUPS_SEED = 2026


@dataclass
class Row:
    """What one random mechanism gave.

    Attributes
    ----------
    seed, groups, links : the mechanism's seed, Assur group count and link count.
    accepted : the Assur decomposition accepts it.
    planned : ``KinematicModel.build`` planned it.
    unknowns : closure unknowns of the plan.
    closed : the reference frame assembles at the reference configuration.
    moved : frames of the short sweep that assemble (the reference's included).
    beside : some frame of the short sweep other than the reference assembles.
    seconds : plan, reference frame and short sweep (None when one of them raised).
    why : the error, for a mechanism not planned or whose motion raised.
    """

    seed: int
    groups: int
    links: int
    accepted: bool = False
    planned: bool = False
    unknowns: int = 0
    closed: bool = False
    moved: int = 0
    beside: bool = False
    seconds: float | None = None
    why: str = ""
    #: with the oracle: frames it reached, of them returned at its positions, missed,
    #: placed elsewhere; frames returned beyond its stop past a gap, and joined to the
    #: reference's run
    reached: int = 0
    same: int = 0
    missed: int = 0
    elsewhere: int = 0
    past_gap: int = 0
    joined: int = 0


def group_counts(count: int, max_groups: int) -> list[int]:
    """Assur group counts of mechanisms ``0 .. count - 1`` (one draw each, in order)."""
    rng = np.random.default_rng(GROUPS_SEED)
    return [int(rng.integers(1, max_groups + 1)) for _ in range(count)]


def one(
    groups: int, seed: int, span: float = SPAN, frames: int = FRAMES, oracle: bool = False
) -> Row:
    """Plan random mechanism ``seed`` of ``groups`` groups, close it and sweep it.

    Parameters
    ----------
    groups : Assur groups grown on the crank.
    seed : seed of the mechanism and of its reference geometry.
    span, frames : the sweep, ``frames`` frames over ±``span`` rad around the reference.
    oracle : also count the frames against the independent continuation.

    Returns
    -------
    Row
        the counts of the module docstring for this mechanism.
    """
    m = random_geometry(random_mechanism(groups, seed=seed), seed)
    row = Row(seed=seed, groups=groups, links=len(m.links))
    try:
        assur_groups(m)
    except MechanismError:
        return row
    row.accepted = True
    t0 = time.perf_counter()
    try:
        model = KinematicModel.build(m)
    except (MechanismError, NumericalError) as exc:
        row.why = f"not planned: {exc}"
        return row
    row.planned = True
    row.unknowns = model.plan.unknowns
    q0 = model.q_ref
    q = q0[None, :] + np.linspace(-span, span, frames)[:, None]
    try:
        with np.errstate(all="ignore"):
            ref = model.motion(q0[None, :])
            sweep = model.motion(q)
    except (MechanismError, NumericalError) as exc:
        row.why = f"motion raised: {exc}"
        return row
    row.seconds = time.perf_counter() - t0
    gap = max(
        abs(complex(ref.centre(j.id)[0][0]) - complex(*j.at)) for j in m.joints if j.kind == "R"
    )
    row.closed = bool(ref.valid.all()) and gap <= 1e-9 * model.scale
    if not row.closed:
        row.why = f"reference not reproduced (gap {gap / model.scale:.3g} of the size)"
    row.moved = int(sweep.valid.sum())
    row.beside = bool(np.delete(sweep.valid, frames // 2).any())
    if oracle and len(model.drivers) == 1 and m.joint(model.drivers[0]).kind == "R":
        compare(row, m, model.scale, q[:, 0], sweep)
    return row


def compare(
    row: Row, m: Mechanism, size: float, q: npt.NDArray[np.float64], sweep: Motion
) -> None:
    """Count the sweep's frames against the independent continuation's (in ``row``)."""
    got = reach(FullSystem(m), q)
    row.reached = len(got)
    for i, r in got.items():
        if not sweep.valid[i]:
            row.missed += 1
            continue
        err = max(abs(complex(sweep.centre(j)[0][i]) - z) for j, z in r.joints.items())
        if err <= 1e-9 * size:
            row.same += 1
        else:
            row.elsewhere += 1
    mid = q.size // 2
    for i in np.flatnonzero(sweep.valid):
        if int(i) not in got:
            run = sweep.valid[min(i, mid) : max(i, mid) + 1]
            row.joined += int(run.all())
            row.past_gap += int(not run.all())


def report(rows: list[Row], slowest: int, frames: int = FRAMES, span: float = SPAN) -> None:
    """Print the counts, the times and the mechanisms that failed."""
    acc = [r for r in rows if r.accepted]
    planned = [r for r in acc if r.planned]
    closed = [r for r in planned if r.closed]
    beside = [r for r in closed if r.beside]
    whole = [r for r in closed if r.moved == frames]
    links = [r.links for r in rows]
    iterated = sum(1 for r in planned if r.unknowns > 0)
    print(
        f"{len(rows)} random mechanisms, {min(links)} to {max(links)} links "
        f"(median {statistics.median(links):.0f}); accepted by the decomposition: {len(acc)}"
    )
    spans = f"±{np.degrees(span):g}°"
    for label, n, of in (
        ("planned", len(planned), len(acc)),
        ("  of which with closure unknowns", iterated, len(planned)),
        ("reference closed (1e-9)", len(closed), len(planned)),
        ("assembled beside the reference", len(beside), len(closed)),
        (f"all {frames} frames of {spans}", len(whole), len(closed)),
    ):
        print(f"  {label:<33}{n:4d} / {of}")
    timed = [(r.seconds, r) for r in planned if r.seconds is not None]
    if timed:
        secs = [t for t, _ in timed]
        print(
            f"  plan + {frames + 1} frames per mechanism: median "
            f"{statistics.median(secs) * 1e3:.1f} ms, total {sum(secs):.1f} s"
        )
        print("  slowest:")
        for t, r in sorted(timed, key=lambda x: -x[0])[:slowest]:
            print(
                f"    seed {r.seed:3d}: {t:6.2f} s  ({r.groups} groups, {r.links} links, "
                f"{r.unknowns} closure unknowns, {r.moved}/{frames} frames)"
            )
    checked = [r for r in closed if r.reached]
    if checked:
        reached = sum(r.reached for r in checked)
        same = sum(r.same for r in checked)
        print(
            f"  independent continuation: {same} of {reached} frames it reaches returned at "
            f"its positions ({100.0 * same / reached:.1f}%; goal 100%) on {len(checked)} "
            "mechanisms"
        )
        print(
            f"    missed {sum(r.missed for r in checked)}, placed elsewhere "
            f"{sum(r.elsewhere for r in checked)}; returned beyond its stop: past a gap "
            f"{sum(r.past_gap for r in checked)}, joined to the reference's run "
            f"{sum(r.joined for r in checked)}"
        )
        for r in checked:
            if r.missed or r.elsewhere or r.joined:
                print(
                    f"    seed {r.seed}: missed {r.missed}, elsewhere {r.elsewhere}, "
                    f"joined {r.joined} of {r.reached}"
                )
    for r in acc:
        if r.why:
            print(f"  FAILED seed {r.seed} ({r.links} links): {r.why}")


def main() -> None:
    """Run the benchmark on the mechanisms the command line asks for."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=60, help="random mechanisms")
    ap.add_argument("--max-groups", type=int, default=20, help="Assur groups at most")
    ap.add_argument("--slowest", type=int, default=5, help="slowest mechanisms listed")
    ap.add_argument("--span", type=float, default=np.degrees(SPAN), help="half sweep (deg)")
    ap.add_argument("--frames", type=int, default=FRAMES, help="frames of the sweep")
    ap.add_argument("--oracle", action="store_true", help="check against the continuation")
    args = ap.parse_args()
    if args.count < 1 or args.max_groups < 1 or args.frames < 2 or not args.span > 0:
        ap.error("--count and --max-groups must be at least 1, --frames 2, --span positive")
    span = float(np.radians(args.span))
    tty = sys.stderr.isatty()
    start = time.perf_counter()
    rows = []
    for seed, groups in enumerate(group_counts(args.count, args.max_groups)):
        if tty:
            elapsed = time.perf_counter() - start
            print(
                f"\r\033[Kmechanism {seed + 1}/{args.count} (seed {seed}, {groups} groups), "
                f"{elapsed:.0f} s elapsed",
                end="",
                file=sys.stderr,
                flush=True,
            )
        rows.append(one(groups, seed, span, args.frames, args.oracle))
    if tty:
        print("\r\033[K", end="", file=sys.stderr, flush=True)
    report(rows, args.slowest, args.frames, span)
    print(f"  wall time {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    main()

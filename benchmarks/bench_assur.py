"""Benchmark: Assur decomposition and pebble-game rank against the project's time budgets.

Prints, for each case, the median wall time over several runs, its budget (the targets
in docs/assur.md) and the ratio median / budget (< 1 is within budget), and next to the
pebble game the numeric rank of the constraint Jacobian at random geometry (numpy SVD)
on the same chain, measured in the same run.

Run: ``python benchmarks/bench_assur.py`` (``--no-numeric`` skips the slow SVD at 1000
links).
"""

from __future__ import annotations

import argparse
import random
import sys

import numpy as np

from mjstruct.catalog_files import example_path
from mjstruct.io import read_mechanism
from mjstruct.mechanism import Mechanism
from mjstruct.structure.assur import assur_groups
from mjstruct.structure.drivers import validate_drivers
from mjstruct.structure.generic_mobility import generic_mobility
from mjstruct.structure.pebble import pebble_rank
from mjstruct.testing import random_mechanism, shared_crank
from timing import median_time


def mechanism_with_links(n_links: int, seed: int = 1, mj: float = 0.3) -> Mechanism:
    """A random one-DOF mechanism of at least ``n_links`` links, grown group by group."""
    groups = max(1, n_links // 3)
    while True:
        m = random_mechanism(groups, seed=seed, mj=mj)
        if m.n >= n_links:
            return m
        groups += max(1, (n_links - m.n) // 3)


def random_graph_chain(n_links: int, pins: int, seed: int = 0) -> Mechanism:
    """A connected chain of random pins (a random tree plus random extra pins)."""
    rng = random.Random(seed)
    joints = [(f"t{k}", [str(rng.randrange(k)), str(k)]) for k in range(1, n_links)]
    while len(joints) < pins:
        a, b = rng.sample(range(n_links), 2)
        joints.append((f"r{len(joints)}", [str(a), str(b)]))
    return Mechanism.build(joints, frame="0")


def jacobian_rank(m: Mechanism, seed: int = 0) -> int:
    """Rank of the velocity constraints at random pin positions and slide axes."""
    rng = np.random.default_rng(seed)
    col = {x: 3 * k for k, x in enumerate(m.links)}
    rows = []
    for j in m.joints:
        p = rng.normal(size=2)
        axis = rng.normal(size=2)
        normal = np.array([-axis[1], axis[0]])
        hub = j.links[0]
        for other in j.links[1:]:
            dirs = [np.array([1.0, 0.0]), np.array([0.0, 1.0])] if j.kind == "R" else [normal]
            for u in dirs:
                row = np.zeros(3 * m.n)
                for link, s in ((hub, 1.0), (other, -1.0)):
                    c = col[link]
                    row[c : c + 3] += s * np.array([u[0], u[1], u[1] * p[0] - u[0] * p[1]])
                rows.append(row)
            if j.kind == "P":
                row = np.zeros(3 * m.n)
                row[col[hub] + 2], row[col[other] + 2] = 1.0, -1.0
                rows.append(row)
    return int(np.linalg.matrix_rank(np.array(rows)))


def line(case: str, median: float, budget: float | None, note: str = "") -> None:
    ratio = f"{median / budget:6.3f}" if budget else "     -"
    b = f"{budget * 1e3:8.1f}" if budget else "       -"
    print(f"{case:<46} {median * 1e3:10.2f} {b} {ratio}  {note}")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--no-numeric", action="store_true", help="skip the SVD at 1000 links")
    args = ap.parse_args(argv)
    print(f"python {sys.version.split()[0]}, numpy {np.__version__}")
    print(f"{'case':<46} {'median ms':>10} {'budget':>8} {'ratio':>6}  note")

    m24 = read_mechanism(example_path("seed002-ex5-24-link"))
    t, d = median_time(lambda: assur_groups(m24), 51)
    line(
        "assur_groups, 24-link example ([MJ structure 2020], ex. 5)",
        t,
        0.020,
        f"class {d.mechanism_class}",
    )

    m200 = mechanism_with_links(200)
    mjs = sum(j.is_multiple for j in m200.joints)
    t, d = median_time(lambda: assur_groups(m200), 7)
    line(
        f"assur_groups, random {m200.n} links ({mjs} MJs)",
        t,
        2.0,
        f"{len(d.groups)} groups, class {d.mechanism_class}",
    )
    t, r = median_time(lambda: pebble_rank(m200), 7)
    line(f"pebble_rank, same {m200.n}-link chain", t, None, f"rank {r}")
    t, nr = median_time(lambda: jacobian_rank(m200), 3)
    line("  numeric Jacobian rank (SVD), same chain", t, None, f"rank {nr}")

    m1000 = mechanism_with_links(1000)
    mjs = sum(j.is_multiple for j in m1000.joints)
    t, r = median_time(lambda: pebble_rank(m1000), 7)
    line(f"pebble_rank, random {m1000.n}-link chain ({mjs} MJs)", t, 2.0, f"rank {r}")
    t_pebble = t
    t, g = median_time(lambda: generic_mobility(m1000), 5)
    line("generic_mobility (rank + rigid parts), same", t, None, f"F_generic {g.F_generic}")
    t_assur, d = median_time(lambda: assur_groups(m1000), 3)
    line("assur_groups, same chain", t_assur, None, f"{len(d.groups)} groups")
    t, _ = median_time(lambda: validate_drivers(m1000), 5)
    line("  its driver check (validate_drivers)", t, None, f"{t / t_assur:.0%} of it")
    crank = shared_crank(499)  # one multiple joint of 500 links, a dyad on each coupler
    t, d = median_time(lambda: assur_groups(crank), 5)
    line(
        f"assur_groups, {len(d.groups)} four-bars on one crank ({crank.n} links)",
        t,
        None,
        f"{t / crank.n * 1e6:.1f} us per link",
    )
    mg = random_graph_chain(1000, 1499)
    t, r = median_time(lambda: pebble_rank(mg), 7)
    g = generic_mobility(mg)
    line(
        "pebble_rank, random-graph chain 1000 links/1499 pins",
        t,
        2.0,
        f"rank {r}, F {g.F_formula} -> F_generic {g.F_generic}",
    )
    if not args.no_numeric:
        t, nr = median_time(lambda: jacobian_rank(m1000), 1)
        line(
            f"numeric Jacobian rank (SVD), the {m1000.n}-link chain with MJs",
            t,
            None,
            f"rank {nr}",
        )
        print(f"pebble game / SVD time ratio at {m1000.n} links: {t_pebble / t:.4f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

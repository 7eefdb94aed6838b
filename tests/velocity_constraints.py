"""An independent reference for rigidity: the velocity-constraint matrix of a chain at
random pin positions and slide axes (its numeric rank is the generic rank the pebble
game must match)."""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from mjstruct.mechanism import Joint, Mechanism


def constraint_rows(
    m: Mechanism,
    rng: np.random.Generator,
    fixed: Iterable[str] = (),
    drivers: Iterable[str] = (),
    joints: Iterable[Joint] | None = None,
) -> np.ndarray:
    """Velocity constraints of the chain at random pin positions and slide axes.

    Unknowns: (vx, vy, ω) of every link not in ``fixed`` (fixed links do not move).
    """
    fixed = set(fixed)
    col: dict[str, int] = {}
    for link in m.links:
        if link not in fixed:
            col[link] = 3 * len(col)
    width = 3 * len(col)
    rows: list[np.ndarray] = []

    def point_row(a: str, b: str, p: np.ndarray, u: np.ndarray) -> np.ndarray:
        """u · (velocity of point p on a - on b)."""
        row = np.zeros(width)
        for link, sign in ((a, 1.0), (b, -1.0)):
            if link in col:
                c = col[link]
                row[c : c + 3] += sign * np.array([u[0], u[1], u[1] * p[0] - u[0] * p[1]])
        return row

    def spin_row(a: str, b: str) -> np.ndarray:
        row = np.zeros(width)
        for link, sign in ((a, 1.0), (b, -1.0)):
            if link in col:
                row[col[link] + 2] += sign
        return row

    geometry = {}
    for j in m.joints if joints is None else joints:
        p = rng.normal(size=2)
        axis = rng.normal(size=2)
        axis /= np.linalg.norm(axis)
        normal = np.array([-axis[1], axis[0]])
        geometry[j.id] = (p, axis)
        hub = j.links[0]
        for other in j.links[1:]:
            if j.kind == "R":
                rows.append(point_row(hub, other, p, np.array([1.0, 0.0])))
                rows.append(point_row(hub, other, p, np.array([0.0, 1.0])))
            else:
                rows.append(spin_row(hub, other))
                rows.append(point_row(hub, other, p, normal))
    for d in drivers:
        j = m.joint(d)
        a, b = j.links[:2]
        if j.kind == "R":
            rows.append(spin_row(a, b))
        else:
            p, axis = geometry[d]
            rows.append(point_row(a, b, p, axis))
    return np.array(rows).reshape(len(rows), width)

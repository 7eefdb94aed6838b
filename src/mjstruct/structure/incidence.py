"""The signed incidence matrix of [Panasenko 2025] (links × simple-joint equivalents)
and the joint kinds H (1 revolute, 2 prismatic).

Column k has −1 on the first listed link of the joint and +1 on the other (Newton's
third law; the paper puts + on the link whose reaction it draws), so every column sums
to 0 when the frame row is included.  A multiple joint with links (a, b, c, ...) is
expanded into the simple joints (a, b), (a, c), ...: the first listed link carries the
pin and each other link is pinned to it.  Columns of an MJ are named ``A``, ``A/2``,
``A/3`` ...

References
----------
.. [1] A. N. Panasenko, "Practical implementation…" (in Russian; the available copy
   gives only this beginning of the title), Systems. Methods. Technologies,
   no. 2 (66), pp. 32–42, 2025. [Panasenko 2025] in docs/references.md.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> m = Mechanism.build([("O1", [0, 1]), ("O2", [1, 2]), ("O3", [2, 3]), ("O4", [3, 0], "P")])
>>> inc = incidence_matrix(m)
>>> inc.matrix.tolist(), inc.H.tolist()
([[-1, 0, 0, 1], [1, -1, 0, 0], [0, 1, -1, 0], [0, 0, 1, -1]], [1, 1, 1, 2])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mjstruct.mechanism import Mechanism, expect_mechanism


@dataclass(frozen=True)
class IncidenceMatrix:
    links: tuple[str, ...]
    columns: tuple[str, ...]
    joints: tuple[str, ...]  # the joint each column comes from
    matrix: np.ndarray
    H: np.ndarray

    def moving(self, frame: str) -> np.ndarray:
        """The block K[j, k] of the moving links (frame row removed)."""
        keep = [i for i, link in enumerate(self.links) if link != frame]
        return self.matrix[keep]


def incidence_matrix(m: Mechanism) -> IncidenceMatrix:
    """Signed incidence of links and simple-joint equivalents (rows in ``m.links`` order)."""
    expect_mechanism(m)
    row = {link: i for i, link in enumerate(m.links)}
    cols: list[tuple[str, str, int, int]] = []  # name, joint, carrier row, other row
    for j in m.joints:
        for k, other in enumerate(j.links[1:], start=1):
            name = j.id if k == 1 else f"{j.id}/{k}"
            cols.append((name, j.id, row[j.links[0]], row[other]))
    mat = np.zeros((len(m.links), len(cols)), dtype=int)
    for c, (_, _, first_row, other_row) in enumerate(cols):
        mat[first_row, c] = -1
        mat[other_row, c] = 1
    kinds = {j.id: (2 if j.kind == "P" else 1) for j in m.joints}
    return IncidenceMatrix(
        links=m.links,
        columns=tuple(c[0] for c in cols),
        joints=tuple(c[1] for c in cols),
        matrix=mat,
        H=np.array([kinds[c[1]] for c in cols], dtype=int),
    )

"""The results of an Assur-group decomposition and their plain-text rendering.

This module owns :class:`AssurGroup`, :class:`Decomposition` and
:class:`DriverChoice` (frozen, with ``to_dict`` for the JSON contract) and the Roman
numerals of Artobolevsky's classes.

Examples
--------
>>> roman(4), roman(12)
('IV', '12')
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

ROMAN = {1: "I", 2: "II", 3: "III", 4: "IV", 5: "V", 6: "VI", 7: "VII", 8: "VIII", 9: "IX"}


def roman(k: int) -> str:
    """Roman numeral of a class (falls back to digits beyond IX)."""
    return ROMAN.get(k, str(k))


@dataclass(frozen=True)
class AssurGroup:
    """One minimal Assur group, in the honest MJ form.

    ``links`` are the links the group places (owned; the groups and initial
    mechanisms partition the moving links); ``bodies`` are the rigid bodies it moves,
    each as all its links (a body can be a link welded by a driver or a rigid cluster
    solved earlier); ``external`` joints attach it to links already placed and
    ``internal`` joints join its own bodies.  ``reference`` is the link in whose frame
    the group is solved (the frame, or a link of the rigid cluster ``within``).
    """

    links: tuple[str, ...]
    joints: tuple[str, ...]
    external: tuple[str, ...]
    klass: int
    order: int
    reference: str
    internal: tuple[str, ...] = ()
    bodies: tuple[tuple[str, ...], ...] = ()
    within: tuple[str, ...] = ()
    pairs: int = 0  # simple-joint equivalents, external pins included (3 n_g = 2 p_g)

    def to_dict(self) -> dict[str, Any]:
        return {
            "links": list(self.links),
            "joints": list(self.joints),
            "class": self.klass,
            "order": self.order,
            "external": list(self.external),
            "internal": list(self.internal),
            "reference": self.reference,
            "bodies": [list(b) for b in self.bodies],
            "within": list(self.within),
            "pairs": self.pairs,
        }


@dataclass(frozen=True)
class Decomposition:
    """Initial mechanisms and Assur groups in solving order; see ``assur_groups``."""

    frame: str
    drivers: tuple[str, ...]
    initial: tuple[tuple[str, str, str], ...]
    groups: tuple[AssurGroup, ...]
    mechanism_class: int
    name: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "frame": self.frame,
            "drivers": list(self.drivers),
            "initial": [{"driver": d, "base": a, "driven": b} for d, a, b in self.initial],
            "groups": [g.to_dict() for g in self.groups],
            "mechanism_class": self.mechanism_class,
        }

    def render(self) -> str:
        """Plain text for a course report."""
        title = f" of {self.name}" if self.name else ""
        lines = [
            f"Assur-group decomposition{title}",
            f"frame: link {self.frame}; drivers: {', '.join(self.drivers) or '(none)'}",
            "",
            "Initial mechanism(s):",
        ]
        for d, a, b in self.initial:
            base = f"the frame {a}" if a == self.frame else f"link {a}"
            lines.append(f"  {d}: link {b} driven relative to {base}")
        lines.append("")
        lines.append("Assur groups, in solving order:")
        for k, g in enumerate(self.groups, 1):
            kind = {2: "dyad"}.get(len(g.bodies), f"{len(g.bodies)} bodies")
            lines.append(
                f"  {k}. class {roman(g.klass)}, order {g.order} ({kind}): "
                f"links {', '.join(g.links)}"
            )
            welded = [b for b in g.bodies if len(b) > 1]
            if welded:
                lines.append(
                    "     moving as bodies: " + "; ".join("{" + ", ".join(b) + "}" for b in welded)
                )
            lines.append(
                f"     external joints: {', '.join(g.external)}; "
                f"internal joints: {', '.join(g.internal) or '-'}"
            )
            if g.reference == self.frame:
                lines.append(f"     solved relative to the frame {self.frame}")
            else:
                lines.append(
                    f"     solved in the frame of link {g.reference}, inside the rigid "
                    f"cluster {{{', '.join(g.within)}}}"
                )
        lines.append("")
        lines.append(f"Mechanism class: {roman(self.mechanism_class)} ({self.mechanism_class})")
        return "\n".join(lines)


@dataclass(frozen=True)
class DriverChoice:
    """One choice of driven joints and what it gives.

    ``status`` is ``"ok"``, ``"under-driven"`` (``dof_left`` > 0), ``"over-driven"``
    (``redundant`` > 0) or ``"over- and under-driven"``.
    """

    drivers: tuple[str, ...]
    status: str
    mechanism_class: int | None
    decomposition: Decomposition | None
    dof_left: int = 0
    redundant: int = 0

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "drivers": list(self.drivers),
            "status": self.status,
            "mechanism_class": self.mechanism_class,
            "dof_left": self.dof_left,
            "redundant": self.redundant,
        }
        if self.decomposition is not None:
            d = self.decomposition.to_dict()
            out["initial"] = d["initial"]
            out["groups"] = d["groups"]
        return out

"""The structural report: every structural quantity, as the JSON object of
docs/contract.md and as the bullet list of [MJ structure 2020] with both formulas shown.

:func:`structural_report` works on a mechanism (graph known) and
:func:`code_report` on a structural code alone (assortments known).  Both fill one
:class:`StructuralReport`; only the graph path can give [L] and the canonical code.

Examples
--------
>>> r = code_report("[8110]/[3·0·0]", dof=1, N=1)
>>> r.K, r.F, r.S_L, r.rc, r.violations
(4, 1, 23, 0, [])
>>> code_report("[8110]/3", dof=2).violations[0]
'AVC = -1 != 0: no closed chain with K = 3.5 has this code'
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

from mjstruct.mechanism import Mechanism, expect_mechanism
from mjstruct.structure import mobility as mob
from mjstruct.structure.assortments import Assortment, assortment, simple_joint_count
from mjstruct.structure.codes import full_code, parse_code, structural_code
from mjstruct.structure.generic_mobility import GenericMobility, generic_mobility


def _num(x: Fraction | int) -> int | float:
    x = Fraction(x)
    return x.numerator if x.denominator == 1 else float(x)


@dataclass
class StructuralReport:
    """All structural quantities of one chain, mechanism or code."""

    name: str
    assortment: Assortment
    K_values: dict[str, Fraction | int]  # "formula", and "cycle_rank"/"euler" or "dof"
    N: int
    lam: int = 3
    p: int | None = None
    F_values: dict[str, Fraction | int] = field(default_factory=dict)
    loops: tuple[int, ...] | None = None
    loops_rule: str | None = None
    loops_note: str | None = None
    canonical: str | None = None
    canonical_mechanism: str | None = None
    source: str = "graph"
    mja_known: bool = True  # a code "[LA]/V" does not say which multiplicities make up V
    generic: GenericMobility | None = None  # pebble-game mobility (graph input only)
    violations: list[str] = field(default_factory=list)

    @property
    def K(self) -> int | float:
        """K used for everything else: the graph's cycle rank, else from the DOF, else formula."""
        for key in ("cycle_rank", "dof", "formula"):
            if key in self.K_values:
                return _num(self.K_values[key])
        raise KeyError("K")

    @property
    def F(self) -> int | float:
        return _num(self.F_values["loops"])

    @property
    def rc(self) -> int | float:
        return _num(mob.redundant_constraints(self.N, Fraction(self.F)))

    @property
    def S_L(self) -> int:
        return mob.side_sum(self.assortment)

    @property
    def AVC(self) -> int | float:
        return _num(mob.avc(self.assortment, Fraction(self.K)))

    @property
    def code(self) -> str | None:
        K = self.K
        return structural_code(self.assortment, K) if isinstance(K, int) else None

    @property
    def code_star(self) -> str | None:
        K = self.K
        if not self.mja_known or not isinstance(K, int):
            return None
        return full_code(self.assortment, K)

    def _repr_html_(self) -> str:
        """Notebook table of the numbers (the ``analyze --json`` keys)."""
        import html  # the notebook's table only: not on the CLI's path

        d = self.to_dict()
        rows = []
        for key, value in d.items():
            if isinstance(value, (dict, list)) and len(str(value)) > 120:
                continue
            text = "" if value is None else str(value)
            rows.append(
                f"<tr><th style='text-align:left'>{html.escape(str(key))}</th>"
                f"<td style='text-align:left'>{html.escape(text)}</td></tr>"
            )
        title = html.escape(self.name or "structural report")
        return f"<table><caption>{title}</caption>{''.join(rows)}</table>"

    def to_dict(self) -> dict[str, Any]:
        """The contract's ``analyze`` object plus the checks behind each number."""
        a = self.assortment
        K = Fraction(self.K)
        d: dict[str, Any] = {
            "name": self.name,
            "n": a.n,
            "LA": list(a.LA),
            "MJA": list(a.MJA) if self.mja_known else None,
            "V": a.V,
            "K": self.K,
            "L": _num(K + 1),
            "AVC": self.AVC,
            "F": self.F,
            "N": self.N,
            "rc": self.rc,
            "S_L": self.S_L,
            "loops": list(self.loops) if self.loops is not None else None,
            "code": self.code,
            "code_star": self.code_star,
            "canonical": self.canonical,
            "canonical_mechanism": self.canonical_mechanism,
            "p": self.p,
            "lambda": self.lam,
            "source": self.source,
            "loops_rule": self.loops_rule,
            "loops_note": self.loops_note,
            "checks": {
                "K": {k: _num(v) for k, v in self.K_values.items()},
                "F": {k: _num(v) for k, v in self.F_values.items()},
                "S_L": {
                    "sum_i_ni": self.S_L,
                    "2(F+3K)-V": _num(mob.side_sum_by_dof(Fraction(self.F), K, a.V)),
                    **({"sum_loops": sum(self.loops)} if self.loops is not None else {}),
                },
                "rc": {
                    "N-F": self.rc,
                    **(
                        {
                            "assortment": (
                                rc_a := mob.redundant_constraints_by_assortment(a, self.N)
                            ),
                            # the name this value had in 0.1.0; kept for scripts that read it
                            "seed": rc_a,
                        }
                        if self.lam == 3
                        else {}
                    ),
                },
            },
            "violations": self.violations,
            "generic_mobility": self.generic.to_dict() if self.generic is not None else None,
        }
        return d


def _fill(r: StructuralReport, K: Fraction) -> StructuralReport:
    a = r.assortment
    r.F_values["loops"] = mob.dof_by_loops(a.n, K, r.lam)
    if r.lam == 3:
        r.F_values["assortment"] = mob.dof_by_assortment(a)
    if r.p is not None:  # Grübler needs the simple-joint count, which a code lacks
        r.F_values["grubler"] = mob.dof_grubler(a.n, r.p, r.lam)
    r.violations = mob.theorem_violations(a, K)
    return r


def structural_report(m: Mechanism, lam: int = 3, with_loops: bool = True) -> StructuralReport:
    """Every structural quantity of ``m`` (frame and drivers used for N and rc only)."""
    expect_mechanism(m)
    from mjstruct.structure.isomorphism import canonical_code

    a = assortment(m)
    p = simple_joint_count(m)
    K_values: dict[str, Fraction | int] = {
        "formula": mob.loops_by_formula(a),
        "cycle_rank": mob.cycle_rank(m),
        "euler": mob.loops_by_joints(a.n, p),
    }
    r = StructuralReport(
        name=m.name, assortment=a, K_values=K_values, N=len(m.drivers), lam=lam, p=p
    )
    _fill(r, Fraction(K_values["cycle_rank"]))
    if with_loops:
        from mjstruct.structure.loops import loop_assortment

        la = loop_assortment(m)
        if la is None:
            r.loops_note = (
                "the chain is not planar (its link–joint graph has a K5 or K3,3 minor), "
                "so it has no [L]"
            )
        else:
            r.loops, r.loops_rule = la.sizes, la.rule
    r.generic = generic_mobility(m)
    r.canonical = canonical_code(m)
    if m.frame is not None:
        r.canonical_mechanism = canonical_code(m, "mechanism")
    return r


def code_report(
    code: str, dof: int | None = None, N: int | None = None, lam: int = 3
) -> StructuralReport:
    """Quantities from a structural code alone; K from ``dof`` when given, else the formula."""
    a = parse_code(code)
    K_values: dict[str, Fraction | int] = {"formula": mob.loops_by_formula(a)}
    if dof is not None:
        K_values["dof"] = Fraction(a.n - 1 - dof, lam - 1)
    K = Fraction(K_values.get("dof", K_values["formula"]))
    r = StructuralReport(
        name=code,
        assortment=a,
        K_values=K_values,
        N=N if N is not None else (dof if dof is not None else 0),
        lam=lam,
        source="code",
        mja_known="/[" in code.replace(" ", ""),
    )
    return _fill(r, K)

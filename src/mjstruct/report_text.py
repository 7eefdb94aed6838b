"""Plain-text rendering of a :class:`~mjstruct.report.StructuralReport` in the style of
[MJ structure 2020]: one bullet per quantity, each formula written out with the numbers
put in, and both formulas where the paper gives two.

A form is written once where the forms coincide (``V = 0``, not ``V = 0 = 0 = 0``), and
a sum with no terms is left out of its formula (``F = n2 − 3 − V`` for a chain of binary
links).
"""

from __future__ import annotations

from mjstruct.report import StructuralReport
from mjstruct.structure.mobility import number_text as _n  # short: used in long formulas


def _terms(coeffs: list[tuple[int, str, int]]) -> tuple[str, str]:
    """Symbolic and numeric sums of ``coeff * symbol`` terms with value ``count``."""
    sym = " + ".join((f"{c}{s}" if c != 1 else s) for c, s, _ in coeffs) or "0"
    num = " + ".join((f"{c}·{v}" if c != 1 else str(v)) for c, _, v in coeffs) or "0"
    return sym, num


def _eq(*forms: str) -> str:
    """The forms joined by " = ", each written once where it repeats the one before.

    >>> _eq("n", "n2", "4", "4"), _eq("V", "0", "0", "0")
    ('n = n2 = 4', 'V = 0')
    """
    kept = [f for k, f in enumerate(forms) if k == 0 or f != forms[k - 1]]
    return " = ".join(kept)


def _plus(coeffs: list[tuple[int, str, int]]) -> tuple[str, str]:
    """`` + sum`` (symbolic, numeric) of the terms, or empty strings when there are none.

    >>> _plus([(1, "n3", 1), (2, "n4", 1)]), _plus([])
    ((' + n3 + 2n4', ' + 1 + 2·1'), ('', ''))
    """
    if not coeffs:
        return "", ""
    sym, num = _terms(coeffs)
    return f" + {sym}", f" + {num}"


def _minus(coeffs: list[tuple[int, str, int]]) -> tuple[str, str]:
    """`` − sum`` (symbolic, numeric) of the terms, in parentheses when there are several,
    or empty strings when there are none.

    >>> _minus([(1, "n4", 1)]), _minus([(1, "n4", 0), (2, "n5", 1)])
    ((' − n4', ' − 1'), (' − (n4 + 2n5)', ' − (0 + 2·1)'))
    """
    if not coeffs:
        return "", ""
    sym, num = _terms(coeffs)
    return (f" − ({sym})", f" − ({num})") if len(coeffs) > 1 else (f" − {sym}", f" − {num}")


def render(r: StructuralReport) -> str:
    a = r.assortment
    la = list(a.LA)
    nsym = [f"n{k + 2}" for k in range(len(la))]
    out = [f"Structural analysis: {r.name or '(unnamed)'}"]
    if a.n1:
        out.append(f"! {a.n1} link(s) have a single joint: the chain is open there")

    def bullet(text: str) -> None:
        out.append("• " + text)

    links = " + ".join(map(str, la)) + (f" + {a.n1} (single-joint)" if a.n1 else "")
    bullet(
        f"number and assortment of links: {_eq('n', ' + '.join(nsym), links, str(a.n))}; "
        f"[LA] = [{' '.join(map(str, la))}]"
    )
    if r.mja_known:
        mja = list(a.MJA)
        msym = [f"ν{k + 2}" for k in range(len(mja))]
        bullet(
            "MJ assortment: [MJA] = "
            + (
                f"[{' '.join(msym)}] = [{' '.join(map(str, mja))}]"
                if mja
                else "[] (simple joints only)"
            )
        )
        vs, vn = _terms([(k + 1, f"ν{k + 2}", nu) for k, nu in enumerate(mja)])
        bullet(f"MJ factor: {_eq('V', vs, vn, str(a.V))}")
    else:
        bullet(f"MJ factor: V = {a.V} ([MJA] not given by the code)")
    if r.p is not None:
        bullet(f"simple-joint equivalents: p = Σ j = {r.p}")

    ex = [(k, f"n{k + 2}", ni) for k, ni in enumerate(la) if k >= 1]
    es, en = _plus(ex)
    kf = r.K_values["formula"]
    k_sym, k_num = (f"(V{es})/2", f"({a.V}{en})/2") if ex else ("V/2", f"{a.V}/2")
    line = f"independent loops: K = 1 + {k_sym} = 1 + {k_num} = {_n(kf)}"
    if "cycle_rank" in r.K_values:
        line += f"; cycle rank of the link–joint graph = {_n(r.K_values['cycle_rank'])}"
        line += f"; p − n + 1 = {r.p} − {a.n} + 1 = {_n(r.K_values['euler'])}"
    if "dof" in r.K_values:
        line += f"; from F: K = (n − 1 − F)/{r.lam - 1} = {_n(r.K_values['dof'])}"
    bullet(line)
    bullet(f"all loops, outer L0 included: L = K + 1 = {_n(r.K + 1)}")
    bullet(
        f"assembly verification criterion: AVC = 2(K − 1) − {f'(V{es})' if ex else 'V'} = "
        f"{_n(2 * (r.K - 1))} − {a.V + a.excess} = {_n(r.AVC)}"
    )
    fl = f"F = (n − 1) − {r.lam - 1}K = {a.n - 1} − {_n((r.lam - 1) * r.K)} = {_n(r.F)}"
    parts = []
    if "assortment" in r.F_values:
        beyond = [(k - 1, f"n{k + 2}", ni) for k, ni in enumerate(la) if k >= 2]
        bs, bn = _minus(beyond)
        n2 = la[0] if la else 0
        parts.append(f"F = n2 − 3 − V{bs} = {n2} − 3 − {a.V}{bn} = {_n(r.F_values['assortment'])}")
    parts.append(fl)
    if "grubler" in r.F_values:
        parts.append(
            f"Grübler F = {r.lam}(n − 1) − {r.lam - 1}p = {r.lam * (a.n - 1)} − "
            f"{(r.lam - 1) * (r.p or 0)} = {_n(r.F_values['grubler'])}"
        )
    bullet("degrees of freedom: " + "; ".join(parts))
    d = r.to_dict()
    sides = " + ".join(f"{k + 2}·{ni}" for k, ni in enumerate(la) if ni)
    bullet(
        f"sum of sides of all loops: S_L = 2(F + 3K) − V = 2({_n(r.F)} + 3·{_n(r.K)}) − {a.V} = "
        f"{_n(d['checks']['S_L']['2(F+3K)-V'])}; S_L = Σ i·n_i = {sides} = {r.S_L}"
    )
    if r.source == "graph":
        if r.loops is not None:
            bullet(
                f"loop assortment: [L] = [{' '.join(map(str, r.loops))}], Σ = {sum(r.loops)} "
                f"(drawing: {r.loops_rule})"
            )
        else:
            bullet(f"loop assortment: none — {r.loops_note}")
    rc_line = f"redundant constraints, N = {r.N}: rc = N − F = {r.N} − {_n(r.F)} = {_n(r.rc)}"
    if "assortment" in d["checks"]["rc"]:
        beyond = [(k - 1, f"n{k + 2}", ni) for k, ni in enumerate(la) if k >= 2]
        bs, bn = _minus(beyond)
        n2 = la[0] if la else 0
        rc_sym, rc_num = (f"(n2{bs})", f"({n2}{bn})") if beyond else ("n2", str(n2))
        rc_line += (
            f"; rc = (N + V + 3) − {rc_sym} = {r.N + a.V + 3} − {rc_num} = "
            f"{d['checks']['rc']['assortment']}"
        )
    bullet(rc_line)
    if r.generic is not None:
        for line in r.generic.render().splitlines():
            out.append(line.replace("- ", "• ", 1) if line.startswith("- ") else line)
    if r.code is not None:
        star = f"; Code* = {r.code_star}" if r.code_star else ""
        bullet(f"structural code: Code = {r.code}{star}")
    if r.canonical:
        bullet(f"canonical code (chain): {r.canonical}")
    if r.canonical_mechanism:
        bullet(f"canonical code (mechanism: frame and drivers coloured): {r.canonical_mechanism}")
    if r.violations:
        out.append("Violations:")
        out.extend(f"  ✗ {v}" for v in r.violations)
    elif r.rc != 0:
        out.append(
            f"Note: rc = {_n(r.rc)} ≠ 0: "
            + ("over-driven / redundant constraints" if r.rc > 0 else "fewer drivers than DOF")
        )
    return "\n".join(out)

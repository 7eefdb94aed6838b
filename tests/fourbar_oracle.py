"""An independent closed form of the hinged four-bar's coupler point (for the design
tests): circle intersection by the law of cosines, not the plug-in's triangle code."""

from __future__ import annotations

import cmath
import math
from collections.abc import Mapping
from typing import Any


def coupler_point(d: Mapping[str, Any], q: float, point: str = "M") -> complex:
    """Position of ``point`` of the four-bar file ``d`` (joints O1, A, B, O2; link 1 the
    crank O1 -> A, so q is the direction of O1 -> A) at driver value ``q``."""
    at = {j["id"]: complex(*j["at"]) for j in d["joints"]}
    at.update({p["id"]: complex(*p["at"]) for p in d.get("points", [])})
    O1, A0, B0, O2, M0 = at["O1"], at["A"], at["B"], at["O2"], at[point]
    if point == "A":
        return O1 + abs(A0 - O1) * cmath.exp(1j * q)
    a, b, c = abs(A0 - O1), abs(B0 - A0), abs(O2 - B0)
    side = 1.0 if ((B0 - A0) * (O2 - A0).conjugate()).imag >= 0 else -1.0
    A = O1 + a * cmath.exp(1j * q)
    e = O2 - A
    f = abs(e)
    cos_alpha = (b * b + f * f - c * c) / (2 * b * f)
    if not -1.0 <= cos_alpha <= 1.0:
        return complex(math.nan, math.nan)
    alpha = math.acos(cos_alpha)
    # B on the same side of A -> O2 as at the reference
    B = A + b * cmath.exp(1j * (cmath.phase(e) + side * alpha))
    return A + (B - A) / (B0 - A0) * (M0 - A0)


def link_angle(d: Mapping[str, Any], q: float, link: str) -> float:
    """The contract's angle of a moving ``link`` of the four-bar file ``d`` at ``q``:
    the direction from its first to its second joint in file order."""
    at = {j["id"]: complex(*j["at"]) for j in d["joints"]}
    joints = [j["id"] for j in d["joints"] if link in j["links"]]
    now = {"A": coupler_point(d, q, "A"), "B": coupler_point(d, q, "B")}
    now.update({k: at[k] for k in ("O1", "O2")})
    return cmath.phase(now[joints[1]] - now[joints[0]])

"""Numbers as the outputs write them: JSON values and text-report cells.

Every ``--json`` output holds no NaN or infinity (strict JSON); a value that was not
computed or is not finite is ``null``, and negative zero is written as ``0.0``. Text
reports print six significant digits, or ``-`` where there is no value.

>>> json_number(float("nan")) is None, json_number(-0.0), json_list([1.0, float("inf")])
(True, 0.0, [1.0, None])
>>> text_number(2 / 3), text_number(None)
('0.666667', '-')
"""

from __future__ import annotations

import math
from collections.abc import Iterable

__all__ = ["json_list", "json_number", "text_number"]


def json_number(x: float | None) -> float | None:
    """``x`` as a float, or None when it is None or not finite."""
    if x is None:
        return None
    x = float(x)
    # + 0.0 turns -0.0 into 0.0 (a printed "-0" reads as a sign that is not there)
    return x + 0.0 if math.isfinite(x) else None


def json_list(values: Iterable[float]) -> list[float | None]:
    """:func:`json_number` of each value."""
    return [json_number(float(x)) for x in values]


def text_number(x: float | None) -> str:
    """``x`` to six significant digits, or ``-`` when it is None or not finite."""
    return "-" if x is None or not math.isfinite(x) else f"{x:.6g}"

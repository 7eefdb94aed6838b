"""Writing a command's result (one JSON object, or text, on standard output) and reading
the arguments several commands share.

JSON is indented by object, with every list of plain values kept on one line, so that
long numeric columns (kinematics) stay compact and reports stay readable.

>>> print(dumps({"LA": [8, 1, 1], "checks": {"K": {"formula": 4}}}))
{
 "LA": [8, 1, 1],
 "checks": {
  "K": {
   "formula": 4
  }
 }
}
"""

from __future__ import annotations

import json
import sys
from typing import TYPE_CHECKING, Any

from mjstruct.errors import MechanismError

if TYPE_CHECKING:
    from mjstruct.mechanism import Mechanism


def dumps(obj: Any, level: int = 0) -> str:
    """JSON text: objects and lists of objects indented, lists of plain values inline."""
    pad, inner = " " * level, " " * (level + 1)
    if isinstance(obj, dict):
        if not obj:
            return "{}"
        items = [
            f"{inner}{json.dumps(str(k), ensure_ascii=False)}: {dumps(v, level + 1)}"
            for k, v in obj.items()
        ]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(obj, (list, tuple)) and any(isinstance(x, (dict, list, tuple)) for x in obj):
        items = [inner + dumps(x, level + 1) for x in obj]
        return "[\n" + ",\n".join(items) + "\n" + pad + "]"
    return json.dumps(obj, ensure_ascii=False, allow_nan=False, separators=(", ", ": "))


def emit_json(obj: Any) -> None:
    sys.stdout.write(dumps(obj) + "\n")


def emit_text(text: str) -> None:
    sys.stdout.write(text.rstrip("\n") + "\n")


def driver_list(text: str | None, m: Mechanism) -> list[str] | None:
    """``--drivers J1,J2`` as joint ids of ``m`` (None when the option was not given)."""
    if text is None:
        return None
    drivers = [d.strip() for d in text.split(",") if d.strip()]
    known = {j.id for j in m.joints}
    for d in drivers:
        if d not in known:
            raise MechanismError(f"--drivers: {d!r} is not a joint id")
    return drivers

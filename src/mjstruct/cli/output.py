"""Writing a command's result: one JSON object, or text, on standard output.

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
from typing import Any


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

"""Writing a command's result: one JSON object, or text, on standard output."""

from __future__ import annotations

import json
import sys
from typing import Any


def emit_json(obj: Any) -> None:
    json.dump(obj, sys.stdout, ensure_ascii=False, indent=1)
    sys.stdout.write("\n")


def emit_text(text: str) -> None:
    sys.stdout.write(text.rstrip("\n") + "\n")

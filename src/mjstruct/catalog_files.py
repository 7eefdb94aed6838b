"""Where the shipped catalogs live: ``catalogs/`` of the source tree, installed as the
data package ``mjstruct._catalogs``.

>>> (catalog_root() / "examples" / "four-bar.json").is_file()
True
"""

from __future__ import annotations

import importlib.resources
from pathlib import Path


def catalog_root() -> Path:
    """The directory of shipped catalogs (examples, atlases)."""
    return Path(str(importlib.resources.files("mjstruct._catalogs")))


def example_path(name: str) -> Path:
    """Path of a shipped example mechanism, by file stem (``"four-bar"``)."""
    return catalog_root() / "examples" / f"{name}.json"

"""Where the shipped catalogs live: ``catalogs/`` of the source tree, installed as the
data package ``mjstruct._catalogs``.

>>> (catalog_root() / "examples" / "four-bar.json").is_file()
True
"""

from __future__ import annotations

from functools import cache
from pathlib import Path


@cache
def catalog_root() -> Path:
    """The directory of shipped catalogs (examples, atlases)."""
    import importlib.util

    # a package installed as a directory (the usual case, and an editable install):
    # its path, without importlib.resources' machinery (a tenth of a CLI start-up)
    spec = importlib.util.find_spec("mjstruct._catalogs")
    for where in (spec and spec.submodule_search_locations) or []:
        if Path(where, "examples").is_dir():
            return Path(where)
    import importlib.resources

    return Path(str(importlib.resources.files("mjstruct._catalogs")))


def example_path(name: str) -> Path:
    """Path of a shipped example mechanism, by file stem (``"four-bar"``)."""
    return catalog_root() / "examples" / f"{name}.json"

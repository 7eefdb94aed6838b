"""``python -m mjstruct``: the ``mjstruct`` command, for environments without its script."""

from __future__ import annotations

if __name__ == "__main__":
    from mjstruct.cli.main import main

    raise SystemExit(main())

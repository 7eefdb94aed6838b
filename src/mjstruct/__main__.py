"""``python -m mjstruct``: the ``mjstruct`` command, for environments without its script.

A signal that lands while the command is still being imported stops it as one
landing later does: one line, status 130 (Ctrl-C) or 143 (SIGTERM), no traceback.
"""

from __future__ import annotations

if __name__ == "__main__":
    import signal
    import sys

    class _Terminated(BaseException):
        """SIGTERM before the command's own handler is in place."""

    def _on_sigterm(signum: int, frame: object) -> None:
        raise _Terminated

    signal.signal(signal.SIGTERM, _on_sigterm)
    try:
        from mjstruct.cli.main import main

        status = main()
    except _Terminated:
        sys.stderr.write("mjstruct: terminated\n")
        status = 143
    except KeyboardInterrupt:
        sys.stderr.write("mjstruct: interrupted\n")
        status = 130
    raise SystemExit(status)

"""The seam through which the kinematics names the singular positions it flags.

Owns one hook.  The near-singular check of a kinematic analysis flags frames; what
kind of singular position each is (input limit, output extreme, change point) is the
singular-positions unit's answer, and that unit sits above the kinematics.  So the
check asks :func:`singular_namer`, and the package installs the singular unit's
:func:`~mjstruct.singular.analysis.name_flagged_frames` (imported at the first flagged
frame) with :func:`set_singular_namer`.  Nothing heavy is imported here: the package
installs the hook on every import, and it lives below every unit so that the
structural commands do not import the kinematics package for it.

Examples
--------
>>> previous = set_singular_namer(lambda r, frames: ["change_point"] * len(frames))
>>> singular_namer()(None, [3, 4])
['change_point', 'change_point']
>>> _ = set_singular_namer(previous)
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

#: names the kind at each flagged frame (None: not identified) of a kinematics result
#: (typed loosely: this seam sits below the kinematics and knows none of its classes)
SingularNamer = Callable[[Any, Any], list["str | None"]]

_namer: SingularNamer | None = None


def set_singular_namer(namer: SingularNamer | None) -> SingularNamer | None:
    """Install ``namer`` as what names flagged frames; returns the one it replaces."""
    global _namer
    previous, _namer = _namer, namer
    return previous


def singular_namer() -> SingularNamer | None:
    """The installed namer (None: flagged frames stay unnamed)."""
    return _namer

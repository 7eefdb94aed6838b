"""The memory a kinematic sweep needs, estimated before it starts, and its limit.

Owns :func:`sweep_bytes` (bytes per frame × frames, from the plan's size) and
:func:`check_sweep_memory`, which refuses a sweep beyond the limit
(:data:`DEFAULT_MAX_MEMORY`, 2 GiB, or the environment variable
``MJSTRUCT_MAX_MEMORY_BYTES``) with the estimate and the largest frame count that fits.

The estimate counts the result's tables (x, y, velocities, accelerations and their
analogs per joint and point; angle, ω, ε, σ, κ per link; the closure unknowns) and
scales them by :data:`BYTES_PER_VALUE`, measured with ``tracemalloc`` as the peak of
an analysis with its checks and its JSON text: 43–55 bytes per table value on the
four-bar, the class-IV and Zhivago examples (closure) and the five-cylinder radial
engine at 20 000 frames; 64 leaves a margin.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
>>> sweep_bytes(model, 1000)
4480000
>>> check_sweep_memory(model, 10**9, limit=2**31)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: frames: 1000000000 frames need about 4.5e+12 bytes, over ... fit
"""

from __future__ import annotations

import os

from mjstruct.errors import MechanismError
from mjstruct.kinematics.model import KinematicModel

#: default limit on a sweep's estimated memory (bytes)
DEFAULT_MAX_MEMORY = 2**31
#: environment variable overriding :data:`DEFAULT_MAX_MEMORY`
MEMORY_ENV = "MJSTRUCT_MAX_MEMORY_BYTES"
#: bytes of peak memory per table value (measured 43-55, see the module docstring)
BYTES_PER_VALUE = 64


def sweep_bytes(model: KinematicModel, frames: int) -> int:
    """Estimated peak memory (bytes) of an analysis of ``model`` over ``frames`` frames."""
    m = model.mechanism
    values = 10 * (len(m.joints) + len(m.points)) + 5 * len(m.links) + 4 * model.plan.unknowns
    return BYTES_PER_VALUE * values * frames


def memory_limit(limit: int | None = None) -> int:
    """The limit in bytes: ``limit`` if given, else the environment's, else 2 GiB.

    Raises
    ------
    MechanismError
        ``limit`` (or the environment variable) not a positive integer.
    """
    if limit is None:
        text = os.environ.get(MEMORY_ENV)
        if text is None:
            return DEFAULT_MAX_MEMORY
        try:
            limit = int(text)
        except ValueError:
            raise MechanismError(
                f"{MEMORY_ENV}: not an integer number of bytes: {text!r}"
            ) from None
        if limit <= 0:
            raise MechanismError(f"{MEMORY_ENV}: must be a positive number of bytes, got {limit}")
        return limit
    if limit <= 0:
        raise MechanismError(f"max_memory: must be a positive number of bytes, got {limit}")
    return limit


def check_sweep_memory(model: KinematicModel, frames: int, limit: int | None = None) -> int:
    """Refuse a sweep whose estimate exceeds the limit; return the estimate (bytes).

    Raises
    ------
    MechanismError
        naming ``frames``, with the estimate, the limit and the largest frame count
        that fits.
    """
    cap = memory_limit(limit)
    need = sweep_bytes(model, frames)
    if need > cap:
        fits = cap // max(sweep_bytes(model, 1), 1)
        raise MechanismError(
            f"frames: {frames} frames need about {need:.2g} bytes, over the limit of "
            f"{cap:.3g} bytes (max_memory, or {MEMORY_ENV}); at most {fits} frames fit"
        )
    return need

"""Memory of a dynamics run, estimated before it starts, and the limit it must keep.

Owns :func:`analysis_bytes`: the kinematic sweep (order 2, no checks) of
:func:`mjstruct.kinematics.memory.sweep_bytes` plus, per frame, the stacked
``u × u`` systems of the link equations (``u = 3`` per moving link) with their LU
copies and right-hand sides. The coefficients were fitted on ``tracemalloc`` peaks of
the slider-crank, the Zhivago mechanism and the 5-cylinder radial engine (constant
speed and free motion, 2000 and 8000 frames): the estimate is 1.0-1.25 times the
measured peak. The limit is the kinematics' (2 GiB, ``MJSTRUCT_MAX_MEMORY_BYTES``, or
``max_memory``).

>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("slider-crank-seed000-dynamics")))
>>> 3000 < analysis_bytes(model, 1) < 5000
True
"""

from __future__ import annotations

from mjstruct.kinematics.memory import memory_limit, refuse_frames, sweep_bytes
from mjstruct.kinematics.model import KinematicModel

__all__ = ["analysis_bytes", "check_analysis_memory"]

#: bytes per frame: SYSTEM_SQUARE * u² + SYSTEM_LINEAR * u doubles
SYSTEM_SQUARE = 2
SYSTEM_LINEAR = 32


def analysis_bytes(model: KinematicModel, frames: int) -> int:
    """Estimated peak memory (bytes) of a dynamics run of ``model`` over ``frames``."""
    u = 3 * (len(model.mechanism.links) - 1)
    per_frame = sweep_bytes(model, 1, checks=False) + 8 * (
        SYSTEM_SQUARE * u * u + SYSTEM_LINEAR * u
    )
    return per_frame * frames


def check_analysis_memory(model: KinematicModel, frames: int, limit: int | None = None) -> int:
    """Refuse a run whose estimate exceeds the limit; return the estimate (bytes).

    Raises
    ------
    MechanismError
        naming ``frames``, with the estimate, the limit and the largest frame count
        that fits.
    """
    cap = memory_limit(limit)
    need = analysis_bytes(model, frames)
    if need > cap:
        refuse_frames(frames, need, cap, cap // max(analysis_bytes(model, 1), 1))
    return need

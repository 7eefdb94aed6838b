"""The memory a kinematic sweep needs, estimated before it starts, and its limit.

Owns :func:`sweep_bytes` (the peak of one output path: the library's result, the JSON
text, or the CSV table streamed in chunks), :func:`frames_that_fit` and
:func:`check_sweep_memory`, which refuses a sweep beyond the limit
(:data:`DEFAULT_MAX_MEMORY`, 2 GiB, or the environment variable
``MJSTRUCT_MAX_MEMORY_BYTES``) with the estimate and the largest frame count that fits.

The estimate is linear in the frames, per *table item* (a joint, a point, a link or a
closure unknown), plus, with the full checks (``checks="full"``), the constraint
Jacobians they build on a few frames (independent of the frames: sparse entries,
linear in the size, and dense matrices only within a fixed budget).  The coefficients
were measured with ``tracemalloc`` (peak of the call, 1000 and 3000 frames, slope and
intercept) on the four-bar, class-IV, Zhivago examples and k four-bars sharing one
crank (10 to 1000 links):

* result, checks off: 44-56 bytes per item and frame (:data:`RESULT_BYTES` 50; the
  tables are views of the evaluation's arrays, made when read; the points of the
  link the plan is solved in share its zero derivatives);
* result with the default checks, read: 50-60 (:data:`CHECKS_BYTES` adds 10; the
  checks go row by row, only the closure's Jacobian over the frames grows with them);
* JSON text (the result, its lists of floats and the text): 358-380
  (:data:`JSON_BYTES` 420);
* the full checks' Jacobians (:func:`full_check_bytes`): sparse entries, about 12 kB
  per link, and for small systems 5 to 26 dense matrices of Nu × 3Ns doubles within
  their budget (12 MB measured at 1000 links, 24 MB at 2000).

A CSV table to a file is streamed: the sweep is solved :data:`CHUNK_FRAMES` frames at
a time (with a short lead-in from the reference, :data:`LEAD_FRAMES`), so its peak
does not grow with the frame count.

Examples
--------
>>> from mjstruct.io import read_mechanism
>>> from mjstruct.catalog_files import example_path
>>> from mjstruct.kinematics.model import KinematicModel
>>> model = KinematicModel.build(read_mechanism(example_path("four-bar")))
>>> sweep_bytes(model, 1000, checks=False)
450000
>>> sweep_bytes(model, 10**9, output="csv") == sweep_bytes(model, 10**7, output="csv")
True
>>> check_sweep_memory(model, 10**9, limit=2**31)  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
mjstruct.errors.MechanismError: frames: 1000000000 frames need about 5.4e+11 bytes, over ... fit
"""

from __future__ import annotations

import os
from typing import Literal, NoReturn

from mjstruct.errors import MechanismError
from mjstruct.kinematics.jacobian import CALIBRATION_FRAMES, MEMORY_BUDGET, SVD_ENTRIES
from mjstruct.kinematics.model import KinematicModel

#: default limit on a sweep's estimated memory (bytes)
DEFAULT_MAX_MEMORY = 2**31
#: environment variable overriding :data:`DEFAULT_MAX_MEMORY`
MEMORY_ENV = "MJSTRUCT_MAX_MEMORY_BYTES"
#: bytes per table item and frame of the result without checks (measured 44-56)
RESULT_BYTES = 50
#: bytes per table item and frame the checks add (measured 0-10)
CHECKS_BYTES = 10
#: bytes per table item and frame of the JSON path, result and checks included
#: (measured 358-380)
JSON_BYTES = 420
#: bytes per link of the full check's sparse Jacobian entries and LU (measured 12 kB)
FULL_CHECK_LINK_BYTES = 16_000
#: bytes the checks need whatever the size (measured 0.04-1.6 MB)
CHECKS_FIXED = 2**18
#: frames solved at once when the CSV table is streamed to a file
CHUNK_FRAMES = 20_000
#: at most this many frames (plus a few) lead each chunk in from the reference
LEAD_FRAMES = 720

Output = Literal["result", "json", "csv"]
#: the checks asked for (see :func:`~mjstruct.kinematics.solver.kinematic_analysis`)
Checks = bool | Literal["full"]


def table_items(model: KinematicModel) -> int:
    """Joints, points, links and closure unknowns: the items the tables hold per frame."""
    m = model.mechanism
    return len(m.joints) + len(m.points) + len(m.links) + model.plan.unknowns


def full_check_bytes(model: KinematicModel) -> int:
    """Bytes the full Jacobian check holds at once, whatever the frames.

    ``[J; D]`` is built as sparse entries (linear in the joints; with the sparse LU
    of large systems about :data:`FULL_CHECK_LINK_BYTES` per link, measured 12 kB at
    1000 and 2000 links); dense matrices only where they fit the check's budget: the
    calibration frames' J kept for the result, and J at the determinant's dips for
    the SVD of the rank (systems of at most ``SVD_ENTRIES`` entries).  Those keep at
    most ``MEMORY_BUDGET / matrix`` matrices; with the copies made around them the
    measured peak was 5 matrices at one kept, 17 at three and 24-26 at five or more:
    about ``2 + 4 × kept`` (kept at most 5), and never more than three budgets.
    """
    m = model.mechanism
    nu = sum(2 * (len(j.links) - 1) if j.kind == "R" else 2 for j in m.joints)
    nc = 3 * (len(m.links) - 1)
    matrix = 8 * (nu + len(model.drivers)) * nc
    sparse = FULL_CHECK_LINK_BYTES * len(m.links)
    if nu * nc > SVD_ENTRIES and CALIBRATION_FRAMES * matrix > MEMORY_BUDGET:
        return sparse  # no dense matrix at all
    kept = min(5, max(1, MEMORY_BUDGET // max(matrix, 1)))
    return sparse + min(matrix * (2 + 4 * kept), 3 * MEMORY_BUDGET)


def _per_frame(model: KinematicModel, output: Output, checks: Checks) -> int:
    per_item = JSON_BYTES if output == "json" else RESULT_BYTES + (CHECKS_BYTES if checks else 0)
    return per_item * table_items(model)


def _fixed(model: KinematicModel, checks: Checks) -> int:
    """The checks' memory whatever the frames (the full check's Jacobians)."""
    if not checks:
        return 0
    return CHECKS_FIXED + (full_check_bytes(model) if checks == "full" else 0)


def sweep_bytes(
    model: KinematicModel, frames: int, output: Output = "result", checks: Checks = True
) -> int:
    """Estimated peak memory (bytes) of an analysis of ``model`` over ``frames`` frames.

    Parameters
    ----------
    model : the model to be solved.
    frames : the frame count.
    output : ``"result"`` (the library's :class:`KinematicsResult`), ``"json"`` (that
        and the JSON text) or ``"csv"`` (the table streamed to a file in chunks of
        :data:`CHUNK_FRAMES`: bounded whatever the frame count).
    checks : the checks asked for (True: the default ones, "full": with the dense
        Jacobians, False: none).
    """
    if output == "csv":
        frames = min(frames, CHUNK_FRAMES + LEAD_FRAMES + 8)
    return _fixed(model, checks) + _per_frame(model, output, checks) * frames


def frames_that_fit(
    model: KinematicModel, limit: int, output: Output = "result", checks: Checks = True
) -> int:
    """The largest frame count whose estimate is within ``limit`` bytes (0: none)."""
    room = limit - _fixed(model, checks)
    return max(0, room // max(_per_frame(model, output, checks), 1))


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


def check_sweep_memory(
    model: KinematicModel,
    frames: int,
    limit: int | None = None,
    output: Output = "result",
    checks: Checks = True,
) -> int:
    """Refuse a sweep whose estimate exceeds the limit; return the estimate (bytes).

    Raises
    ------
    MechanismError
        naming ``frames``, with the estimate, the limit and the largest frame count
        that fits.
    """
    cap = memory_limit(limit)
    need = sweep_bytes(model, frames, output, checks)
    if need > cap:
        if output == "csv":
            raise MechanismError(
                f"frames: the streamed table needs about {need:.2g} bytes whatever the frame "
                f"count, over the limit of {cap:.3g} bytes (max_memory, or {MEMORY_ENV})"
            )
        refuse_frames(frames, need, cap, frames_that_fit(model, cap, output, checks))
    return need


def refuse_frames(frames: int, need: int, cap: int, fits: int) -> NoReturn:
    """The one refusal of a run over the memory limit: the estimate, the limit, what fits."""
    raise MechanismError(
        f"frames: {frames} frames need about {need:.2g} bytes, over the limit of "
        f"{cap:.3g} bytes (max_memory, or {MEMORY_ENV}); at most {fits} frames fit"
    )

"""Array types shared by the numerical modules: one home for the ``numpy.typing`` aliases.

Positions are complex (``x + iy``), analogs and angles real; a module annotates its
arrays with these names instead of defining its own.

>>> import numpy as np
>>> z: ComplexArray = np.array([1 + 2j])
>>> z.dtype == np.complex128
True
"""

from __future__ import annotations

from typing import TypeAlias

import numpy as np
import numpy.typing as npt

__all__ = ["BoolArray", "ComplexArray", "FloatArray", "IntArray"]

#: real arrays: angles, analogs, lengths, forces
FloatArray: TypeAlias = npt.NDArray[np.float64]
#: complex arrays: planar positions and vectors as ``x + iy``
ComplexArray: TypeAlias = npt.NDArray[np.complex128]
#: masks: per-frame validity, convergence
BoolArray: TypeAlias = npt.NDArray[np.bool_]
#: indices and counts
IntArray: TypeAlias = npt.NDArray[np.int_]

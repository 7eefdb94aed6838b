"""Assur-group decomposition that keeps multiple joints whole, and the choice of drivers.

One topic per module:

* :mod:`~mjstruct.structure.assur.results`: the result types (:class:`AssurGroup`,
  :class:`Decomposition`, :class:`DriverChoice`), their JSON and text;
* :mod:`~mjstruct.structure.assur.bodies`: links welded by the driven joints;
* :mod:`~mjstruct.structure.assur.contours`: Artobolevsky's class of a group;
* :mod:`~mjstruct.structure.assur.decomposition`: :func:`assur_groups`;
* :mod:`~mjstruct.structure.assur.choices`: :func:`driver_choices`.

The drivers themselves are checked by :mod:`mjstruct.structure.drivers`.

References
----------
.. [1] L. V. Assur, "Investigation of planar bar mechanisms with lower pairs from the
   point of view of their structure and classification" (in Russian), Bulletin of
   the Petrograd Polytechnic Institute, 1913–1914. [Assur 1914] in docs/references.md.
.. [2] I. I. Artobolevsky, Theory of Mechanisms and Machines (in Russian), Moscow:
   Nauka, 1988. [Artobolevsky 1988] in docs/references.md.
.. [3] A. Sljoka, O. Shai, W. Whiteley, "Checking mobility and decomposition of
   linkages via pebble game algorithm", Proc. ASME IDETC/CIE 2011, Washington, DC,
   2011. [Sljoka et al. 2011] in docs/references.md.

Examples
--------
>>> from mjstruct.mechanism import Mechanism
>>> four_bar = Mechanism.build([("O1", [0, 1]), ("A", [1, 2]), ("B", [2, 3]),
...                             ("O2", [3, 0])], frame=0, drivers=["O1"])
>>> assur_groups(four_bar).mechanism_class
2
"""

from mjstruct.structure.assur.choices import driver_choices
from mjstruct.structure.assur.contours import group_class
from mjstruct.structure.assur.decomposition import assur_groups
from mjstruct.structure.assur.results import AssurGroup, Decomposition, DriverChoice, roman

__all__ = [
    "AssurGroup",
    "Decomposition",
    "DriverChoice",
    "assur_groups",
    "driver_choices",
    "group_class",
    "roman",
]

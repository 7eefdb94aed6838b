"""Exceptions that carry a one-line message for the user.

``MechanismError`` is bad input (exit status 2 at the CLI); ``NumericalError`` is
numerical trouble found while computing (no assembly, singular Jacobian, ...).
"""

from __future__ import annotations

import math
from collections.abc import Iterable


class MechanismError(ValueError):
    """Invalid mechanism data; the message names the offending field."""


class NumericalError(ArithmeticError):
    """A computation could not produce a trustworthy number; the message says why."""


def expect_int(value: object, parameter: str, minimum: int | None = None) -> int:
    """``value`` as an int (not a bool), at least ``minimum``; else a one-line error.

    >>> expect_int(3, "n", 1)
    3
    >>> expect_int(2.5, "n")
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: n: expected an integer, got 2.5
    """
    import numbers

    # numbers.Integral: a numpy integer (a count read from an array) is an integer too
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise MechanismError(f"{parameter}: expected an integer, got {_shown(value)}")
    if minimum is not None and value < minimum:
        raise MechanismError(f"{parameter}: must be >= {minimum}, got {value}")
    return int(value)


def expect_number(value: object, parameter: str, *, finite: bool = True) -> float:
    """``value`` as a float (an int, float or numpy real; not a bool or a string), finite
    unless ``finite`` is False; else a one-line error naming ``parameter``.

    >>> expect_number(2, "speed")
    2.0
    >>> expect_number("1", "speed")
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: speed: expected a number, got '1'
    """
    import numbers

    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise MechanismError(f"{parameter}: expected a number, got {_shown(value)}")
    try:
        number = float(value)
    except OverflowError:  # an int beyond the double range
        number = math.inf if value > 0 else -math.inf  # type: ignore[operator]
    if finite and not math.isfinite(number):
        raise MechanismError(f"{parameter}: expected a finite number, got {_shown(value)}")
    return number


def expect_id(value: object, parameter: str) -> str:
    """An id as text: a string or an integer (a bool is neither), else raise naming
    ``parameter``; one rule for the ids of links, joints, points, gears and elements.

    >>> expect_id(3, "links"), expect_id("O1", "drivers")
    ('3', 'O1')
    >>> expect_id(True, "gears[0].id")
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: gears[0].id: an id must be a string or an integer, got True
    """
    if isinstance(value, bool) or not isinstance(value, (str, int)):
        raise MechanismError(f"{parameter}: an id must be a string or an integer, got {value!r}")
    return str(value)


def expect_ids(value: object, parameter: str) -> None:
    """Raise unless ``value`` is None or a list (any non-string iterable) of ids: a
    string would be iterated character by character.

    >>> expect_ids("O1", "drivers")
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: drivers: expected a list of joint ids, got 'O1'
    """
    if value is None:
        return
    if isinstance(value, (str, bytes)) or not isinstance(value, Iterable):
        raise MechanismError(f"{parameter}: expected a list of joint ids, got {_shown(value)}")


def expect_instance(
    value: object, parameter: str, kind: type | tuple[type, ...], what: str
) -> None:
    """Raise :class:`MechanismError` naming ``parameter`` unless ``value`` is a ``kind``
    (described to the user as ``what``)."""
    if not isinstance(value, kind):
        raise MechanismError(f"{parameter}: expected {what}, got {type(value).__name__}")


def _shown(value: object) -> str:
    try:
        text = repr(value)
    except ValueError:  # an int beyond Python's digit limit for str()
        return "a number too long to show"
    return text if len(text) <= 60 else text[:57] + "..."

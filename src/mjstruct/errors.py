"""Exceptions that carry a one-line message for the user.

``MechanismError`` is bad input (exit status 2 at the CLI); ``NumericalError`` is
numerical trouble found while computing (no assembly, singular Jacobian, ...).
"""

from __future__ import annotations


class MechanismError(ValueError):
    """Invalid mechanism data; the message names the offending field."""


class NumericalError(ArithmeticError):
    """A computation could not produce a trustworthy number; the message says why."""


def expect_mechanism(value: object, parameter: str = "m") -> None:
    """Raise :class:`MechanismError` naming ``parameter`` unless ``value`` is a Mechanism.

    >>> expect_mechanism("four-bar.json")  # doctest: +ELLIPSIS
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: m: expected a Mechanism (read a file ...), got str
    """
    from mjstruct.mechanism import Mechanism  # here: mechanism.py imports this module

    if not isinstance(value, Mechanism):
        raise MechanismError(
            f"{parameter}: expected a Mechanism (read a file with read_mechanism), "
            f"got {type(value).__name__}"
        )


def expect_int(value: object, parameter: str, minimum: int | None = None) -> int:
    """``value`` as an int (not a bool), at least ``minimum``; else a one-line error.

    >>> expect_int(3, "n", 1)
    3
    >>> expect_int(2.5, "n")
    Traceback (most recent call last):
    ...
    mjstruct.errors.MechanismError: n: expected an integer, got 2.5
    """
    if isinstance(value, bool) or not isinstance(value, int):
        raise MechanismError(f"{parameter}: expected an integer, got {value!r}")
    if minimum is not None and value < minimum:
        raise MechanismError(f"{parameter}: must be >= {minimum}, got {value}")
    return value

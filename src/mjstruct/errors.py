"""Exceptions that carry a one-line message for the user.

``MechanismError`` is bad input (exit status 2 at the CLI); ``NumericalError`` is
numerical trouble found while computing (no assembly, singular Jacobian, ...).
"""

from __future__ import annotations


class MechanismError(ValueError):
    """Invalid mechanism data; the message names the offending field."""


class NumericalError(ArithmeticError):
    """A computation could not produce a trustworthy number; the message says why."""

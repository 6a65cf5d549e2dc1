"""Checks of scalar arguments, shared by every module: each returns the value as a
plain ``float`` / ``int`` or raises :class:`~.errors.InputError` naming the argument
and quoting the value.

Numbers are Python or numpy reals (``bool`` and text are refused); integers are Python
or numpy integers (``2.0`` is refused).  Always ``check(name, value)``.
"""

from __future__ import annotations

import math
import numbers

from .errors import InputError


def positive(name: str, value, *, allow_inf: bool = False) -> float:
    """A number > 0, finite unless ``allow_inf`` (then inf passes)."""
    x = _real(name, value, allow_inf)
    if not x > 0:
        raise InputError(f"{name} must be a positive {'number or inf' if allow_inf else 'finite number'}",
                         value=value)
    return x


def non_negative(name: str, value) -> float:
    """A finite number >= 0."""
    x = _real(name, value, False)
    if not x >= 0:
        raise InputError(f"{name} must be a finite number >= 0", value=value)
    return x


def fraction(name: str, value) -> float:
    """A number in [0, 1]."""
    x = _real(name, value, False)
    if not 0.0 <= x <= 1.0:
        raise InputError(f"{name} must be in [0, 1]", value=value)
    return x


def positive_int(name: str, value) -> int:
    """An integer >= 1."""
    n = _integer(name, value, "a positive integer")
    if n < 1:
        raise InputError(f"{name} must be a positive integer", value=value)
    return n


def non_negative_int(name: str, value) -> int:
    """An integer >= 0."""
    n = _integer(name, value, "a non-negative integer")
    if n < 0:
        raise InputError(f"{name} must be a non-negative integer", value=value)
    return n


def check_format(obj, expected: str | tuple[str, ...], what: str, source: str) -> dict:
    """``obj`` if it is a JSON object whose ``format`` is ``expected`` (or one of them,
    the newest last); else an InputError naming ``source`` and the format found."""
    accepted = (expected,) if isinstance(expected, str) else tuple(expected)
    if not isinstance(obj, dict) or obj.get("format") not in accepted:
        formats = ("" if len(accepted) == 1 else "one of ") + ", ".join(f'"{f}"' for f in accepted)
        raise InputError(f"not a {what} (expected \"format\": {formats})", file=source, column="format",
                         value=obj.get("format") if isinstance(obj, dict) else obj)
    return obj


def _real(name: str, value, allow_inf: bool) -> float:
    """float(value) for a real number (NaN and, unless allowed, inf included: the
    callers' range checks refuse them with their own message)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise InputError(f"{name} must be a number", value=value)
    x = float(value)
    if math.isnan(x) or (math.isinf(x) and not allow_inf):
        return math.nan
    return x


def _integer(name: str, value, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise InputError(f"{name} must be {what}", value=value)
    return int(value)

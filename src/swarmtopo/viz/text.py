"""Numbers as swarmtopo prints them, the same on the command line, in map.json's advice
and in report.html."""

from __future__ import annotations

from decimal import Decimal


def format_confidence(p: float) -> str:
    """A probability in percent, one decimal, more where needed so that a p < 1 never
    shows as 100 % and a p > 0 never as 0 %: ``0.3618`` -> ``"36.2%"``, ``0.99996`` ->
    ``"99.996%"``, ``1e-5`` -> ``"0.001%"``.  Exact: digits are taken from the float's
    own decimal value."""
    exact = Decimal(float(p)) * 100
    digits = 1
    while True:
        shown = round(exact, digits)
        if (shown < 100 or exact == 100) and (shown > 0 or exact == 0):
            return f"{shown:f}%"
        digits += 1

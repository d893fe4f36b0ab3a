"""Numbers typed on the command line."""

from __future__ import annotations

import math

from .errors import InputError

_PLAIN = frozenset("0123456789.eE+- ")


def parse_number(name: str, text: str) -> float:
    """A finite number; fractions such as 5/3 are accepted."""
    shown = text if len(text) <= 40 else f"{text[:20]}...({len(text)} characters)"
    try:
        if len(text) > 400:
            raise ValueError(text)
        if _PLAIN.issuperset(text) and any(c.isdigit() for c in text):
            # the common case, without importing fractions (a cold start pays ~2 ms for it);
            # float() rounds a decimal as Fraction would, and overflows to inf
            value = float(text)
            if not math.isfinite(value):
                raise OverflowError(text)
        else:
            from fractions import Fraction

            value = float(Fraction(text.strip()))
    except (ValueError, ZeroDivisionError, OverflowError):
        raise InputError(f"{name} must be a finite number (at most about 1e308) or a fraction "
                         f"like 5/3, got {shown!r}") from None
    return value

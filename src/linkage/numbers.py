"""Numbers typed on the command line."""

from __future__ import annotations

from fractions import Fraction

from .errors import InputError


def parse_number(name: str, text: str) -> float:
    """A finite number; fractions such as 5/3 are accepted."""
    shown = text if len(text) <= 40 else f"{text[:20]}...({len(text)} characters)"
    try:
        if len(text) > 400:
            raise ValueError(text)
        value = float(Fraction(text.strip()))
    except (ValueError, ZeroDivisionError, OverflowError):
        raise InputError(f"{name} must be a finite number (at most about 1e308) or a fraction "
                         f"like 5/3, got {shown!r}") from None
    return value

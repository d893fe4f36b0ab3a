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


QUANTITY = r"\s*([-+]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][-+]?[0-9]+)?)\s*(.*?)\s*"
"""A number, then the unit it is in (anything after it; spaces around both)."""


def split_unit(text: str) -> tuple[str, str] | None:
    """``"600rpm"`` -> ("600", "rpm"), ``"-2 N m"`` -> ("-2", "N m"), ``"5"`` -> ("5", ""): a
    number, then the unit it is in (None when the text does not begin with a number)."""
    import re  # here: a command that types no unit never compiles the pattern

    m = re.fullmatch(QUANTITY, text)
    return None if m is None else (m.group(1), m.group(2))


def unit_key(unit: str) -> str:
    """A unit as it is compared: spaces, ``*`` and ``·`` dropped, so ``N m``, ``Nm``, ``N*m``
    and ``N·m`` are one unit."""
    return "".join(unit.split()).replace("*", "").replace("\u00b7", "")


def parse_quantity(name: str, text: str, units: dict[str, float]) -> tuple[float, str]:
    """A number typed with an optional unit (``600rpm``, ``-2Nm``, ``-20 lbf``): (the number
    times the unit's factor, the unit as typed). ``units`` maps each accepted unit to its
    factor, ``""`` to the factor of a bare number. The one reading of "number+unit" on the
    command line (--speed, --accel, --torque, --load)."""
    parts = split_unit(text)
    known = {unit_key(u): f for u, f in units.items()}
    if parts is None or unit_key(parts[1]) not in known:
        listed = ", ".join(u for u in units if u) or "none"
        why = InputError(f"{name} {text!r}: give a number, optionally with one of these units: {listed}")
        if "" not in known or "/" not in text:
            raise why
        try:
            return parse_number(name, text) * known[""], ""  # a bare fraction, 5/3
        except InputError:
            raise why from None
    return parse_number(name, parts[0]) * known[unit_key(parts[1])], parts[1]

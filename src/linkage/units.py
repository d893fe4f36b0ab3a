"""Angles: degrees at the interface, radians inside (README, "Angle conventions").

The one home of the conversion. ``radians`` and ``degrees`` take a float or a numpy array
(they only multiply), and give the same bits as ``math.radians``/``numpy.radians`` and
``math.degrees``/``numpy.degrees``, which multiply by the same rounded constants; so an
engine that moves to them changes no result. A hot loop may hold ``RAD_PER_DEG`` in a local.
"""

from __future__ import annotations

import math
from typing import TypeVar

RAD_PER_DEG = math.pi / 180.0
"""pi/180 rounded once: the factor ``math.radians`` uses (CPython's ``degToRad``)."""
DEG_PER_RAD = 180.0 / math.pi
"""180/pi rounded once: the factor ``math.degrees`` uses (CPython's ``radToDeg``)."""

Angle = TypeVar("Angle")


def radians(degrees_value: Angle) -> Angle:
    """Degrees (as typed or read from a file) to radians (as the engines work)."""
    return degrees_value * RAD_PER_DEG  # type: ignore[operator]


def degrees(radians_value: Angle) -> Angle:
    """Radians (as the engines work) to degrees (as shown and written)."""
    return radians_value * DEG_PER_RAD  # type: ignore[operator]

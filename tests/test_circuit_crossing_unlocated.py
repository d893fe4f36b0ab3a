"""A crossing of the start value beside a limit position that no corrected point can place
on its own side is a named failure (circuits.CrossingNotLocated, the circuit "unlocated"),
never a configuration solved from the fold, where both sides meet, and matched by chance."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from linkage.kinematics import circuits as circuits_module
from linkage.kinematics.circuits import CrossingNotLocated, circuits
from linkage.kinematics.loading import load
from linkage.units import radians

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
NEAR_LIMIT_DEG = 112.0243
"""ME581's limit crank angle is 112.02431...: the first step passes the limit and the start
value on both sides of it (tests/test_circuit_limits.py)."""


def _failing_inside_crossings(monkeypatch) -> list[int]:
    """Make the corrector fail when called to locate a crossing (and only then)."""
    correct = circuits_module._correct
    failed: list[int] = []

    def correct_or_fail(curve, y, t):
        if sys._getframe(1).f_code.co_name == "_crossing_on_arc":
            failed.append(1)
            return None, 1
        return correct(curve, y, t)

    monkeypatch.setattr(circuits_module, "_correct", correct_or_fail)
    return failed


def test_a_crossing_no_corrected_point_locates_is_reported_unlocated(monkeypatch):
    m = load(SAMPLES / "fourbar_me581.toml")
    (traced,) = circuits(m, radians(NEAR_LIMIT_DEG)).circuits
    assert traced.status == "closed" and traced.members == (0, 1)  # the corrector working
    failed = _failing_inside_crossings(monkeypatch)
    found = circuits(m, radians(NEAR_LIMIT_DEG)).circuits
    assert failed, "the crossing beside the limit was not located by bisection: the test tests nothing"
    # each assembly's trace stops, named, at its first step: neither claims the other's assembly
    assert [(c.status, c.members, c.steps) for c in found] == [("unlocated", (0,), 1), ("unlocated", (1,), 1)]


def test_the_crossing_locator_raises_rather_than_returning_a_piece_end(monkeypatch):
    _failing_inside_crossings(monkeypatch)
    m = load(SAMPLES / "fourbar_me581.toml")
    start = circuits_module.assemblies(m, radians(NEAR_LIMIT_DEG))
    curve = circuits_module._Curve(m)
    a = np.array([*start.real[0].q, start.driver]) / curve.scale
    t = circuits_module._tangent(curve.at(a)[1], None)
    with pytest.raises(CrossingNotLocated, match="corrects onto the curve"):
        circuits_module._crossing_on_arc(curve, start, a, t, 0.0, 0.01, -1e-6)

"""A circuit traced from a start within a hair of a limit position (`linkage assemblies
--sweep` at a driver value near a fold) reports the circuit's own limit positions, the
crank angles where the coupler and rocker are collinear (Norton, "Design of Machinery",
section 4.12: the diagonal A-O4 is r3 + r4), evaluated at 40 digits with mpmath."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from mpmath import acos, asin, mp, mpf
from mpmath import degrees as mp_degrees

from linkage.kinematics.circuits import circuits
from linkage.kinematics.loading import load
from linkage.units import degrees, radians

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


def _me581_limit_deg() -> float:
    """The ME581 four-bar's (r1..r4 = 90, 30, 60, 45) limit crank angle: the law of cosines
    on the triangle O2-A-O4 with A-O4 = r3 + r4 (40 digits)."""
    with mp.workdps(40):
        r1, r2, d = mpf(90), mpf(30), mpf(60) + mpf(45)
        return float(mp_degrees(acos((r1 * r1 + r2 * r2 - d * d) / (2 * r1 * r2))))


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("gap_deg", [1e-3, 1e-6, 1e-9])
def test_circuit_started_near_a_limit_reports_its_two_limit_positions(side, gap_deg):
    limit = _me581_limit_deg()
    start = side * (limit - gap_deg)
    m = load(SAMPLES / "fourbar_me581.toml")
    c = circuits(m, radians(start))
    assert len(c.assemblies.real) == 2
    (circ,) = c.circuits
    assert circ.status == "closed" and circ.members == (0, 1)
    found = sorted(degrees(v) for v in circ.limits)
    assert found == pytest.approx([-limit, limit], abs=1e-9), found
    assert degrees(circ.driver_low) == pytest.approx(-limit, abs=1e-9)
    assert degrees(circ.driver_high) == pytest.approx(limit, abs=1e-9)


@pytest.mark.parametrize("start", ["112.02", "112.024", "112.0243"])
def test_assemblies_sweep_near_a_limit_prints_two_limit_positions(cli, start):
    out = cli("assemblies", str(SAMPLES / "fourbar_me581.toml"), "--sweep", "--set", f"theta2={start}")
    assert out.code == 0, out.err
    assert "theta2 from -112.024313 to 112.024313 deg, 2 limit positions" in out.out
    assert "unfinished" not in out.out


def _limit_deg(r1: float, r2: float, diagonal: float) -> float:
    """The crank angle at which the diagonal A-O4 is ``diagonal`` (law of cosines, 40 digits)."""
    with mp.workdps(40):
        r1_, r2_, d = mpf(r1), mpf(r2), mpf(diagonal)
        return float(mp_degrees(acos((r1_ * r1_ + r2_ * r2_ - d * d) / (2 * r1_ * r2_))))


@pytest.mark.parametrize("gap_deg", [1e-3, 1e-6, 1e-9])
@pytest.mark.parametrize("at_low", [True, False])
def test_double_rocker_started_near_either_limit_reports_both(gap_deg, at_low):
    """The Grashof double rocker r1..r4 = 100, 80, 30, 90 rocks between the folded (|r4 - r3|
    = 60) and extended (r3 + r4 = 120) diagonals; started just inside either limit, the
    circuit leaves away from it (near the low one) or through it (near the high one)."""
    low, high = _limit_deg(100, 80, 60), _limit_deg(100, 80, 120)
    start = low + gap_deg if at_low else high - gap_deg
    m = load(SAMPLES / "crank_rocker.toml").with_values({"r2": 80, "r3": 30, "r4": 90}, {})
    (circ,) = circuits(m, radians(start)).circuits
    assert circ.status == "closed" and circ.members == (0, 1)
    assert sorted(degrees(v) for v in circ.limits) == pytest.approx([low, high], abs=1e-9)


def _ulps(x: float, n: int) -> float:
    for _ in range(abs(n)):
        x = math.nextafter(x, math.inf if n > 0 else -math.inf)
    return x


@pytest.mark.parametrize("side", [1.0, -1.0])
@pytest.mark.parametrize("offset", ["-1ulp", "0", "+1ulp", "-1e-12deg", "+1e-12deg"])
def test_circuit_started_exactly_at_a_limit_is_that_limit_counted_once(side, offset):
    """Started at the limit crank angle itself (the double assembly where both branches
    meet), the trace once went round the circuit forever (+limit: 37 limits, or unfinished)
    or never counted the start's own limit (-limit: 1 limit), both 'closed' with exit 0."""
    limit = _me581_limit_deg()
    start = {"-1ulp": _ulps(limit, -1), "0": limit, "+1ulp": _ulps(limit, 1),
             "-1e-12deg": limit - 1e-12, "+1e-12deg": limit + 1e-12}[offset]
    m = load(SAMPLES / "fourbar_me581.toml")
    c = circuits(m, radians(side * start))
    (circ,) = c.circuits
    assert circ.status == "closed" and circ.members == tuple(range(len(c.assemblies.real)))
    assert sorted(degrees(v) for v in circ.limits) == pytest.approx([-limit, limit], abs=1e-9)
    assert degrees(circ.driver_low) == pytest.approx(-limit, abs=1e-9)
    assert degrees(circ.driver_high) == pytest.approx(limit, abs=1e-9)


@pytest.mark.parametrize("scale", [1e-6, 1e3])
@pytest.mark.parametrize("side", [1.0, -1.0])
def test_circuit_started_at_a_limit_is_the_same_at_any_scale(scale, side):
    limit = _me581_limit_deg()
    m = load(SAMPLES / "fourbar_me581.toml").with_values(
        {"r1": 90 * scale, "r2": 30 * scale, "r3": 60 * scale, "r4": 45 * scale}, {})
    (circ,) = circuits(m, radians(side * limit)).circuits
    assert circ.status == "closed"
    assert sorted(degrees(v) for v in circ.limits) == pytest.approx([-limit, limit], abs=1e-9)


@pytest.mark.parametrize("which", ["low", "high", "-low", "-high"])
def test_double_rocker_started_exactly_at_either_limit_reports_both(which):
    low, high = _limit_deg(100, 80, 60), _limit_deg(100, 80, 120)
    sign = -1.0 if which.startswith("-") else 1.0
    start = sign * (low if which.endswith("low") else high)
    m = load(SAMPLES / "crank_rocker.toml").with_values({"r2": 80, "r3": 30, "r4": 90}, {})
    (circ,) = circuits(m, radians(start)).circuits
    assert circ.status == "closed"
    assert sorted(abs(degrees(v)) for v in circ.limits) == pytest.approx([low, high], abs=1e-9)


@pytest.mark.parametrize("start", ["112.02431283704216", "-112.02431283704216"])
def test_assemblies_sweep_exactly_at_the_limit_prints_two_limit_positions(cli, start):
    out = cli("assemblies", str(SAMPLES / "fourbar_me581.toml"), "--sweep", "--set", f"theta2={start}")
    assert out.code == 0, out.err
    assert "theta2 from -112.024313 to 112.024313 deg, 2 limit positions" in out.out


@pytest.mark.parametrize("side", [1.0, -1.0])
def test_circuit_started_exactly_at_a_limit_passes_both_branches(side):
    """At the limit the one (double) assembly is where the two branches meet, its own name a
    matter of rounding; the circuit passes both, as the two assemblies 1e-6 deg inside say."""
    limit = _me581_limit_deg()
    m = load(SAMPLES / "fourbar_me581.toml")
    inside = circuits(m, radians(side * (limit - 1e-6)))
    (circ,) = circuits(m, radians(side * limit)).circuits
    assert len(inside.assemblies.real) == 2
    assert circ.branches == tuple(sorted(a.branch for a in inside.assemblies.real))
    assert len(set(circ.branches)) == 2


def _slider_limits_deg(r2: float, r3: float, e: float) -> tuple[float, float]:
    """An in-line-offset slider-crank with the crank r2 longer than the coupler r3 + |e|
    turns back where |r2 sin(theta2) - e| = r3: theta2 = asin((e + r3) / r2) and
    asin((e - r3) / r2) on the right-hand circuit (40 digits)."""
    with mp.workdps(40):
        return (float(mp_degrees(asin((mpf(e) - mpf(r3)) / mpf(r2)))),
                float(mp_degrees(asin((mpf(e) + mpf(r3)) / mpf(r2)))))


@pytest.mark.parametrize("at", [0, 1])
def test_slider_crank_started_exactly_at_a_limit_reports_both(at):
    low, high = _slider_limits_deg(120, 40, 10)
    m = load(SAMPLES / "slider_crank.toml").with_values({"r2": 120, "r3": 40}, {})
    c = circuits(m, radians((low, high)[at]))
    (circ,) = c.circuits
    assert circ.status == "closed" and len(set(circ.branches)) == 2
    assert sorted(degrees(v) for v in circ.limits) == pytest.approx([low, high], abs=1e-9)


def test_circuit_started_one_ulp_past_a_limit_where_no_double_assembly_is_found():
    """The drawn ME581 (joints and links) one ulp past its limit has one real assembly that
    the homotopy found as an ordinary root, not a double one: the trace went round 94 limits
    and stopped unfinished."""
    limit = _me581_limit_deg()
    m = load(SAMPLES / "fourbar_me581_joints.toml")
    (circ,) = circuits(m, radians(_ulps(limit, 1))).circuits
    assert circ.status == "closed" and len(set(circ.branches)) == 2
    assert sorted(degrees(v) for v in circ.limits) == pytest.approx([-limit, limit], abs=1e-9)


@pytest.mark.parametrize("which", [2, 4])
def test_a_circuit_touching_the_start_value_at_a_limit_has_the_double_assembly_there(which):
    """The six-limit circuit of the offset slider, started at one of its limits: the other
    assemblies' circuit touches the start value there without crossing it, and the double
    assembly at the limit is on it, not traced again as a second circuit (it was, unfinished).
    The reference: the same circuit traced from the file's start value, away from any limit."""
    m = load(SAMPLES / "offset_slider.toml")
    (ref,) = circuits(m).circuits
    assert ref.status == "closed" and len(ref.limits) == 6
    c = circuits(m, ref.limits[which])
    assert c.assemblies.multiplicity.count(2) == 1  # the start is a limit: else the test tests nothing
    (circ,) = c.circuits
    assert circ.status == "closed" and circ.members == tuple(range(len(c.assemblies.real)))
    assert sorted(degrees(v) for v in circ.limits) == pytest.approx(sorted(degrees(v) for v in ref.limits),
                                                                     abs=1e-9)


SLIDER_DRIVEN = """
name = "slider-driven slider-crank"
length_unit = "mm"
[parameters]
r2 = { value = 40, unit = "mm" }
r3 = { value = 120, unit = "mm" }
e = { value = 10, unit = "mm", signed = true }
[driver]
name = "s"
value = 150
unit = "mm"
[unknowns]
theta2 = { guess = 45, unit = "deg" }
theta3 = { guess = 0, unit = "deg" }
[[loops]]
name = "O2-A-B"
vectors = [
  { length = "r2", angle = "theta2" },
  { length = "r3", angle = "theta3" },
  { length = "s", angle = 0, sign = -1 },
  { length = "e", angle = 90, sign = -1 },
]
"""


@pytest.mark.parametrize("at", [0, 1])
def test_slider_driven_slider_crank_started_exactly_at_a_limit_reports_both(tmp_path, at):
    """A length driver: the slide s of an offset slider-crank (crank 40, coupler 120,
    offset 10) turns back where crank and coupler line up, s = sqrt((r3 -+ r2)^2 - e^2)
    (40 digits); started at either, it once reported 138 or 3 limit positions, exit 0."""
    with mp.workdps(40):
        low, high = (float(mp.sqrt(mpf(80) ** 2 - 100)), float(mp.sqrt(mpf(160) ** 2 - 100)))
    path = tmp_path / "slider_driven.toml"
    path.write_text(SLIDER_DRIVEN)
    m = load(path)
    (circ,) = circuits(m, (low, high)[at]).circuits
    assert circ.status == "closed" and len(set(circ.branches)) == 2
    assert sorted(circ.limits) == pytest.approx([low, high], abs=1e-9 * high)

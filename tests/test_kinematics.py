"""Velocities, accelerations, joints and points on links, each against an independent
reference: worked example P7, docs/worked_examples.md, closed forms differentiated by mpmath, central
differences."""

from __future__ import annotations

import cmath
import json
import math
from pathlib import Path

import mpmath as mp
import pytest

import linkage
from linkage import load_mechanism
from linkage.problems.closed_form import fourbar_positions

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
ME581 = str(SAMPLES / "fourbar_me581.toml")

P7 = {"theta3": (-3.901274121944855, 5.892333757673076), "theta4": (5.353311575177702, 71.37419488746042)}


def test_p7_velocities_and_accelerations(cli):
    doc = json.loads(cli("solve", ME581, "--speed", "10", "--accel", "5", "--format", "json").out)
    assert doc["converged"] and doc["branch"] == "open"
    for name, (w, a) in P7.items():
        assert doc["velocities"][name] == pytest.approx(w, abs=1e-9)
        assert doc["accelerations"][name] == pytest.approx(a, abs=1e-9)


def test_p7_joint_rates_are_the_derivatives_of_r_e_it(cli):
    """A = r2 e^(i t2), B = A + r3 e^(i t3): their velocities and accelerations from P7's
    angular rates, computed here without the engine."""
    doc = json.loads(cli("solve", ME581, "--speed", "10", "--accel", "5", "--format", "json").out)
    t2, t3 = math.radians(65.0), math.radians(doc["solution"]["theta3"])
    w2, a2 = 10.0, 5.0
    w3, a3 = P7["theta3"]
    e2, e3 = cmath.exp(1j * t2), cmath.exp(1j * t3)
    vA = 1j * 30 * w2 * e2
    aA = (1j * 30 * a2 - 30 * w2 * w2) * e2
    vB = vA + 1j * 60 * w3 * e3
    aB = aA + (1j * 60 * a3 - 60 * w3 * w3) * e3
    for name, v, a in (("A", vA, aA), ("B", vB, aB)):
        assert doc["joint_velocities"][name] == pytest.approx([v.real, v.imag], abs=1e-8)
        assert doc["joint_accelerations"][name] == pytest.approx([a.real, a.imag], abs=1e-7)
    assert doc["joint_velocities"]["O2"] == [0, 0] and doc["joint_velocities"]["O4"] == [0, 0]
    assert doc["joints"]["O4"] == [90, 0]


@pytest.mark.parametrize("theta2", [0.0, 37.0, 100.0, 215.0, 300.0])
@pytest.mark.parametrize("speed,accel", [("600rpm", "0"), ("10", "5"), ("-3rad/s", "90deg/s^2")])
def test_slider_crank_rates_match_the_closed_form_differentiated(cli, theta2, speed, accel):
    m = load_mechanism(SAMPLES / "slider_crank.toml")
    v = {k: q.value for k, q in m.parameters.items()}
    r2, r3, e = v["r2"], v["r3"], v["e"]
    w = {"600rpm": 20 * math.pi, "10": 10.0, "-3rad/s": -3.0}[speed]
    al = {"0": 0.0, "5": 5.0, "90deg/s^2": math.pi / 2}[accel]
    mp.mp.dps = 40

    def s_of(t: mp.mpf) -> mp.mpf:  # the slider's closed form along the motion theta2(t)
        th2 = mp.radians(theta2) + w * t + al * t * t / 2
        th3 = mp.asin((e - r2 * mp.sin(th2)) / r3)
        return r2 * mp.cos(th2) + r3 * mp.cos(th3)

    ds, d2s = (float(mp.diff(s_of, 0, k)) for k in (1, 2))
    doc = json.loads(cli("solve", str(SAMPLES / "slider_crank.toml"), "--set", f"theta2={theta2}",
                         "--speed", speed, "--accel", accel, "--format", "json").out)
    assert doc["converged"]
    assert doc["velocities"]["s"] == pytest.approx(ds, rel=1e-9, abs=1e-9 * abs(w) * r2)
    assert doc["accelerations"]["s"] == pytest.approx(d2s, rel=1e-9, abs=1e-9 * (w * w + abs(al)) * r2)


@pytest.mark.parametrize("path", sorted(SAMPLES.glob("*.toml")), ids=lambda p: p.name)
def test_sweep_velocities_are_the_derivatives_of_the_sweep_positions(path):
    """With driver speed 1 rad/s, dq/dt = dq/dtheta2: central differences of the sweep's own
    positions (h = 1e-3 deg) agree to 1e-6 relative, away from singular positions."""
    m = load_mechanism(path)
    h = 1e-3
    for base in (10.0, 75.0, 140.0, 205.0, 290.0):
        r = linkage.sweep(m, [base - h, base, base + h], speed=1.0)
        lo, mid, hi = r.positions
        if not all(p.status == "converged" for p in r.positions) or abs(mid.det) < 1e-3 * m.length_scale ** 2:
            continue
        scale = math.radians(2 * h) if m.driver.kind == "angle" else 2 * h
        for u in m.unknowns:
            k = math.pi / 180.0 if u.kind == "angle" else 1.0
            fd = (hi.solution[u.name] - lo.solution[u.name]) * k / scale
            got = mid.rates.velocities[u.name]
            assert got == pytest.approx(fd, rel=1e-6, abs=1e-6 * (1 + abs(fd))), (path.name, base, u.name)


def test_coupler_point_path_matches_the_closed_form():
    """Point P of crank_rocker.toml: A + 60 e^(i (theta3 + 30 deg)), theta3 from the circle
    intersection (open branch), over a whole crank turn."""
    m = load_mechanism(SAMPLES / "crank_rocker.toml")
    r = linkage.sweep(m, [float(k) for k in range(0, 361, 3)], joints=True)
    for p in r.positions:
        t2 = math.radians(p.input)
        t3 = fourbar_positions(100, 40, 120, 80, 0.0, theta2=t2)["open"]["theta3"]
        a = 40 * cmath.exp(1j * t2)
        want = a + 60 * cmath.exp(1j * (t3 + math.radians(30)))
        got = p.rates.joints["P"]
        assert got[0] == pytest.approx(want.real, abs=1e-9) and got[1] == pytest.approx(want.imag, abs=1e-9)


def test_watt_sixbar_joints_start_the_second_loop_at_the_rocker_pivot(cli):
    doc = json.loads(cli("solve", str(SAMPLES / "watt_sixbar.toml"), "--format", "json").out)
    j = doc["joints"]
    assert j["O2"] == [0, 0] and j["O4"] == [100, 0]
    o6 = 100 + 120 * cmath.exp(1j * math.radians(60))
    assert j["O6"] == pytest.approx([o6.real, o6.imag])
    t4 = math.radians(doc["solution"]["theta4"])
    c = complex(100, 0) + 70 * cmath.exp(1j * (t4 + math.radians(40)))
    assert j["C"] == pytest.approx([c.real, c.imag], abs=1e-9)


def test_rates_at_a_singular_position_say_so():
    """At a toggle the Jacobian is singular: no velocities, a named status."""
    from linkage.kinematics.rates import position_rates
    from linkage.problems.loops import LoopModel

    m = load_mechanism(ME581)
    model = LoopModel.compile(m)
    # theta3 = theta4: the coupler and rocker in line, det J = 0
    rates = position_rates(model, [math.radians(30.0), math.radians(30.0)], math.radians(65.0), 10.0, 0.0)
    assert rates.status == "undefined" and not rates.velocities


@pytest.mark.parametrize("args", [
    ("--speed", "10rpmx"), ("--speed", "fast"), ("--accel", "5"), ("--speed", "1e400"),
    ("--speed", "10mm/s"),
])
def test_bad_driver_motion_is_one_line(cli, args):
    run = cli("solve", ME581, *args)
    assert run.code == 2 and run.err.startswith("error: ") and len(run.err.strip().splitlines()) == 1


def test_points_must_hang_from_a_named_joint(cli, tmp_path):
    text = (SAMPLES / "crank_rocker.toml").read_text().replace('from = "A"', 'from = "Z"')
    bad = tmp_path / "m.toml"
    bad.write_text(text)
    run = cli("solve", str(bad))
    assert run.code == 2 and "points.P.from" in run.err


def test_sweep_json_and_csv_carry_rates_and_joints(cli):
    doc = json.loads(cli("sweep", str(SAMPLES / "crank_rocker.toml"), "--step", "90", "--speed", "600rpm",
                         "--format", "json").out)
    p = doc["positions"][1]
    assert set(p) >= {"velocities", "accelerations", "joints", "joint_velocities", "joint_accelerations"}
    assert "P" in p["joints"] and doc["driver_motion"]["speed"] == pytest.approx(20 * math.pi)
    csv = cli("sweep", str(SAMPLES / "crank_rocker.toml"), "--step", "90", "--speed", "10", "--format",
              "csv").out.splitlines()
    assert "dtheta4/dt (rad/s)" in csv[0] and "P.vx (mm/s)" in csv[0] and len(csv) == 6


def test_public_position_rates_after_solve_system():
    m = load_mechanism(ME581)
    r = linkage.solve_system(m.problem(), tol=1e-12)
    rates = linkage.position_rates(m, r.x, speed=10.0, accel=5.0)
    assert rates.velocities["theta4"] == pytest.approx(P7["theta4"][0], abs=1e-9)
    assert rates.joints["B"] == pytest.approx(list(linkage.position_rates(m, r.x).joints["B"]))

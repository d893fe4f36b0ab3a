"""Loads (issue 23): the matrix method against virtual power on every joints sample and on
random four-bars, slider-cranks and six-bars, with and without masses; global equilibrium;
a static four-bar against its free bodies worked by hand; toggles flagged.

A textbook's printed answer (done-when 1) is in test_textbook_forces.py (a slider-crank's
kinetostatics); a four-bar static analysis with a printed answer could not be reached from
this machine."""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest

from linkage.cli import run_cli
from linkage.kinematics.forces import forces_at
from linkage.kinematics.loading import load, parse_mechanism
from linkage.problems.loads import Loads, Mass
from linkage.problems.templates import template

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
JOINT_SAMPLES = sorted(SAMPLES.glob("*_joints.toml"))


def _loads_for(m, rng: random.Random, masses: bool) -> Loads:
    d = m.extra["drawing"]
    links = [b for b in d.bodies if b != "ground"]
    moving = [j for j in d.xy if j not in d.ground]
    forces = {rng.choice(moving): (rng.uniform(-100, 100), rng.uniform(-100, 100))}
    torques = {rng.choice(links): rng.uniform(-10, 10)}
    mass = {}
    if masses:
        for b in links:
            xs = [d.xy[j] for j in d.bodies[b]]
            cx = sum(p[0] for p in xs) / len(xs) + rng.uniform(-5, 5)
            cy = sum(p[1] for p in xs) / len(xs) + rng.uniform(-5, 5)
            mass[b] = Mass(rng.uniform(0.1, 3.0), (cx, cy), rng.uniform(1e-4, 1e-2))
    return Loads(forces, torques, mass, (0.0, -9.81) if masses else None)


def _check(m, q, loads: Loads, speed: float, accel: float, driver: float | None = None) -> None:
    f = forces_at(m, q, loads, speed=speed, accel=accel, driver=driver)
    if f.status == "undefined":
        return
    scale = max([abs(f.input)] + [p.magnitude for p in f.pins] + [1e-12])
    assert f.input == pytest.approx(f.virtual_power_input, rel=1e-9, abs=1e-9 * scale)
    # global equilibrium: the ground carries the applied loads, inertia included
    fx, fy, mz = f.applied
    size = max(scale, abs(fx), abs(fy), abs(mz), 1e-12)
    assert f.ground_force[0] == pytest.approx(fx, abs=1e-9 * size)
    assert f.ground_force[1] == pytest.approx(fy, abs=1e-9 * size)
    assert f.ground_moment == pytest.approx(mz, abs=1e-9 * size * 10)


def _internal(m, values: dict, unknowns=None) -> list[float]:
    return [math.radians(values[u.name]) if u.kind == "angle" else values[u.name] for u in m.unknowns]


def _positions(m, offsets) -> list[tuple[list[float], float]]:
    """Solved positions near the drawn one: (q, driver), internal units."""
    from linkage.kinematics.sweep import sweep_mechanism

    angle = m.driver.kind == "angle"
    shown = math.degrees(m.driver.value) if angle else m.driver.value
    out = [([u.value for u in m.unknowns], m.driver.value)]
    r = sweep_mechanism(m, [shown + k for k in offsets])
    for pos in r.positions:
        if pos.status == "converged":
            out.append((_internal(m, pos.solution), math.radians(pos.input) if angle else pos.input))
    return out


@pytest.mark.parametrize("path", JOINT_SAMPLES, ids=lambda p: p.stem)
@pytest.mark.parametrize("masses", [False, True])
def test_virtual_power_equals_the_matrix_method_on_every_sample(path: Path, masses: bool) -> None:
    m = load(path)
    rng = random.Random(path.stem)
    positions = _positions(m, (-5.0, 3.0, 11.0))
    assert len(positions) >= 3
    for q, drv in positions:
        loads = _loads_for(m, rng, masses)
        for speed, accel in ((0.0, 0.0), (3.0, 0.0), (3.0, -2.0)):
            f = forces_at(m, q, loads, speed=speed, accel=accel, driver=drv)
            assert f.status in ("ok", "near_toggle", "ill_conditioned")
            _check(m, q, loads, speed, accel, drv)


def _random_mechanism(kind: str, rng: random.Random):
    from linkage.errors import InputError

    base = {"fourbar": (40, 120, 80, 100), "slider-crank": (40, 120, 10),
            "watt": (40, 120, 80, 100, 70, 110, 80, 120),
            "stephenson": (40, 120, 80, 100, 60, 100, 90, 160)}[kind]
    for _ in range(200):
        links = [v * rng.uniform(0.7, 1.3) if i != 2 or kind != "slider-crank" else rng.uniform(-20, 20)
                 for i, v in enumerate(base)]
        try:
            doc = template(kind, links, rng.uniform(0, 360), rng.choice(["open", "crossed"]) if kind in
                           ("fourbar", "slider-crank") else rng.choice(["open", "crossed"]) + "/" +
                           rng.choice(["open", "crossed"]))
        except InputError:
            continue
        try:
            return parse_mechanism(doc, f"random {kind}")
        except Exception:
            continue
    pytest.skip(f"no assemblable random {kind}")


@pytest.mark.parametrize("kind", ["fourbar", "slider-crank", "watt", "stephenson"])
def test_virtual_power_on_random_mechanisms(kind: str) -> None:
    rng = random.Random(kind)
    checked = 0
    for i in range(50):
        m = _random_mechanism(kind, rng)
        q = [u.value for u in m.unknowns]
        loads = _loads_for(m, rng, masses=bool(i % 2))
        speed, accel = rng.uniform(-20, 20), rng.uniform(-50, 50)
        f = forces_at(m, q, loads, speed=speed, accel=accel)
        if f.status != "undefined":
            _check(m, q, loads, speed, accel)
            checked += 1
    assert checked >= 45


def test_static_fourbar_against_its_free_bodies() -> None:
    """A torque T on the rocker, massless links: the coupler is a two-force member, so the
    force it carries lies along A -> B; the rocker's moment about O4 gives its size, the
    crank's about O2 the input torque (worked here from the joints' positions alone)."""
    m = load(SAMPLES / "fourbar_me581_joints.toml")
    q = [u.value for u in m.unknowns]
    f = forces_at(m, q, Loads(torques={"rocker": 5.0}))
    from linkage.kinematics.rates import rates_at

    pts = {k: (x / 100.0, y / 100.0) for k, (x, y) in rates_at(m, q).joints.items()}  # cm -> m
    ax, ay = pts["A"]
    bx, by = pts["B"]
    ox, oy = pts["O4"]
    length = math.hypot(bx - ax, by - ay)
    ux, uy = (bx - ax) / length, (by - ay) / length
    # force on the rocker at B from the coupler: F u; moment about O4: (B - O4) x F u + T = 0
    arm = (bx - ox) * uy - (by - oy) * ux
    size = -5.0 / arm
    # on the crank at A from the coupler: -F u; input T_in + (A - O2) x (-F u) = 0
    t_in = -(-(ax * uy - ay * ux) * size)
    assert f.input == pytest.approx(t_in, rel=1e-12)
    pin_b = next(p for p in f.pins if p.joint == "B")
    assert (pin_b.fx, pin_b.fy) == pytest.approx((size * ux, size * uy), rel=1e-12)
    assert f.mechanical_advantage == pytest.approx(abs(5.0 / t_in), rel=1e-12)


def test_forces_near_a_limit_are_flagged_not_bare() -> None:
    """The ME581 four-bar's crank meets a limit (crank and coupler in line) at the end of its
    feasible range; within 1e-9 to 1e-3 deg of it the force matrix nears singular: flagged,
    never a bare number."""
    from linkage.kinematics.sweep import sweep_mechanism

    m = load(SAMPLES / "fourbar_me581_joints.toml")
    r = sweep_mechanism(m, [i * 0.5 for i in range(720)])
    # the sweep locates each limit to rounding: the ends of its feasible ranges inside 0..360
    (_, hi1), (lo2, _) = r.feasible_ranges
    p = m.parameters
    c = (p["crank"].value ** 2 + p["ground"].value ** 2 - (p["coupler"].value + p["rocker"].value) ** 2) / (
        2 * p["crank"].value * p["ground"].value)
    assert hi1 == pytest.approx(math.degrees(math.acos(c)), abs=1e-9)  # |A - O4| = coupler + rocker
    seen = 0
    for b, inward in ((hi1, -1.0), (lo2, 1.0)):
        for gap in (1e-9, 1e-6, 1e-3):
            value = b + inward * gap
            pos = sweep_mechanism(m, [value]).positions[0]
            if pos.status != "converged":
                continue
            q = _internal(m, pos.solution)
            f = forces_at(m, q, Loads(torques={"rocker": 5.0}), driver=math.radians(value))
            assert f.status in ("near_toggle", "ill_conditioned", "undefined"), (gap, f.status)
            seen += 1
    assert seen >= 3


def test_solve_prints_the_loads_and_refuses_bad_ones(tmp_path, capsys) -> None:
    text = (SAMPLES / "fourbar_me581_joints.toml").read_text() + (
        "\n[loads]\nrocker = { torque = 5 }\n\n[mass]\n"
        "coupler = { mass = 1.2, cg = [60, 20], inertia = 0.004 }\n")
    path = tmp_path / "loaded.toml"
    path.write_text(text)
    assert run_cli(["solve", str(path), "--speed", "10", "--gravity", "9.81", "-f", "json"]) == 0
    import json

    doc = json.loads(capsys.readouterr().out)
    forces = doc["forces"]
    assert forces["status"] == "ok"
    assert forces["input"] == pytest.approx(forces["virtual_power_input"], rel=1e-9)
    for argv, words in (
        (["--load", "Z=0,1"], "a force acts at a joint"),
        (["--load", "B=0"], "FX,FY"),
        (["--torque", "ground=1"], "a torque acts on a moving link"),
        (["--load", "O2=0,-10"], "O2 is a fixed joint"),
        (["--gravity", "1,2,3"], "--gravity"),
    ):
        code = run_cli(["solve", str(path), *argv])
        err = capsys.readouterr().err.strip()
        assert code == 2 and err.startswith("error:") and "\n" not in err and words in err, (argv, err)
    code = run_cli(["solve", str(SAMPLES / "fourbar_me581.toml"), "--torque", "r4=1"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "joints form" in err


def test_solve_near_a_limit_says_near_toggle(capsys) -> None:
    """The command line at 1e-3 deg from the ME581's limit: the forces carry the flag."""
    import json

    c = (30.0 ** 2 + 90.0 ** 2 - 105.0 ** 2) / (2 * 30.0 * 90.0)
    value = math.degrees(math.acos(c)) - 1e-3
    code = run_cli(["solve", str(SAMPLES / "fourbar_me581_joints.toml"), "--set", f"theta_crank={value!r}",
                    "--torque", "rocker=5", "-f", "json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and doc["forces"]["status"] in ("near_toggle", "ill_conditioned")
    code = run_cli(["solve", str(SAMPLES / "fourbar_me581_joints.toml"), "--set", f"theta_crank={value!r}",
                    "--torque", "rocker=5", "-f", "plain"])
    out = capsys.readouterr().out
    assert code == 0 and ("near_toggle" in out or "ill_conditioned" in out)


def test_sweep_gives_the_loads_as_columns_and_plots_the_torque(tmp_path, capsys) -> None:
    import json

    from linkage.kinematics.sweep import sweep_mechanism

    crank = SAMPLES / "crank_rocker_joints.toml"
    picture = tmp_path / "torque.png"
    code = run_cli(["sweep", str(crank), "--step", "30", "--torque", "rocker=5", "--speed", "10",
                    "--torque-plot", str(picture), "-f", "json"])
    doc = json.loads(capsys.readouterr().out)
    assert code == 0 and picture.stat().st_size > 5000
    table = next(t for t in doc["tables"] if t["name"] == "loads")
    rows = [dict(zip(table["columns"], r)) for r in table["rows"]]
    assert len(rows) == 13
    m = load(crank)
    result = sweep_mechanism(m, [r["theta_crank"] for r in rows])
    for row, pos in zip(rows, result.positions):
        q = _internal(m, pos.solution)
        f = forces_at(m, q, Loads(torques={"rocker": 5.0}), speed=10.0, driver=math.radians(pos.input))
        assert row["input"] == pytest.approx(f.input, rel=1e-12)
        assert row["input"] == pytest.approx(f.virtual_power_input, rel=1e-9)
        assert row["forces_status"] == f.status
    code = run_cli(["sweep", str(crank), "--step", "30", "--torque-plot", str(tmp_path / "t.png")])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "--torque-plot needs loads" in err


@pytest.mark.parametrize("theta_deg", [10.0, 45.0, 100.0, 200.0, 300.0])
def test_slider_crank_kinetostatics_against_its_closed_form(theta_deg: float) -> None:
    """The offset slider-crank (crank 40 mm, coupler 120 mm, offset e = 10 mm) with a 2 kg
    block, massless crank and coupler, the crank at a constant 100 rad/s: the block's
    position x(theta) = r cos(theta) + sqrt(l^2 - (r sin(theta) - e)^2) in closed form, its
    acceleration x'' = x_thetatheta omega^2, the coupler a two-force member, so the input
    torque is m x'' x_theta (by d'Alembert on the block and the crank's moment), the rod's
    force m x'' along the rod's horizontal, and the block's normal force its vertical share.
    The derivatives of x are differentiated here by hand, not by the tool."""
    r, l_, e, m, w = 0.040, 0.120, 0.010, 2.0, 100.0
    t = math.radians(theta_deg)
    s = r * math.sin(t) - e
    root = math.sqrt(l_ * l_ - s * s)
    x_t = -r * math.sin(t) - s * r * math.cos(t) / root
    ds = r * math.cos(t)
    x_tt = -r * math.cos(t) - (ds * ds - s * r * math.sin(t)) / root - (s * ds) ** 2 / root ** 3
    acc = x_tt * w * w
    torque = m * acc * x_t
    m_ = load(SAMPLES / "slider_crank_joints.toml")
    from linkage.kinematics.sweep import sweep_mechanism

    pos = sweep_mechanism(m_, [theta_deg]).positions[0]
    assert pos.status == "converged"
    q = _internal(m_, pos.solution)
    f = forces_at(m_, q, Loads(masses={"block": Mass(m, (146.88311367414514, 10.0), 0.0)}), speed=w,
                  driver=t)
    assert f.status == "ok"
    assert f.input == pytest.approx(torque, rel=1e-9)
    # the rod pushes the block with m x'' along x; its line of action is the rod's
    rod = next(p for p in f.pins if p.joint == "B")
    assert rod.fx == pytest.approx(m * acc, rel=1e-9, abs=1e-9)
    ax_, ay_ = r * math.cos(t), r * math.sin(t)
    xb = r * math.cos(t) + root
    assert rod.fy / rod.fx == pytest.approx((e - ay_) / (xb - ax_), rel=1e-9)
    block = f.sliders[0]
    assert block.normal == pytest.approx(-rod.fy, rel=1e-9, abs=1e-9)


def test_loads_in_other_units_are_converted_on_read(tmp_path) -> None:
    base = (SAMPLES / "fourbar_me581_joints.toml").read_text()
    si = base + ('\n[loads]\nrocker = { torque = 0.5 }\nB = { force = [0, -4.4482216152605] }\n\n[mass]\n'
                 'coupler = { mass = 0.45359237, cg = [60, 20], inertia = 0.0004 }\n')
    other = base + ('\n[loads]\nrocker = { torque = 500, unit = "N mm" }\n'
                    'B = { force = [0, -1], unit = "lbf" }\n\n[mass]\n'
                    'coupler = { mass = 1, mass_unit = "lb", cg = [60, 20], inertia = 400, '
                    'inertia_unit = "kg mm^2" }\n')
    results = []
    for name, text in (("si", si), ("other", other)):
        path = tmp_path / f"{name}.toml"
        path.write_text(text)
        m = load(path)
        results.append(forces_at(m, [u.value for u in m.unknowns], speed=5.0, accel=1.0))
    assert results[0].input == pytest.approx(results[1].input, rel=1e-14)
    bad = tmp_path / "bad.toml"
    bad.write_text(base + '\n[loads]\nrocker = { torque = 5, unit = "ft lb" }\n')
    from linkage.errors import LinkageError

    with pytest.raises(LinkageError, match="is not one of N m, N mm"):
        load(bad)


def test_a_sliding_driver_gets_an_input_force(tmp_path) -> None:
    """The slider-crank driven by its block: the input is a force (N) along the line, equal
    to the virtual-power answer with and without masses; the ground carries the loads."""
    text = (SAMPLES / "slider_crank_joints.toml").read_text()
    text = text.replace('link = "crank"', 'slider = "block"')
    text = text.replace("value = 45 ", "value = 146.88311367414514 ")
    path = tmp_path / "driven_by_block.toml"
    path.write_text(text)
    m = load(path)
    assert m.driver.kind == "length"
    rng = random.Random(3)
    for q, drv in _positions(m, (-20.0, 15.0)):
        for masses in (False, True):
            loads = _loads_for(m, rng, masses)
            for speed, accel in ((0.0, 0.0), (100.0, 0.0), (100.0, 30.0)):
                f = forces_at(m, q, loads, speed=speed, accel=accel, driver=drv)
                assert f.input_unit == "N" and f.status in ("ok", "near_toggle")
                _check(m, q, loads, speed, accel, drv)


@pytest.mark.parametrize("path", JOINT_SAMPLES, ids=lambda p: p.stem)
def test_the_unit_speed_motion_takes_the_rotations_found_once(path: Path) -> None:
    """The matrix method finds each body's rotation once for both of its motions
    (load_matrix.body_motion's ``turned``): the same numbers as found again."""
    import numpy as np

    from linkage.kinematics.bodies import Frame
    from linkage.kinematics.load_matrix import body_motion
    from linkage.kinematics.placing import place_motion_np
    from linkage.kinematics.rates import motions_rates_np
    from linkage.problems.loops import LoopModel

    m = load(path)
    model = LoopModel.compile(m, {})
    q = [np.full(3, u.value) for u in m.unknowns]
    d = np.full(3, m.driver.value)
    ((qd, qdd),), _ = motions_rates_np(model, q, d, ((1.5, 0.25),))
    placed = place_motion_np(model, q, d, qd, 1.5, qdd, 0.25)
    pos, vel, acc = ({j: (v[i].real, v[i].imag) for j, v in placed.items()} for i in range(3))
    frame = Frame.of(m)
    first = body_motion(frame, pos, vel, acc)
    still = {j: (np.zeros(3), np.zeros(3)) for j in pos}
    again, reused = body_motion(frame, pos, vel, still), body_motion(frame, pos, vel, still, turned=first)
    assert again.keys() == reused.keys()
    for b in again:
        for x, y in zip(again[b], reused[b]):
            np.testing.assert_array_equal(x, y)

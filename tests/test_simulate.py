"""linkage simulate (kinematics.dynamics, docs/simulate.md): the forward dynamics against a
closed form, the kinetostatic matrix method and energy conservation computed independently
here; its events and refusals."""

from __future__ import annotations

import json
import math
import random
import re
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.errors import InputError, ParseError
from linkage.kinematics.loading import from_text
from linkage.problems.expression import function_of

pytest.importorskip("scipy")

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = ROOT / "sample_inputs"
CRANK_ROCKER = (SAMPLES / "crank_rocker_joints.toml").read_text()
ME581 = (SAMPLES / "fourbar_me581_joints.toml").read_text()
LOADED = ROOT / "docs" / "crank_rocker_loads.toml"


def _with(text: str, extra: str, name: str = "test") -> linkage.Mechanism:
    return from_text(text + "\n" + extra, name)


# --- the closed form --------------------------------------------------------------------------


@pytest.mark.parametrize("torque,omega0", [(2.0, 0.0), (-0.5, 30.0), (0.0, 12.0)])
def test_a_crank_inertia_alone_under_constant_torque_follows_the_closed_form(torque, omega0):
    """Massless coupler and rocker, the crank's mass centred on its pivot: I = I_crank, a
    constant, so theta(t) = theta0 + omega0 t + T t^2 / (2 I) and omega^2 = omega0^2 +
    2 T (theta - theta0) / I."""
    inertia = 0.05
    m = _with(CRANK_ROCKER, f"[mass]\ncrank = {{ mass = 1.5, cg = [0, 0], inertia = {inertia} }}\n")
    sim = linkage.simulate(m, str(torque), (0.0, 1.0), omega0=omega0, samples=51)
    assert sim.event is None
    theta0 = math.radians(30.0)
    t = sim.t
    exact = theta0 + omega0 * t + torque * t * t / (2.0 * inertia)
    span = max(float(np.ptp(exact)), 1.0)
    assert np.max(np.abs(sim.theta - exact)) <= 1e-8 * span
    w2 = omega0 ** 2 + 2.0 * torque * (sim.theta - theta0) / inertia
    assert np.max(np.abs(sim.omega ** 2 - w2)) <= 1e-8 * max(float(np.max(w2)), 1.0)
    assert np.allclose(sim.alpha, torque / inertia, rtol=1e-12, atol=1e-12)


def test_a_sliding_driver_with_the_only_mass_follows_the_closed_form(cli, tmp_path):
    """The offset slider-crank driven by its block, the block's 2 kg the only mass, a constant
    3 N along its line: x(t) = x0 + v0 t + F t^2 / (2 m), in m inside and mm on the page."""
    text = (SAMPLES / "slider_crank_joints.toml").read_text()
    text = text.replace('link = "crank"', 'slider = "block"')
    text = text.replace("value = 45 ", "value = 146.88311367414514 ")
    text += "\n[mass]\nblock = { mass = 2.0, cg = [146.88311367414514, 10.0], inertia = 0 }\n"
    m = from_text(text, "block-driven")
    sim = linkage.simulate(m, "3", (0.0, 0.05), omega0=200.0, samples=11)  # 200 mm/s
    assert sim.event is None and sim.sliding
    exact = 0.14688311367414514 + 0.2 * sim.t + 3.0 * sim.t ** 2 / 4.0
    assert np.max(np.abs(sim.theta - exact)) <= 1e-8 * 0.01
    assert sim.drive_check <= 1e-10
    path = tmp_path / "block.toml"
    path.write_text(text)
    r = cli("simulate", str(path), "--drive", "3", "--omega0", "200mm/s", "--time", "0:0.05",
            "--samples", "3", "-f", "csv", "--table", "motion")
    assert r.code == 0, r.err
    header, first = r.out.splitlines()[0:2]  # one table: no "# motion" line above it
    assert header.startswith("t (s),s_block (mm),ds_block/dt (mm/s),d2s_block/dt2 (mm/s^2),drive (N)")
    assert first.startswith("0.0,146.88311367414514,200.0,")


# --- the kinetostatic matrix method ---------------------------------------------------------


def test_the_simulated_motion_needs_exactly_the_simulated_drive_from_linkage_forces():
    """Each output time's (speed, acceleration) fed to linkage.forces with the file's loads
    and gravity (no friction): its input plus the flywheel's I_f alpha is the drive."""
    m = linkage.load_mechanism(LOADED)
    loads = m.extra["loads"].merged(linkage.Loads(gravity=(0.0, -9.81)))
    sim = linkage.simulate(m, "T0*(1 - omega/w0)", (0.0, 0.5), constants={"T0": 5.0, "w0": 40.0},
                           loads=loads, flywheel=0.01, samples=21)
    assert sim.event is None
    worst = 0.0
    for i in range(0, len(sim.t), 4):
        q = [sim.unknowns[u.name][i] for u in m.unknowns]
        f = linkage.forces(m, q, loads, speed=float(sim.omega[i]), accel=float(sim.alpha[i]),
                           driver=float(sim.theta[i]))
        worst = max(worst, abs(f.input + 0.01 * sim.alpha[i] - sim.drive[i]))
    assert worst <= 1e-9 * 5.0
    assert sim.drive_check <= 1e-10


def test_friction_enters_the_kinetostatic_check_as_torques_on_the_links():
    m = linkage.load_mechanism(LOADED)
    sim = linkage.simulate(m, "3", (0.0, 0.3), omega0=20.0, flywheel=0.005, samples=11,
                           friction_viscous={"*": 2e-3, "B": 5e-3}, friction_coulomb=0.01)
    assert sim.event is None
    assert sim.drive_check <= 1e-10
    assert sim.balance <= 1e-8
    assert sim.work_friction[-1] < 0.0  # friction takes energy out


# --- energy ------------------------------------------------------------------------------------


def _random_fourbar(rng: random.Random) -> str:
    ground = rng.uniform(80.0, 120.0)
    a = rng.uniform(0.0, 2.0 * math.pi)
    A = (rng.uniform(20.0, 50.0) * math.cos(a), rng.uniform(20.0, 50.0) * math.sin(a))
    B = (rng.uniform(40.0, 140.0), rng.uniform(20.0, 90.0))
    cg = {k: (rng.uniform(-30, 150), rng.uniform(-30, 90)) for k in ("crank", "coupler", "rocker")}
    masses = "\n".join(f"{k} = {{ mass = {rng.uniform(0.05, 2.0)!r}, cg = [{x!r}, {y!r}], "
                       f"inertia = {rng.uniform(1e-5, 1e-2)!r} }}" for k, (x, y) in cg.items())
    return (f'name = "random"\nlength_unit = "mm"\nground = ["O2", "O4"]\n[joints]\nO2 = [0.0, 0.0]\n'
            f"A = [{A[0]!r}, {A[1]!r}]\nB = [{B[0]!r}, {B[1]!r}]\nO4 = [{ground!r}, 0.0]\n"
            '[links]\ncrank = ["O2", "A"]\ncoupler = ["A", "B"]\nrocker = ["O4", "B"]\n'
            f'[driver]\nlink = "crank"\nvalue = {math.degrees(math.atan2(A[1], A[0]))!r}\n[mass]\n{masses}\n')


def _energy_by_hand(m: linkage.Mechanism, q, theta: float, omega: float, g: tuple[float, float]):
    """Kinetic and potential energy from linkage.position_rates' joint velocities alone: each
    link's omega from two of its joints, its centre of mass carried rigidly from the
    drawing."""
    r = linkage.position_rates(m, q, speed=omega, driver=theta)
    d = m.extra["drawing"]
    k = 1e-3  # mm
    kinetic = potential = 0.0
    for body, mass in m.extra["loads"].masses.items():
        j0, j1 = d.bodies[body][:2]
        (x0, y0), (x1, y1) = r.joints[j0], r.joints[j1]
        (vx0, vy0), (vx1, vy1) = r.joint_velocities[j0], r.joint_velocities[j1]
        rx, ry = x1 - x0, y1 - y0
        w = (rx * (vy1 - vy0) - ry * (vx1 - vx0)) / (rx * rx + ry * ry)
        turn = math.atan2(ry, rx) - math.atan2(d.xy[j1][1] - d.xy[j0][1], d.xy[j1][0] - d.xy[j0][0])
        dx, dy = mass.cg[0] - d.xy[j0][0], mass.cg[1] - d.xy[j0][1]
        ex, ey = dx * math.cos(turn) - dy * math.sin(turn), dx * math.sin(turn) + dy * math.cos(turn)
        vg = ((vx0 - w * ey) * k, (vy0 + w * ex) * k)
        kinetic += 0.5 * mass.mass * (vg[0] ** 2 + vg[1] ** 2) + 0.5 * mass.inertia * w * w
        potential -= mass.mass * (g[0] * (x0 + ex) * k + g[1] * (y0 + ey) * k)
    return kinetic, potential


def test_fifty_random_fourbars_with_masses_conserve_energy():
    """No drive, no friction, no loads but gravity: kinetic + potential, each computed here
    from the rates engine's joint velocities (not from I(theta)), constant to 1e-8 of the
    largest, over the rows simulated (to a limit of assembly, where one ends the span)."""
    rng = random.Random(31)
    done = limits = 0
    while done < 50:
        try:
            m = from_text(_random_fourbar(rng), "random")
        except InputError:
            continue
        g = (0.0, -9.81) if done % 2 else (0.0, 0.0)
        loads = m.extra["loads"].merged(linkage.Loads(gravity=g))
        try:
            sim = linkage.simulate(m, "0", (0.0, 0.2), omega0=rng.uniform(5.0, 20.0), loads=loads, samples=6)
        except InputError as exc:  # drawn at a dead point
            assert "dead point" in str(exc)
            continue
        done += 1
        limits += sim.event is not None
        assert sim.event in (None, "limit_of_assembly", "dead_point")
        assert sim.balance <= 1e-8
        energies = [sum(_energy_by_hand(m, [sim.unknowns[u.name][i] for u in m.unknowns], float(sim.theta[i]),
                                        float(sim.omega[i]), g)) for i in range(len(sim.t))]
        size = max(abs(e) for e in energies)
        assert max(abs(e - energies[0]) for e in energies) <= 1e-8 * size
    assert limits < 50


# --- events and refusals ------------------------------------------------------------------------


ME581_MASSES = ("[mass]\ncrank = { mass = 0.5, cg = [6, 13], inertia = 1e-3 }\n"
                "coupler = { mass = 1.0, cg = [40, 35], inertia = 2e-2 }\n")


def test_a_span_through_a_limit_of_assembly_ends_there_with_a_named_event():
    """The ME581 four-bar's crank cannot pass 112.024312837 deg (docs/rates.md): driven
    towards it, the simulation stops there, with the rows up to it."""
    m = _with(ME581, ME581_MASSES)
    sim = linkage.simulate(m, "0", (0.0, 1.0), omega0=10.0, samples=101)
    assert sim.event == "limit_of_assembly"
    assert sim.t[-1] == sim.event_time < 1.0
    assert abs(math.degrees(sim.theta[-1]) - 112.024312837) < 1e-3
    assert np.all(np.diff(sim.t) > 0)


def test_cli_limit_of_assembly_is_exit_1_with_the_event_named(cli, tmp_path):
    path = tmp_path / "me581.toml"
    path.write_text(ME581 + "\n" + ME581_MASSES)
    r = cli("simulate", str(path), "--time", "0:1", "--omega0", "10", "--samples", "5", "-f", "plain")
    assert r.code == 1
    assert "event: limit_of_assembly at t = " in r.out


@pytest.mark.parametrize("args,needle", [
    (["--drive", "T0*q", "--const", "T0=1"], "unknown name 'q'"),
    (["--drive", "__import__('os')"], "unknown function"),
    (["--friction-viscous", "-1"], "friction must be >= 0"),
    (["--friction-coulomb", "Z=0.1"], "'Z' is not a pin"),
    (["--time", "2:1"], "END must be after START"),
    (["--flywheel", "-0.1"], "flywheel"),
])
def test_cli_bad_input_is_one_line_exit_2(cli, args, needle):
    r = cli("simulate", str(LOADED), *(["--time", "0:1"] if "--time" not in args else []), *args)
    assert r.code == 2, r.err
    assert needle in r.err
    assert len(r.err.strip().splitlines()) == 1


def test_a_million_second_span_is_refused_in_one_line_not_integrated_for_minutes(cli):
    """Finding: --time 0:1e6 ran for minutes (200,000 evaluations, then integration_failed).
    The span is projected from the run's first evaluations and refused: exit 2, one line
    naming --time; a span within the budget still runs (the other tests)."""
    r = cli("simulate", str(LOADED), "--time", "0:1e6", "--omega0", "10")
    assert r.code == 2, r.err
    assert "--time" in r.err and "evaluations" in r.err and len(r.err.strip().splitlines()) == 1


def test_cli_a_mechanism_without_masses_is_refused(cli):
    r = cli("simulate", str(SAMPLES / "crank_rocker_joints.toml"), "--time", "0:1")
    assert r.code == 2
    assert "the dynamics need masses" in r.err and len(r.err.strip().splitlines()) == 1


def test_coulomb_friction_brings_the_driver_to_rest_as_a_named_event():
    m = linkage.load_mechanism(LOADED)
    sim = linkage.simulate(m, "0", (0.0, 5.0), omega0=5.0, flywheel=1e-3, friction_coulomb=0.05,
                           loads=linkage.Loads(masses=m.extra["loads"].masses))
    assert sim.event == "stopped"
    assert abs(sim.omega[-1]) <= 1e-8


def test_the_last_full_turn_gives_the_coefficient_of_speed_fluctuation():
    """Cs = (omega_max - omega_min) / omega_mean over the last turn, mean = 2 pi / period:
    checked against the dense trace; a heavier flywheel evens the speed."""
    m = linkage.load_mechanism(LOADED)
    cycles = []
    for flywheel in (0.01, 0.05):
        sim = linkage.simulate(m, "T0*(1 - omega/w0)", (0.0, 0.6), constants={"T0": 5.0, "w0": 40.0},
                               flywheel=flywheel, omega0=39.0)
        c = sim.cycle
        assert c is not None and c.steady
        t, theta, omega = sim.trace
        inside = (t >= c.start) & (t <= c.end)
        assert abs(float(np.interp(c.start, t, theta)) - (theta[-1] - 2 * math.pi)) < 1e-6
        assert abs(c.omega_max - omega[inside].max()) <= 1e-3 * c.omega_max
        assert abs(c.omega_min - omega[inside].min()) <= 1e-3 * c.omega_max
        assert c.cs == pytest.approx((c.omega_max - c.omega_min) / c.omega_mean)
        cycles.append(c)
    assert cycles[1].cs < cycles[0].cs


def test_a_turn_still_speeding_up_is_not_steady():
    m = linkage.load_mechanism(LOADED)
    sim = linkage.simulate(m, "T0*(1 - omega/w0)", (0.0, 1.0), constants={"T0": 5.0, "w0": 40.0},
                           flywheel=0.1, samples=11)
    assert sim.cycle is not None and not sim.cycle.steady


def test_cli_simulate_prints_the_checks_and_writes_the_plot(cli, tmp_path):
    png = tmp_path / "motion.png"
    r = cli("simulate", str(LOADED), "--drive", "T0*(1 - omega/w0)", "--const", "T0=5", "--const", "w0=40",
            "--time", "0:0.5", "--flywheel", "0.01", "--gravity", "9.81", "--samples", "6", "-f", "plain",
            "--plot", str(png))
    assert r.code == 0, r.err
    assert "energy balance: within 1e-08 (" in r.out
    assert "kinetostatic check: within 1e-10 (" in r.out
    assert png.read_bytes()[:4] == b"\x89PNG"


# --- the expression parser's variables ----------------------------------------------------------


def test_function_of_reads_variables_and_named_constants():
    f = function_of("T0*(1 - omega/w0) + sin(theta) - t^2", ("t", "theta", "omega"), {"T0": 5.0, "w0": 40.0})
    assert f(2.0, 0.5, 10.0) == pytest.approx(5.0 * 0.75 + math.sin(0.5) - 4.0, rel=1e-15)


@pytest.mark.parametrize("text,constants,needle", [
    ("x + 1", {}, "unknown name 'x'"),
    ("omega.real", {}, "Attribute is not allowed"),
    ("(lambda: 1)()", {}, "unknown function"),
    ("sin", {}, "unknown name"),
    ("T0", {"sin": 1.0}, "has the name of"),
    ("T0", {"omega": 1.0}, "has the name of"),
])
def test_function_of_refuses_what_is_not_whitelisted(text, constants, needle):
    with pytest.raises(ParseError, match=needle):
        function_of(text, ("t", "theta", "omega"), constants)


def test_an_equation_in_x_is_unchanged_by_the_variables():
    from linkage.problems.expression import Expression

    e = Expression.parse("x^3 - 2*x")
    assert e.function()(2.0) == 4.0 and e.derivative()(2.0) == 10.0 and e.second_derivative()(2.0) == 12.0


def _crank_on_its_pivot(tmp_path):
    """The crank-rocker with only a 2 kg crank centred on its pivot (inertia 0.01 kg m^2)."""
    text = (ROOT / "sample_inputs" / "crank_rocker_joints.toml").read_text()
    text += '\n[mass]\ncrank = { mass = 2.0, cg = [0, 0], inertia = 0.01 }\n'
    path = tmp_path / "pivot.toml"
    path.write_text(text)
    return path


def test_a_driver_stopped_by_coulomb_friction_is_the_stopped_event_not_bad_input(cli, tmp_path):
    """An adversary's pass: the speed at the stop, 7.5e-13, was refused by the kinetostatic
    check's range for a person's input ('speed must be 0 or from 1e-12'): exit 2. A crank
    with I = 0.01 from 10 rad/s under 0.05 N m of friction stops at t = I omega0 / M = 2 s."""
    r = cli("simulate", str(_crank_on_its_pivot(tmp_path)), "--time", "0:3", "--omega0", "10",
            "--friction-coulomb", "O2=0.05", "--samples", "4", "-f", "plain")
    assert r.code == 1, r.err
    assert "event: stopped at t = 2 s" in r.out


def test_a_mechanism_without_inertia_is_refused_not_a_hang(cli, tmp_path):
    text = (ROOT / "sample_inputs" / "crank_rocker_joints.toml").read_text()
    path = tmp_path / "massless.toml"
    path.write_text(text + '\n[mass]\ncrank = { mass = 0.0, cg = [0, 0], inertia = 0.0 }\n')
    r = cli("simulate", str(path), "--time", "0:1", "--drive", "1")
    assert r.code == 2 and "no inertia" in r.err and r.err.count("\n") == 1


def test_a_drive_that_cannot_be_evaluated_is_one_line_or_a_named_event(cli):
    """'1/0' said 'internal error (please report this)'; a drive that fails mid-run ends as
    integration_failed at the time it failed, its rows kept."""
    loads = str(ROOT / "docs" / "me581_masses.toml")
    r = cli("simulate", loads, "--time", "0:1", "--drive", "1/0")
    assert r.code == 2 and "the drive cannot be evaluated at t = 0 s" in r.err
    r = cli("simulate", loads, "--time", "0:1", "--drive", "theta/(t-0.5)", "--samples", "3", "-f", "plain")
    assert r.code == 1 and "internal error" not in r.err
    assert "event: integration_failed at t = 0.5 s" in r.out and "to 0.5 s" in r.out


# --- what an adversarial pass found: never a hang, never an internal error ---------------------


@pytest.mark.parametrize("span", [(1e15, 1.0000000000001e15), (1e14, 100000000000000.1), (1e12, 1e12 + 1.0)])
def test_a_time_span_finer_than_double_precision_resolves_is_refused(cli, span):
    """At t = 1e15 s times are 0.125 s apart: 0.1 s there had no time to step to (it ran
    past a minute at full load), and 1e14 + 0.1 had output times out of order (an internal
    error). The driver grids' rule (rules.grid_resolved) refuses them at once."""
    with pytest.raises(InputError, match="finer than double precision"):
        linkage.simulate(linkage.load_mechanism(str(LOADED)), drive="1", time=span)
    run = cli("simulate", str(LOADED), "--time", f"{span[0]!r}:{span[1]!r}", "--drive", "1")
    assert run.code == 2 and run.err.count("\n") == 1 and "finer than double precision" in run.err


def test_a_run_that_cannot_take_a_step_ends_integration_failed_with_its_start():
    """A span at 1e300 s leaves the integrator no step: the run is integration_failed at its
    start with the start's row, not an IndexError. (A drive of 1e300 N m, the other case
    here before, is now refused by its value: test_a_drive_beyond_a_loads_bound_...)"""
    time = (1e300, 1.0000001e300)
    sim = linkage.simulate(linkage.load_mechanism(str(LOADED)), drive="1", time=time)
    assert sim.event == "integration_failed" and len(sim.t) == 1 and sim.t[0] == time[0]


def test_a_drive_beyond_the_solvers_rates_leaves_those_forces_undefined_not_an_error(cli):
    """The kinetostatic solver refuses a speed or acceleration above 1e12 from a person; a
    simulated one there (a drive with a pole) leaves that row's forces undefined, said once,
    instead of "accel must be ..." naming an option nobody gave. (A drive of 1e99 omega N m:
    within the loads' bound until it ends the run.)"""
    run = cli("simulate", str(LOADED), "--time", "0:0.4", "--drive", "1e99*omega", "--omega0", "1")
    assert run.code == 1 and "accel must be" not in run.err
    assert "forces undefined at 2 of 2 output times" in run.out
    # no row with forces: the check has nothing to compare, and says so (not "within")
    assert "kinetostatic check: nothing to check" in run.out
    # and the json document says it was neither met nor missed (null), not true
    doc = json.loads(cli("simulate", str(LOADED), "--time", "0:0.4", "--drive", "1e99*omega",
                         "--omega0", "1", "-f", "json").out)
    assert doc["drive_ok"] is None and doc["energy_ok"] is True


def test_a_nan_check_figure_is_a_miss_in_the_report_and_the_exit_alike():
    """The command's exit and the report's check lines read one verdict
    (render.simulate.simulation_checks): a NaN energy balance or kinetostatic figure is a
    miss (BEYOND, exit 1), never "within"; a run's real figures pass."""
    import dataclasses

    from linkage.render.simulate import simulation_checks

    sim = linkage.simulate(linkage.load_mechanism(str(LOADED)), drive="1", time=(0.0, 0.05), samples=11)
    ok = simulation_checks(sim, 1e-8, 1e-10, 0.02)
    assert ok.energy_ok and ok.drive_ok and ok.passed
    for field in ("balance", "drive_check"):
        bad = simulation_checks(dataclasses.replace(sim, **{field: math.nan}), 1e-8, 1e-10, 0.02)
        assert not bad.passed


def test_a_run_that_stops_at_its_start_has_its_start_once(cli):
    """Coulomb friction of 100 N m against a drive of 0 stops the crank at its start (the
    'stopped' event at t = 0): the output time 0 is the event's row, once, and the energy
    balance has nothing to compare (it read 'within' over two copies of one row before)."""
    sim = linkage.simulate(linkage.load_mechanism(str(LOADED)), drive="0", time=(0.0, 0.2), samples=5,
                           friction_coulomb={"O2": 100.0})
    assert sim.event == "stopped" and list(sim.t) == [0.0]
    run = cli("simulate", str(LOADED), "--time", "0:0.2", "--samples", "5", "--friction-coulomb", "100")
    assert "energy balance: nothing to compare" in run.out
    doc = json.loads(cli("simulate", str(LOADED), "--time", "0:0.2", "--samples", "5", "--friction-coulomb",
                         "100", "-f", "json").out)
    assert doc["energy_ok"] is None  # neither met nor missed, not true


@pytest.mark.parametrize("drive", ["1e308", "1e308*1e308", "-1e101"])
def test_a_drive_beyond_a_loads_bound_is_refused_by_its_value(drive):
    """A drive beyond MAX_LOAD (1e100 N m, the loads' bound) is refused with its value, t,
    theta and omega: it overflowed the acceleration to inf (numpy's RuntimeWarning on stderr
    and inf in the table), or an infinite drive read 'more than 200,000 evaluations (at t =
    nan s): shorten --time'."""
    with pytest.raises(linkage.InputError, match=r"drive: the drive is .* beyond 1e\+100"):
        linkage.simulate(linkage.load_mechanism(str(LOADED)), drive=drive, time=(0.0, 0.01), samples=3)


def test_a_runaway_motion_ends_instead_of_walking_to_its_trial_position():
    """A drive of 1e101 t^3 N m (within the bound over 0..0.01 s) spins the crank up so fast
    that a trial step lands 1e40 rad on: the position was walked there in 0.2 rad steps, a
    hang (12 minutes and counting). A trial position beyond MAX_WALK_STEPS is refused, so
    the run ends as a refusal (or a named event) at once. Run in a child with a generous
    timeout: a hang fails the test instead of stalling the suite."""
    import subprocess
    import sys

    code = (f"import linkage\ntry:\n    s = linkage.simulate(linkage.load_mechanism({str(LOADED)!r}), "
            "drive='1e101*t**3', time=(0.0, 0.01), samples=3)\n    print('event', s.event)\n"
            "except linkage.InputError as e:\n    print('refused', e)\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0 and out.stdout.startswith(("refused", "event")), out.stderr


OVERFLOWS = [("1e308", 0.0, "beyond 1e+100"), ("1e308*1e308", 0.0, "beyond 1e+100"),
             ("0", 1e308, "the acceleration overflows at the start, t = 0 s")]


@pytest.mark.parametrize("drive,omega0,said", OVERFLOWS)
def test_an_acceleration_that_overflows_is_refused_not_a_runtime_warning_and_inf(cli, drive, omega0, said):
    """A drive of 1e308 N m (or inf) on 2.6e-4 kg m^2, or a start at 1e308 rad/s, overflows
    theta'': it printed numpy's RuntimeWarning and d2theta = inf (exit 1); the one line now
    says why (a drive beyond the loads' bound, or the overflow), and the library raises
    InputError without a warning."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(InputError, match=re.escape(said)):
            linkage.simulate(str(LOADED), drive=drive, time=(0.0, 0.01), omega0=omega0)
    if omega0 == 0.0:
        run = cli("simulate", str(LOADED), "--time", "0:0.01", "--drive", drive)
        assert run.code == 2 and run.err.count("\n") == 1 and said in run.err


def test_a_run_stopped_at_its_start_has_its_start_once_and_nothing_to_compare(cli):
    """At rest, the file's loads turn the crank against 100 N m of Coulomb friction: the
    driver stops at t = 0. The start was printed twice (the output time and the event's row)
    and the energy balance read 'within ... by 0' of two copies of one state."""
    sim = linkage.simulate(str(LOADED), "0", (0.0, 0.2), samples=5, friction_coulomb=100.0)
    assert sim.event == "stopped" and sim.event_time == 0.0 and list(sim.t) == [0.0]
    run = cli("simulate", str(LOADED), "--time", "0:0.2", "--samples", "5", "--friction-coulomb", "100",
              "-f", "plain")
    assert run.code == 1 and "energy balance: nothing to compare (one output time)" in run.out


@pytest.mark.parametrize("args, said", [
    (["--theta0", "nan"], "error: --theta0 must be finite"),
    (["--flywheel", "nan"], "error: --flywheel must be finite"),
    (["--rtol", "1"], "error: --rtol: give a tolerance"),
])
def test_simulate_refusals_name_the_command_line_options(cli, args, said):
    """They named the library's arguments (theta0, flywheel), not the options given."""
    run = cli("simulate", str(LOADED), "--time", "0:0.1", *args)
    assert run.code == 2 and run.err.count("\n") == 1 and run.err.startswith(said)


def test_simulate_refusals_say_what_the_start_or_the_file_lacks(cli):
    """1.3e-5 deg inside the ME581's limit is assembled: the refusal names the dead-point rule
    (an unknown 300 times as fast as the driver), not "a dead point or not assembled"; a loops
    file lacks bodies and masses, not loads (none were given)."""
    run = cli("simulate", str(ROOT / "docs" / "me581_masses.toml"), "--time", "0:1", "--theta0", "112.0243")
    assert run.code == 2 and "times as fast as the driver there (a run starts below 300)" in run.err
    run = cli("simulate", str(ROOT / "sample_inputs" / "crank_rocker.toml"), "--time", "0:1")
    assert run.code == 2 and "the dynamics need links as bodies with masses" in run.err
    assert "loads need" not in run.err


def test_a_run_ending_at_an_event_says_it_on_stderr_when_the_tables_go_to_csv(cli, tmp_path):
    """With -o FILE.csv only "wrote ..." reached stderr and the CSVs hold no event: exit 1
    without its reason anywhere. The event is now a note (JSON holds it already)."""
    args = ("simulate", str(ROOT / "docs" / "me581_masses.toml"), "--time", "0:2", "--drive", "5",
            "--samples", "5")
    run = cli(*args, "-o", str(tmp_path / "e.csv"))
    assert run.code == 1 and "note: event: limit_of_assembly at t = 0.19222" in run.err
    run = cli(*args, "-o", str(tmp_path / "e.json"))
    assert run.code == 1 and "note: event" not in run.err


def test_a_run_too_stiff_to_integrate_names_what_makes_it_so_not_only_the_span(cli):
    """1e308 N m s/rad of viscous friction makes the first steps 5.6e-308 s: the refusal said
    only "shorten --time (or --omega0)", which cannot help; it names friction among the causes."""
    run = cli("simulate", str(LOADED), "--time", "0:0.2", "--samples", "5", "--friction-viscous", "1e308")
    assert run.code == 2 and run.err.count("\n") == 1 and "friction" in run.err

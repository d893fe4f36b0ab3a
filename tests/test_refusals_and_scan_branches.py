"""Refusals at every front door, and the assembly a scan follows: regressions, each named
after what it found."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage import load_mechanism
from linkage.errors import InputError
from linkage.render.sweep import ranges_of

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
THETA4 = SAMPLES / "fourbar_me581_theta4.toml"


def _rocker_driven(r1: float, r2: float, r3: float, r4: float):
    m = load_mechanism(THETA4)
    return m.with_values({"r1": r1, "r2": r2, "r3": r3, "r4": r4}, {})


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_scans_of_rocker_driven_fourbars_follow_the_sweeps_assembly(branch):
    """The scan's closed-form engine picked each position's assembly by its label, and a
    rocker-driven four-bar's two mirror assemblies can share one: theta2_range 200.75 where
    the sweep (and --batch) follow one assembly, range 154.57. Random rocker-driven designs,
    both branches: the scan's ranges are the one-at-a-time sweep's."""
    rng = np.random.default_rng(4)
    values = [float(v) for v in range(0, 360, 3)]
    designs = [(57.052, 93.277, 66.932, 50.853)] + [
        tuple(float(x) for x in rng.uniform(0.5, 1.5, 4) * [90.0, 30.0, 100.0, 60.0]) for _ in range(7)]
    from linkage.files import read_input
    from linkage.scan import ScanJob, run_chunk

    job = ScanJob(read_input(THETA4), str(THETA4), (), ("r1", "r2", "r3", "r4"), tuple(values), branch, 1e-12)
    cols = run_chunk(job, 0, np.array(designs))
    compared = 0
    for i, d in enumerate(designs):
        one = linkage.sweep(_rocker_driven(*d), values, branch=branch)
        if not any(p.status == "converged" for p in one.positions):
            assert not cols["solved_fraction"][i]
            continue
        got = ranges_of(one)
        for name in ("theta2", "theta3"):
            assert abs(cols[f"{name}_range"][i] - got[name]["stroke"]) < 1e-9, (d, name)
        compared += 1
    assert compared >= 4
    if branch == "crossed":
        one = ranges_of(linkage.sweep(_rocker_driven(*designs[0]), [float(v) for v in range(360)],
                                      branch="crossed"))
        assert abs(one["theta2"]["stroke"] - _crossed_assembly_stroke(designs[0])) < 1e-9


def _crossed_assembly_stroke(links: tuple[float, float, float, float]) -> float:
    """theta2's stroke over theta4 = 0, 1, ..., 359 deg on the assembly (A on one side of
    O2 -> B) that is crossed (sin(theta4 - theta3) < 0) where a crossed one first appears:
    the sweep follows an assembly by its signs (issue 19). From circle intersections."""
    r1, r2, r3, r4 = links
    sides: dict[int, list[tuple[int, float]]] = {1: [], -1: []}
    first = None
    for v in range(360):
        b = r1 + r4 * complex(math.cos(math.radians(v)), math.sin(math.radians(v)))
        c = (r2 * r2 + abs(b) ** 2 - r3 * r3) / (2 * r2 * abs(b))
        if abs(c) >= 1:
            continue
        for side in (1, -1):
            t2 = math.atan2(b.imag, b.real) + side * math.acos(c)
            a = r2 * complex(math.cos(t2), math.sin(t2))
            t3 = math.atan2((b - a).imag, (b - a).real)
            sides[side].append((v, math.degrees(t2)))
            if first is None and math.sin(math.radians(v) - t3) < 0:
                first = side
    assert first is not None
    run = sides[first]
    # start after the gap, so that the run is one arc of the circle of theta4
    k = next((i for i in range(1, len(run)) if run[i][0] - run[i - 1][0] > 1), 0)
    run = run[k:] + run[:k]
    turns = [run[0][1]]
    for _, t2 in run[1:]:
        turns.append(turns[-1] + math.remainder(t2 - turns[-1], 360.0))
    return max(turns) - min(turns)


def test_a_scan_of_no_driver_values_is_refused_not_a_zero_fraction():
    """scan_designs(values=[]) reported feasible_fraction 0.0 for every design."""
    with pytest.raises(InputError, match="values"):
        linkage.scan_designs(SAMPLES / "crank_rocker.toml", {"r2": (20.0, 60.0, 3)}, values=[])


@pytest.mark.parametrize("method", ["newton", "newton-fd", "lm"])
def test_a_system_of_no_unknowns_is_refused_not_a_domain_error(method):
    """solve_system(lambda x: [], [], method="newton-fd") was a DOMAIN_ERROR whose detail
    read 'max() arg is an empty sequence'."""
    with pytest.raises(InputError, match="x0"):
        linkage.solve_system(lambda x: [], [], method=method)


@pytest.mark.parametrize("method", ["newton-fd", "lm"])
def test_a_residual_that_recurses_without_end_is_an_input_error(method):
    """An F that recursed without end raised a raw RecursionError under newton-fd and lm."""
    def F(x):
        return F(x)

    with pytest.raises(InputError, match="recursed"):
        linkage.solve_system(F, [1.0, 2.0], method=method)


@pytest.mark.parametrize("char", ["\u202e", "\u2067", "\u200f"])
def test_a_bidirectional_control_in_a_name_is_refused(cli, tmp_path, char):
    """A name with U+202E (right-to-left override) was printed raw: the terminal then shows
    the rest of the line reversed."""
    text = (SAMPLES / "crank_rocker.toml").read_text()
    start = text.index("name = ")
    end = text.index("\n", start)
    path = tmp_path / "bidi.toml"
    path.write_text(text[:start] + f'name = "crank{char}rocker"' + text[end:])
    run = cli("solve", str(path))
    assert run.code == 2 and len(run.err.strip().splitlines()) == 1, run.err
    assert "control character" in run.err and char not in run.err


def test_the_normal_equations_are_the_sums_they_were_written_as():
    """Damped Newton forms J^T J once per step now (a 24-unknown sweep spent 140 s forming
    it again for every damping value): the same sums in the same order, bit for bit."""
    import random

    from linkage.methods.newton_system import normal_equations

    rng = random.Random(18)
    for n in (1, 2, 3, 7, 24):
        for _ in range(40):
            jac = [[rng.uniform(-1.0, 1.0) * 10.0 ** rng.randint(-8, 8) for _ in range(n)] for _ in range(n)]
            phi = [rng.uniform(-1.0, 1.0) for _ in range(n)]
            jtj, g = normal_equations(jac, phi)
            assert jtj == [[sum(jac[k][i] * jac[k][j] for k in range(n)) for j in range(n)] for i in range(n)]
            assert g == [sum(jac[k][i] * phi[k] for k in range(n)) for i in range(n)]


def test_a_parameter_both_set_and_varied_is_refused(cli):
    """scan --vary r2=20:60:3 --set r2=30 was accepted silently (which one wins?)."""
    run = cli("scan", str(SAMPLES / "crank_rocker.toml"), "--vary", "r2=20:60:3", "--set", "r2=30",
              "--step", "30", "-f", "csv")
    assert run.code == 2 and len(run.err.strip().splitlines()) == 1, run.err
    assert "r2" in run.err and "--set" in run.err and "--vary" in run.err


@pytest.mark.parametrize("speed", ["1e-320", "1e-318", "5e-324", "1e-13"])
def test_a_tiny_speed_is_refused_not_an_internal_error(cli, speed):
    """--speed 1e-320 was 'internal error: ZeroDivisionError'; 1e-318 printed a rate off by
    6.6e-6 relative with a bound of 0 (the bound's products underflowed)."""
    run = cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--speed", speed)
    assert run.code == 2 and len(run.err.strip().splitlines()) == 1, run.err
    assert "out of range" in run.err


def test_a_tiny_speed_in_the_api_is_an_input_error_naming_it():
    m = load_mechanism(SAMPLES / "fourbar_me581.toml")
    q = linkage.solve_system(m.problem(), tol=1e-12).x
    for speed in (5e-324, 1e-300, 1e-13):
        with pytest.raises(InputError, match="speed"):
            linkage.position_rates(m, q, speed=speed)
    small = linkage.position_rates(m, q, speed=1e-12, accel=1e-12)
    big = linkage.position_rates(m, q, speed=1.0, accel=1.0)
    for name, v in big.velocities.items():
        assert small.velocities[name] == pytest.approx(1e-12 * v, rel=1e-12)
        assert small.velocity_bounds[name] > 0.0


def test_position_rates_refuses_a_q_that_is_not_a_solution():
    """A q 60 deg from the solution got the root's rates with status ok (and, without a
    speed, the joints at q itself); q = [0, 0] was called 'undefined', as if J were singular."""
    m = load_mechanism(SAMPLES / "fourbar_me581.toml")
    q = linkage.solve_system(m.problem(), tol=1e-12).x
    far = [q[0] + math.radians(60.0), q[1] - math.radians(60.0)]
    for bad in (far, [0.0, 0.0]):
        for speed in (None, 10.0):
            with pytest.raises(InputError, match="not a solution"):
                linkage.position_rates(m, bad, speed=speed)
    near = [q[0] + 1e-9, q[1] - 1e-9]  # a solve at a loose tolerance: accepted, polished
    assert linkage.position_rates(m, near, speed=10.0).velocities == pytest.approx(
        linkage.position_rates(m, q, speed=10.0).velocities, rel=1e-12)


def _toggles_mod_turn(result) -> list[float]:
    return sorted(round(t % 360.0, 4) % 360.0 for t in result.toggles)


@pytest.mark.parametrize("grid", [(0.0, 359.0), (-180.0, 180.0), (0.0, 360.0), (-10.0, 349.0)])
def test_a_toggle_at_the_grids_end_is_listed(grid):
    """A toggle at the start or end of a full-turn grid had no neighbour on one side and was
    not listed, though the rates there were undefined: the parallelogram's crossing at 0 in
    a 0..359 sweep, at 180 in -180..180; the in-line slider-crank's at 270 in -90..270."""
    lo, hi = grid
    values = [lo + k for k in range(int(hi - lo) + 1)]
    parallelogram = {"r1": 60.0, "r3": 60.0, "r4": 30.0}
    para = load_mechanism(SAMPLES / "fourbar_me581.toml").with_values(parallelogram, {})
    assert _toggles_mod_turn(linkage.sweep(para, values)) == [0.0, 180.0]
    slider = load_mechanism(SAMPLES / "slider_crank.toml").with_values({"e": 0.0, "r3": 40.0}, {})
    for shift in (0.0, -90.0, 90.0):
        assert _toggles_mod_turn(linkage.sweep(slider, [v + shift for v in values])) == [90.0, 270.0]


def test_integers_beyond_the_float_range_are_input_errors_at_every_front_door():
    """sweep, scan_designs and solve_system (newton-fd, lm) let an OverflowError out."""
    m = load_mechanism(SAMPLES / "fourbar_me581.toml")
    calls = [
        lambda: linkage.sweep(m, [10**400]),
        lambda: linkage.scan_designs(SAMPLES / "crank_rocker.toml", {"r2": (20, 60, 3)}, values=[10**400]),
        lambda: linkage.solve_system(lambda x: [x[0] - 1, x[1] - 2], [10**400, 0], method="newton-fd"),
        lambda: linkage.solve_system(lambda x: [x[0] - 1, x[1] - 2], [10**400, 0], method="lm"),
    ]
    for call in calls:
        with pytest.raises(InputError, match="beyond the float range"):
            call()

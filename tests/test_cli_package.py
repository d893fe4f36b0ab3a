"""The command line as a package (src/linkage/cli/): small modules, every command
registered, and the numerics it used to hold importable from the engine, with the
four-bar equation's sweep checked against a closed form derived here."""

from __future__ import annotations

import json
import math
from pathlib import Path
from types import SimpleNamespace

import pytest

import linkage

CLI = Path(linkage.__file__).parent / "cli"
COMMANDS = ("solve", "sweep", "scan", "draw", "samples", "stress", "bench")


def test_no_module_of_the_cli_is_over_250_lines():
    modules = sorted(CLI.glob("*.py"))
    assert len(modules) >= len(COMMANDS) + 3  # a module per command, the app, options, entry
    long = {m.name: n for m in modules if (n := len(m.read_text(encoding="utf-8").splitlines())) > 250}
    assert not long, long


def test_every_command_module_registers_its_command(cli):
    run = cli("--help")
    assert run.code == 0
    listed = [line.split()[1] for line in run.out.splitlines()
              if len(line.split()) > 1 and line.split()[0] in "│|"]
    for name in COMMANDS:
        assert name in listed, (name, run.out)
    for name in COMMANDS:  # each one's own help page, from its own module
        assert cli(name, "--help").code == 0


def _roots_deg(alpha: float, r1: float, r2: float, r3: float) -> list[float]:
    """Both roots of R1 cos a - R2 cos p + R3 - cos(a - p) = 0, derived here: it is
    A cos p + B sin p = C with A = R2 + cos a, B = sin a, C = R1 cos a + R3."""
    a = math.radians(alpha)
    big_a, big_b, big_c = r2 + math.cos(a), math.sin(a), r1 * math.cos(a) + r3
    ratio = big_c / math.hypot(big_a, big_b)
    if abs(ratio) > 1.0:
        return []
    base, half = math.atan2(big_b, big_a), math.acos(ratio)
    return [math.degrees(base + half), math.degrees(base - half)]


def _near(x: float, roots: list[float]) -> float:
    return min(abs(((x - r) + 180.0) % 360.0 - 180.0) for r in roots)


def test_equation_sweep_lands_on_the_closed_form_and_is_what_sweep_prints(cli):
    from linkage.kinematics.equation_sweep import equation_sweep

    rs = (5 / 3, 5 / 2, 11 / 6)
    values = [10.0, 40.0, 70.0, 100.0, 130.0, 160.0]
    rows = equation_sweep(values, rs, "newton", 1e-12)
    assert [r.alpha for r in rows] == values
    at40 = rows[1]
    assert at40.status.startswith("converged")
    assert _near(at40.phi, _roots_deg(40.0, *rs)) < 1e-9
    for r in rows:
        assert _near(r.phi, _roots_deg(r.alpha, *rs)) < 1e-9
    # the same rows as the command prints (its JSON keeps every digit)
    run = cli("sweep", "--from", "10", "--to", "160", "--step", "30", "--format", "json")
    assert run.code == 0
    printed = json.loads(run.out)["positions"]
    assert [(p["alpha"], p["status"], p["phi"], p["iterations"]) for p in printed] == \
        [(r.alpha, r.status, r.phi, r.iterations) for r in rows]


def test_equation_sweep_reports_where_the_linkage_cannot_be_assembled():
    from linkage.kinematics.equation_sweep import equation_sweep

    rs = (1.0, 1.2, 0.3)  # no real root over part of the cycle
    values = [float(a) for a in range(0, 361, 15)]
    rows = equation_sweep(values, rs, "newton", 1e-12)
    for r in rows:
        roots = _roots_deg(r.alpha, *rs)
        if not roots:
            assert (r.status, r.phi) == ("no_solution", None)
        elif r.phi is not None:
            assert _near(r.phi, roots) < 1e-9
    assert any(r.status == "no_solution" for r in rows)
    assert any(r.phi is not None for r in rows)


def test_parse_motion_lives_in_arguments_with_its_units_and_messages():
    from linkage.arguments import parse_motion
    from linkage.errors import InputError

    crank = SimpleNamespace(driver=SimpleNamespace(kind="angle"), length_unit="mm")
    assert parse_motion("600rpm", "90deg/s^2", crank) == pytest.approx((20 * math.pi, math.pi / 2),
                                                                        rel=1e-15)
    assert parse_motion(None, None, crank) == (None, 0.0)
    slider = SimpleNamespace(driver=SimpleNamespace(kind="length"), length_unit="mm")
    assert parse_motion("250mm/s", None, slider) == (250.0, 0.0)
    with pytest.raises(InputError, match="--accel needs --speed"):
        parse_motion(None, "1", crank)
    with pytest.raises(InputError, match="--speed '5rpm/s'"):
        parse_motion("5rpm/s", None, crank)


def test_the_moved_engine_functions_are_importable_from_their_homes():
    from linkage.measure.timing import time_per_solve
    from linkage.problems.seed_equation import (
        applicable,
        fourbar_coefficients,
        fourbar_info,
        scalar_problem,
    )
    from linkage.problems.start import start_on_branch
    from linkage.render.plots import error_series, sweep_frames
    from linkage.render.scalar import fourbar_blocks

    for f in (time_per_solve, applicable, fourbar_info, start_on_branch, error_series, sweep_frames,
              fourbar_blocks):
        assert callable(f)
    rs, _ = fourbar_coefficients(None, None, None, ("2", "7", "9", "6"))
    # Freudenstein's ratios from the links, derived here: d/c, d/a, (a^2 - b^2 + c^2 + d^2)/(2ac)
    assert rs == pytest.approx((6 / 9, 6 / 2, (4 - 49 + 81 + 36) / (2 * 2 * 9)), rel=1e-14)
    problem = scalar_problem(None, None, 40.0, None, None, None, ("2", "7", "9", "6"))
    for root in _roots_deg(40.0, *rs):
        assert abs(problem.f(root)) < 1e-12


def test_the_collector_paused_for_start_up_runs_again_while_the_command_works():
    """linkage.cli.main pauses the cyclic collector while the command line starts (a cold
    start's cost, docs/performance.md) and must resume it before the command works: a long
    sweep's cyclic garbage is collected as ever. What start-up made is frozen (never walked
    again), and an in-process run_cli (the tests' own) leaves the collector alone."""
    from conftest import run_process

    code = """
import gc, sys
import linkage.render.writers as writers
seen = []
real = writers.write
def write(*args, **kwargs):
    seen.append((gc.isenabled(), gc.get_freeze_count() > 0))
    return real(*args, **kwargs)
writers.write = write
sys.argv = ["linkage", "solve"]
from linkage.cli import main
try:
    main()
except SystemExit as stop:
    print(seen, gc.isenabled(), stop.code, file=sys.stderr)
"""
    run = run_process(code=code)
    assert run.stderr.strip().splitlines()[-1] == "[(True, True)] True 0", run.stderr
    import gc

    from linkage.cli import run_cli

    frozen = gc.get_freeze_count()
    assert run_cli(["samples"]) == 0
    assert gc.isenabled() and gc.get_freeze_count() == frozen

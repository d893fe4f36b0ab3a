"""What a person sees: output read the way a mechanism student reads it, at 80 columns and
in every format. Each test is named after what was wrong."""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import pytest

from pty_run import run

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
LINKAGE = [sys.executable, "-m", "linkage"]


def law_of_cosines_transmission(r1: float, r2: float, r3: float, r4: float, theta2_deg: float) -> float:
    """The angle at B between coupler and rocker (deg, 0..180), from the triangle A-B-O4:
    |A O4|^2 = r1^2 + r2^2 - 2 r1 r2 cos(theta2) (ground along +x), independent of any
    solver output but theta2, folded into 0..90 (the transmission angle: the acute angle
    between the two links' lines)."""
    d2 = r1 * r1 + r2 * r2 - 2.0 * r1 * r2 * math.cos(math.radians(theta2_deg))
    mu = math.degrees(math.acos((r3 * r3 + r4 * r4 - d2) / (2.0 * r3 * r4)))
    return min(mu, 180.0 - mu)


@pytest.mark.parametrize("engine", [[], ["--batch"]], ids=["stepwise", "batch"])
def test_rocker_driven_sweep_shows_the_transmission_angle_not_a_dash(cli, engine):
    """With theta4 the driver the transmission angle uses the driver's value; it was "—"
    (None in JSON) at every position, though the scan of the same file reported it."""
    run_ = cli("sweep", str(SAMPLES / "fourbar_me581_theta4.toml"), "--from", "110", "--to", "250",
               "--step", "10", *engine, "--format", "json")
    assert run_.code == 0, run_.err
    solved = [p for p in json.loads(run_.out)["positions"] if p["status"] == "converged"]
    assert len(solved) >= 5
    for p in solved:
        want = law_of_cosines_transmission(90.0, 30.0, 60.0, 45.0, p["solution"]["theta2"])
        assert p["transmission"] is not None and abs(p["transmission"] - want) < 1e-8, (p, want)


def test_rocker_driven_table_has_a_transmission_angle_in_every_solved_row(cli):
    run_ = cli("sweep", str(SAMPLES / "fourbar_me581_theta4.toml"), "--from", "120", "--to", "160",
               "--step", "20", "--format", "csv")
    header, *rows = [line.split(",") for line in run_.out.splitlines()]
    j = header.index("transmission angle 0..90 (deg)")
    assert [r[1] for r in rows] == ["converged"] * 3
    assert all(r[j] for r in rows), rows


HELP_COMMANDS = [["--help"], ["solve", "--help"], ["sweep", "--help"], ["scan", "--help"]]


@pytest.mark.parametrize("args", HELP_COMMANDS, ids=" ".join)
def test_help_text_at_80_columns_is_not_squeezed_into_a_narrow_column(args):
    """--digits' type label "<int range> [3<=x<=17]" widened the type column of every
    command's options so that their help wrapped at 23 characters (--speed took 11
    lines). Now each option's help has at least 34 characters a line, and no word is cut."""
    seen = run([*LINKAGE, *args], 80)
    assert "3<=x<=17" not in seen
    rows = [line for line in seen.splitlines() if line.startswith("│ --")]
    assert rows, seen
    # the help column starts after the option, its short form and the type label
    for line in rows:
        assert len(line) <= 80
    widths = []
    for line in seen.splitlines():
        inner = line.strip("│").rstrip()
        if line.startswith("│ --speed"):
            widths.append(len(inner) - inner.index("SPEED") - len("SPEED"))
    if args[0] in ("solve", "sweep"):
        assert widths and widths[0] >= 34, seen


def test_digits_out_of_range_is_one_line_naming_the_range(cli):
    for value in ("2", "18", "x"):
        r = cli("solve", "--digits", value)
        assert r.code == 2 and r.err.startswith("error: ") and len(r.err.strip().splitlines()) == 1, r.err
        assert "--digits" in r.err
    assert "3 to 17" in cli("sweep", "--digits", "40").err
    assert cli("solve", "--digits", "17", "--format", "plain").code == 0


@pytest.mark.parametrize("command", ["solve", "sweep"])
def test_help_explains_the_rate_statuses(cli, monkeypatch, command):
    """ill_conditioned and undefined appear in output with --speed; the help said nothing
    of them."""
    monkeypatch.setenv("COLUMNS", "200")
    text = " ".join(cli(command, "--help").out.split())
    assert "ill_conditioned" in text and "undefined" in text and "error bound" in text


def test_sweep_help_names_every_position_status(cli, monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")
    text = " ".join(cli("sweep", "--help").out.split())
    for status in ("converged", "no_solution", "off_branch"):
        assert status in text, status


def test_solve_help_names_the_mirror_branch_key(cli, monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")
    assert "open (mirror)" in " ".join(cli("solve", "--help").out.split())


P7 = {"dtheta3/dt (rad/s)": -3.901274121944855, "dtheta4/dt (rad/s)": 5.353311575177702,
      "d2theta3/dt2 (rad/s^2)": 5.892333757673076, "d2theta4/dt2 (rad/s^2)": 71.37419488746042}
"""worked example P7, docs/worked_examples.md: the P3 four-bar at 65 deg, crank at 10 rad/s and 5 rad/s^2."""


def _rates_rows(seen: str) -> list[list[str]]:
    block = seen.split("Velocities and accelerations", 1)[1].split("Joints", 1)[0]
    return [line.split() for line in block.splitlines() if "/dt" in line]


def test_rates_table_fits_80_columns_each_unit_beside_its_rate():
    """At 80 columns the rates table (unknown, velocity, bound, unit, acceleration, bound,
    unit: 82 wide) split in two and left the acceleration's unit alone in a second table.
    One row per rate now, named as the sweep's columns and the CSV name it, its unit in
    the name: one table, and P7's figures in it."""
    seen = run([*LINKAGE, "solve", str(SAMPLES / "fourbar_me581.toml"), "--speed", "10", "--accel", "5"], 80)
    title = [line.rstrip() for line in seen.splitlines() if line.startswith("Velocities and accelerations")]
    assert title == ["Velocities and accelerations"], title  # not "(columns part 1 of 2)"
    rows = {f"{r[0]} {r[1]}": r[2:] for r in _rates_rows(seen)}
    assert set(rows) == set(P7), rows
    for label, want in P7.items():
        value, bound = float(rows[label][0]), float(rows[label][1])
        assert abs(value - want) <= max(bound, 1e-11 * abs(want)), (label, value, want)
        assert bound < 1e-9


def test_rates_table_names_the_ill_conditioned_rates_as_the_note_does():
    """Near the limit, the note lists dtheta3/dt, d2theta3/dt2...: the table's rows carry
    those names (they were columns "velocity" and "acceleration" of a row "theta3"), and a
    flagged value shows only the digits its bound leaves."""
    seen = run([*LINKAGE, "solve", str(SAMPLES / "fourbar_me581.toml"), "--set", "theta2=112.024312837",
                "--speed", "10"], 80)
    rows = {r[0]: r[2:] for r in _rates_rows(seen)}
    note = " ".join(seen.split("ill-conditioned here", 1)[1].split())
    for label in ("dtheta3/dt", "d2theta3/dt2", "dtheta4/dt", "d2theta4/dt2"):
        assert label in rows and label in note, (label, rows)
    # exact (docs/worked_examples.md-style 50-digit closed form, README): theta3' = -3.40e6 rad/s
    value, bound = float(rows["dtheta3/dt"][0]), float(rows["dtheta3/dt"][1])
    assert rows["dtheta3/dt"][0] == "-3.4e+06" and abs(value - -3401211.6) <= bound


@pytest.mark.parametrize("engine", [[], ["--batch"]], ids=["stepwise", "batch"])
def test_json_rates_status_is_there_whenever_the_csv_has_one(cli, engine):
    """The CSV's "rates status" column says ok, ill_conditioned or undefined at every
    solved position; the JSON left the key out where the rates were ok, so a reader of
    p["rates_status"] met a KeyError at every ordinary position. An in-line slider-crank
    with r3 = r2 has its toggles at 90 and 270 deg (undefined there)."""
    args = ["sweep", str(SAMPLES / "slider_crank.toml"), "--set", "e=0", "--set", "r3=40", "--speed", "10",
            "--step", "45", *engine]
    doc = json.loads(cli(*args, "--format", "json").out)
    header, *rows = [line.split(",") for line in cli(*args, "--format", "csv").out.splitlines()]
    j = header.index("rates status")
    got = [p.get("rates_status") for p in doc["positions"]]
    assert got == [r[j] for r in rows]
    assert {p["input"] for p in doc["positions"] if p["rates_status"] == "undefined"} == {90.0, 270.0}
    assert set(got) == {"ok", "undefined"}


def test_json_has_no_rates_status_without_a_speed(cli):
    doc = json.loads(cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--format", "json").out)
    assert "rates_status" not in doc and "joints" in doc


def test_scan_help_states_the_step_default_once_and_names_top_k(cli, monkeypatch):
    """scan --help said "Driver increment (default 1). [default: 1.0]" and "--top <int>
    Keep only the first K designs" (K named nowhere else)."""
    monkeypatch.setenv("COLUMNS", "200")
    lines = cli("scan", "--help").out.splitlines()
    step = next(ln for ln in lines if "--step" in ln)
    assert "(default 1)" in step and "[default: 1.0]" not in step, step
    top = next(ln for ln in lines if "--top" in ln)
    assert " K " in top and "<int>" not in top, top


def test_rocker_driven_sweep_and_scan_agree_on_the_transmission_extremes(cli):
    """The scan of the rocker-driven file reported min/max_transmission_deg while its sweep
    showed none; the sweep's extremes (folded into 0..90 by the one rule) are the scan's."""
    args = ("--from", "0", "--to", "359", "--step", "1")
    doc = json.loads(cli("sweep", str(SAMPLES / "fourbar_me581_theta4.toml"), *args, "--format", "json").out)
    folded = [p["transmission"] for p in doc["positions"] if p["status"] == "converged"]
    assert max(folded) <= 90.0
    table = json.loads(cli("scan", str(SAMPLES / "fourbar_me581_theta4.toml"), "--vary", "r2=30:30:1", *args,
                           "-f", "json").out)["tables"][0]
    scan = dict(zip(table["columns"], table["rows"][0]))
    assert min(folded) == pytest.approx(scan["min_transmission_deg"], abs=1e-9)
    assert max(folded) == pytest.approx(scan["max_transmission_deg"], abs=1e-9)


@pytest.mark.parametrize("command", ["solve", "sweep"])
def test_json_rates_carry_their_units_not_only_the_positions_deg(cli, command):
    """JSON's `units` says theta3 is in deg; its velocity is in rad/s, and the driver's
    speed (600rpm given) is stored as 62.83: nothing in the JSON said so."""
    args = [command, str(SAMPLES / "slider_crank.toml"), "--speed", "600rpm", "--format", "json"]
    doc = json.loads(cli(*args, *(["--step", "90"] if command == "sweep" else [])).out)
    assert doc["units"] == {"theta3": "deg", "s": "mm"}
    assert doc["rate_units"] == {"speed": "rad/s", "accel": "rad/s^2",
                                 "velocities": {"theta3": "rad/s", "s": "mm/s"},
                                 "accelerations": {"theta3": "rad/s^2", "s": "mm/s^2"},
                                 "joint_velocities": "mm/s", "joint_accelerations": "mm/s^2"}
    speed = doc["driver"]["speed"] if command == "solve" else doc["driver_motion"]["speed"]
    assert speed == pytest.approx(600 * 2 * math.pi / 60, rel=1e-15)
    assert "rate_units" not in json.loads(cli(*args[:2], "--format", "json").out)


def test_a_rocker_driven_plot_draws_one_assembly_as_one_line(monkeypatch, tmp_path):
    """The plot drew the re-entry on the mirror assembly (theta2 112 -> 268 deg between
    theta4 164 and 165) as a vertical stroke, as if the linkage moved there; then as a
    break in its line. The sweep now follows one assembly by its signs (issue 19), so
    there is no jump to draw: from 105 to 255 deg theta2 is one unbroken line, through
    the change of its name from open to crossed."""
    import math as _math
    from itertools import pairwise

    import linkage
    from linkage.kinematics.continuation import REENTERED
    from linkage.render import plots

    result = linkage.sweep(linkage.load_mechanism(SAMPLES / "fourbar_me581_theta4.toml"),
                           [float(v) for v in range(360)])
    assert not [p.input for p in result.positions if p.note == REENTERED]
    solved = [p for p in result.positions if p.solution]
    assert [p.input for p in solved] == [float(v) for v in range(105, 256)]
    assert {p.branch for p in solved} == {"open", "crossed"}
    seen = {}
    monkeypatch.setattr(plots, "save_figure", lambda fig, path: seen.setdefault("fig", fig))
    plots.sweep_plot(result, tmp_path / "p.png")
    xs, ys = seen["fig"].axes[0].lines[0].get_data()
    assert result.branch == "+" and "+ branch" in seen["fig"]._suptitle.get_text()
    drawn = [(x, y) for x, y in zip(xs, ys) if 105 <= x <= 255]
    assert [x for x, _ in drawn] == [p.input for p in solved]
    assert not any(_math.isnan(y) for _, y in drawn)
    assert max(abs(b - a) for (_, a), (_, b) in pairwise(drawn)) < 15.0

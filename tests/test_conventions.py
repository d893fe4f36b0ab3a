"""One linkage, one answer: the input-output equation, mechanism files, solve and sweep
agree; --branch picks an assembly; drawings place every loop from its own joint."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

import linkage
from linkage import load_mechanism, solve_system
from linkage.problems.closed_form import wrap_degrees

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


@pytest.mark.parametrize("alpha", [10.0, 30.0, 95.0, 200.0, 330.0])
def test_links_report_the_files_theta3_and_theta4(cli, alpha):
    """`solve --links a b c d --alpha A` and crank_rocker.toml (the same links) at
    theta2 = A + 180 give the same theta3 and theta4, on the same branch."""
    doc = json.loads(cli("solve", "--links", "40", "120", "80", "100", "--alpha", str(alpha),
                         "--format", "json").out)
    fc = doc["fourbar"]["file_convention"]
    m = load_mechanism(SAMPLES / "crank_rocker.toml").with_values({"theta2": alpha + 180.0}, {})
    ref = m.problem().reference()[fc["branch"]]
    assert wrap_degrees(fc["theta3"] - ref["theta3"]) == pytest.approx(0, abs=1e-9)
    assert wrap_degrees(fc["theta4"] - ref["theta4"]) == pytest.approx(0, abs=1e-9)
    other = doc["fourbar"]["other_assembly"]
    ref2 = m.problem().reference()[other["branch"]]
    assert wrap_degrees(other["theta4"] - ref2["theta4"]) == pytest.approx(0, abs=1e-9)
    assert len(doc["fourbar"]["roots"]) == 2


@pytest.mark.parametrize("path", sorted(SAMPLES.glob("*.toml")), ids=lambda p: p.name)
def test_sweep_and_solve_agree_at_the_files_driver_value(path):
    m = load_mechanism(path)
    scale = 180.0 / math.pi if m.driver.kind == "angle" else 1.0
    v0 = m.driver.value * scale
    r = solve_system(m.problem(), tol=1e-12)
    assert r.converged
    solved = dict(zip([u.name for u in m.unknowns], m.problem().to_display(r.x)))
    s = linkage.sweep(m, [v0 - 30.0, v0 - 15.0, v0, v0 + 15.0])
    at = s.positions[2]
    assert at.status == "converged"
    for name, value in solved.items():
        assert at.solution[name] == pytest.approx(value, abs=1e-8), (path.name, name)


def test_rapier_sweep_reports_the_same_turn_as_solve():
    """Issue 11's example: the rapier drive at 60 deg is theta13 = 188.57 in solve; the
    sweep said -171.43."""
    s = linkage.sweep(load_mechanism(SAMPLES / "rapier_drive.toml"), [0.0, 30.0, 60.0, 90.0])
    assert s.positions[2].solution["theta13"] == pytest.approx(188.572556, abs=1e-6)


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_solve_file_branch_matches_the_closed_form(cli, branch):
    doc = json.loads(cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--branch", branch,
                         "--format", "json").out)
    assert doc["converged"] and doc["branch"] == branch
    want = {"open": (13.151499346, 114.827770616), "crossed": (-51.898819255, 206.424909476)}[branch]
    assert wrap_degrees(doc["solution"]["theta3"] - want[0]) == pytest.approx(0, abs=1e-8)
    assert wrap_degrees(doc["solution"]["theta4"] - want[1]) == pytest.approx(0, abs=1e-8)


def test_branch_needs_a_closed_form_and_an_assembly(cli):
    run = cli("solve", str(SAMPLES / "rapier_drive.toml"), "--branch", "open")
    assert run.code == 2 and "closed form" in run.err
    run = cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--set", "theta2=180", "--branch", "open")
    assert run.code == 2 and "'open': no such assembly" in run.err


def test_a_drawing_starts_each_loop_at_its_own_joint():
    """The Watt six-bar's second loop starts at the rocker pivot O4 = (100, 0): its points,
    which the drawing joins, begin there and not at the origin."""
    from linkage.problems.loops import LoopModel

    m = load_mechanism(SAMPLES / "watt_sixbar.toml")
    r = solve_system(m.problem(), tol=1e-12)
    loops = LoopModel.compile(m).points(r.x, m.driver.value)
    assert loops[1][0] == pytest.approx(complex(100, 0))
    assert loops[1][-1] == pytest.approx(complex(100, 0), abs=1e-9)  # the loop closes
    c = loops[1][1]
    rates = linkage.position_rates(m, r.x)
    assert (c.real, c.imag) == pytest.approx(rates.joints["C"])


def test_draw_of_the_six_bar_writes_a_picture(cli, tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "watt.png"
    run = cli("draw", str(SAMPLES / "watt_sixbar.toml"), "-o", str(out))
    assert run.code == 0 and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


# --- the transmission angle: one rule (steps.folded_transmission) in every engine -----

ME581 = Path(__file__).resolve().parents[1] / "sample_inputs" / "fourbar_me581.toml"


def _mu_reference(theta2_deg: float) -> float:
    """ME581's four-bar (a = 30, b = 60, c = 45, d = 90 cm): the angle at B between coupler
    and rocker by the law of cosines in triangle A-B-O4 at 40 digits (mpmath), folded into
    0..90 as Norton's transmission angle (the acute angle between the two links' lines)."""
    import mpmath

    mpmath.mp.dps = 40
    a, b, c, d = 30, 60, 45, 90
    t = mpmath.radians(mpmath.mpf(theta2_deg))
    diag2 = a * a + d * d - 2 * a * d * mpmath.cos(t)
    mu = mpmath.degrees(mpmath.acos((b * b + c * c - diag2) / (2 * b * c)))
    return float(min(mu, 180 - mu))


def test_the_transmission_angle_is_one_folded_rule_in_every_engine(cli, tmp_path):
    """solve and sweep printed ME581's unfolded 101.7 deg at theta2 = 65 where scan and
    synthesize folded into 0..90: now every engine reads steps.folded_transmission,
    and its column says so (``transmission angle 0..90 (deg)``)."""
    assert _mu_reference(65.0) == pytest.approx(180.0 - 101.6763, abs=1e-4)  # the 101.7, folded
    doc = json.loads(cli("solve", str(ME581), "-f", "json").out)
    assert doc["fourbars"][0]["transmission_deg"] == pytest.approx(_mu_reference(65.0), abs=1e-11)
    assert "transmission angle 0..90 = 78.32" in cli("solve", str(ME581), "-f", "plain").out
    values = [float(v) for v in range(0, 101, 5)]
    want = [_mu_reference(v) for v in values]
    for engine in ("--no-batch", "--batch"):
        r = cli("sweep", str(ME581), "--from", "0", "--to", "100", "--step", "5", engine, "-f", "csv")
        lines = r.out.splitlines()
        k = lines[0].split(",").index("transmission angle 0..90 (deg)")
        got = [float(line.split(",")[k]) for line in lines[1:]]
        assert got == pytest.approx(want, abs=1e-10), engine
    api = linkage.sweep(load_mechanism(str(ME581)), values)
    assert [p.transmission for p in api.positions] == pytest.approx(want, abs=1e-10)
    r = cli("scan", str(ME581), "--vary", "r3=60:61:2", "--from", "0", "--to", "100", "--step", "5",
            "-f", "json")
    first = json.loads(r.out)["tables"][0]
    row = dict(zip(first["columns"], first["rows"][0]))
    assert row["r3"] == 60.0
    assert row["min_transmission_deg"] == pytest.approx(min(want), abs=1e-10)
    assert row["max_transmission_deg"] == pytest.approx(max(want), abs=1e-10)

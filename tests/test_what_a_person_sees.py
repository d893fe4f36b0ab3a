"""What a person sees: output read the way a mechanism student reads it, at 80 columns and
in every format. Each test is named after what was wrong."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


def law_of_cosines_transmission(r1: float, r2: float, r3: float, r4: float, theta2_deg: float) -> float:
    """The angle at B between coupler and rocker (deg, 0..180), from the triangle A-B-O4:
    |A O4|^2 = r1^2 + r2^2 - 2 r1 r2 cos(theta2) (ground along +x), independent of any
    solver output but theta2."""
    d2 = r1 * r1 + r2 * r2 - 2.0 * r1 * r2 * math.cos(math.radians(theta2_deg))
    return math.degrees(math.acos((r3 * r3 + r4 * r4 - d2) / (2.0 * r3 * r4)))


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
    j = header.index("transmission angle (deg)")
    assert [r[1] for r in rows] == ["converged"] * 3
    assert all(r[j] for r in rows), rows

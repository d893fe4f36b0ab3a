"""A drawing's fixed joints are reported where they were drawn, exactly (LoopModel.drawn,
the placing rule kinematics.placing.walk): not as the sum of the ground's vectors, which
put a pivot drawn at x = 40.0 at 39.99999999999999."""

from __future__ import annotations

import csv
import io
import json
import math

import linkage

TILTED = """name = "tilted ground"
length_unit = "mm"
ground = ["O2", "O4"]
[joints]
O2 = [0.0, 0.0]
A = [0.0, 30.0]
B = [35.0, 110.0]
O4 = [40.0, 70.0]
[links]
crank = ["O2", "A"]
coupler = ["A", "B"]
rocker = ["O4", "B"]
[driver]
link = "crank"
value = 90
"""
"""A four-bar whose ground O2 -> O4 is at atan2(70, 40): 80.6... x cos of it is not 40.0."""


def _file(tmp_path):
    path = tmp_path / "tilted.toml"
    path.write_text(TILTED)
    return path


def test_a_fixed_joint_drawn_at_70_is_reported_as_drawn(cli, tmp_path) -> None:
    path = _file(tmp_path)
    r = cli("solve", str(path), "-f", "json")
    assert r.code == 0, r.err
    joints = json.loads(r.out)["joints"]
    assert joints["O2"] == [0.0, 0.0] and joints["O4"] == [40.0, 70.0]
    for extra in ([], ["--speed", "10", "--accel", "3"]):  # the batch engine and the rates'
        r = cli("sweep", str(path), "--from", "60", "--to", "120", "--step", "5", "-f", "csv", *extra)
        assert r.code == 0, r.err
        rows = list(csv.DictReader(io.StringIO(r.out)))
        assert len(rows) == 13
        for row in rows:
            assert (row["O4.x (mm)"], row["O4.y (mm)"]) == ("40.0", "70.0")
            assert (row["O2.x (mm)"], row["O2.y (mm)"]) == ("0.0", "0.0")
            if extra:
                assert {row[f"O4.{k} (mm/s{s})"] for k, s in (("vx", ""), ("vy", ""), ("ax", "^2"),
                                                              ("ay", "^2"))} == {"0.0"}


def test_the_api_places_fixed_joints_as_drawn_too(tmp_path) -> None:
    m = linkage.load_mechanism(_file(tmp_path))
    for speed in (None, 2.0):
        swept = linkage.sweep(m, [70.0, 90.0, 110.0], joints=True, speed=speed)
        assert [p.rates.joints["O4"] for p in swept.positions] == [(40.0, 70.0)] * 3
    q = linkage.solve_system(m.problem(), record=False).x  # at the drawn 90 deg
    rates = linkage.position_rates(m, q, speed=2.0)
    assert rates.joints["O4"] == (40.0, 70.0) and rates.joint_velocities["O4"] == (0.0, 0.0)


def test_a_moved_ground_places_its_joint_by_its_vectors(cli, tmp_path) -> None:
    """--set ground=100: O4 is no longer where it was drawn, but 100 mm along the drawn
    ground's angle (the drawn joint is reported as drawn only while it is)."""
    r = cli("solve", str(_file(tmp_path)), "--set", "ground=100", "-f", "json")
    assert r.code == 0, r.err
    x, y = json.loads(r.out)["joints"]["O4"]
    angle = math.atan2(70.0, 40.0)
    assert math.isclose(x, 100.0 * math.cos(angle), rel_tol=1e-15)
    assert math.isclose(y, 100.0 * math.sin(angle), rel_tol=1e-15)

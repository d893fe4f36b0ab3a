"""Scans of a joints file (issue 21): a link's derived length scans as the derived loops
file does, and a ground joint's coordinate (``--vary O4.x=LO:HI:N``, column ``O4_x``)
scans, design by design, as drawings with that joint moved by hand do."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from linkage.kinematics.loading import from_text
from linkage.problems.toml_text import loops_text
from linkage.scan import scan
from test_joints_errors import SLIDER_CRANK

VALUES = [float(v) for v in range(0, 360, 6)]
CRANK, COUPLER, ROCKER, POINT, POINT_DEG, THETA2 = 30.0, 60.0, 45.0, 30.0, 40.0, 65.0


def drawing(o4: tuple[float, float] = (90.0, 0.0)) -> str:
    """A four-bar (crank 30, coupler 60, rocker 45 cm, the crank at 65 deg) with its fixed
    joint O4 drawn at ``o4``: B where circles about A (60) and O4 (45) meet, left of A -> O4
    (derived here, not by the code under test), and a coupler point P 30 cm from A at 40 deg
    to AB."""
    t2 = math.radians(THETA2)
    ax, ay = CRANK * math.cos(t2), CRANK * math.sin(t2)
    dx, dy = o4[0] - ax, o4[1] - ay
    d = math.hypot(dx, dy)
    a = (COUPLER ** 2 - ROCKER ** 2 + d * d) / (2 * d)
    h = math.sqrt(COUPLER ** 2 - a * a)
    bx, by = ax + a * dx / d - h * dy / d, ay + a * dy / d + h * dx / d
    t3 = math.atan2(by - ay, bx - ax) + math.radians(POINT_DEG)
    px, py = ax + POINT * math.cos(t3), ay + POINT * math.sin(t3)
    return (f'name = "drawn"\nlength_unit = "cm"\nground = ["O2", "O4"]\n[joints]\nO2 = [0, 0]\n'
            f"A = [{ax!r}, {ay!r}]\nB = [{bx!r}, {by!r}]\nO4 = [{o4[0]!r}, {o4[1]!r}]\n"
            f"P = [{px!r}, {py!r}]\n"
            '[links]\ncrank = ["O2", "A"]\ncoupler = ["A", "B", "P"]\nrocker = ["O4", "B"]\n'
            f'[driver]\nlink = "crank"\nvalue = {THETA2!r}\n')


def same(got: np.ndarray, want: np.ndarray, tol: float) -> bool:
    if got.dtype.kind in "fc":
        return bool(np.all((np.isnan(got) & np.isnan(want)) | (np.abs(got - want) <= tol)))
    return bool(np.array_equal(got, want))


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_derived_length_scans_as_the_derived_loops_file(tmp_path) -> None:
    drawn = write(tmp_path, "drawn.toml", drawing())
    loops = write(tmp_path, "loops.toml", loops_text(from_toml(drawing()), "drawn.toml"))
    vary = {"coupler": (50.0, 70.0, 5), "coupler_A_P": (20.0, 40.0, 3)}
    got, want = scan(drawn, vary, values=VALUES), scan(loops, vary, values=VALUES)
    assert list(got) == list(want)
    for k in got:
        assert np.array_equal(got[k], want[k], equal_nan=got[k].dtype.kind == "f"), k


@pytest.mark.parametrize(("driver", "values"), [('link = "crank"', VALUES),
                                                ('slider = "block"', [60.0 + 5 * k for k in range(19)])])
def test_a_slider_cranks_derived_lengths_scan_as_its_loops_file(tmp_path, driver, values) -> None:
    text = SLIDER_CRANK.replace('link = "crank"', driver)
    drawn = write(tmp_path, "drawn.toml", text)
    loops = write(tmp_path, "loops.toml", loops_text(from_toml(text), "drawn.toml"))
    vary = {"coupler": (100.0, 140.0, 3), "e_block": (-10.0, 10.0, 3)}
    got, want = scan(drawn, vary, values=values), scan(loops, vary, values=values)
    assert list(got) == list(want) and got["solved_fraction"].min() > 0.5
    for k in got:
        assert np.array_equal(got[k], want[k], equal_nan=got[k].dtype.kind == "f"), k


def from_toml(text: str) -> dict:
    import tomllib

    return tomllib.loads(text)


def moved_by_hand(tmp_path: Path, x: float, y: float) -> dict[str, np.ndarray]:
    """The scan of a drawing redrawn with O4 at (x, y), its links kept (the crank at the
    first drawing's own length, so only O4 differs)."""
    crank = from_text(drawing(), "<drawn>").parameters["crank"].value
    path = write(tmp_path, f"moved_{x!r}_{y!r}.toml", drawing((x, y)))
    return scan(path, {"crank": (crank, crank, 1)}, values=VALUES)


def check_against_moved(tmp_path: Path, got: dict[str, np.ndarray]) -> None:
    metrics = [k for k in got if k not in ("design", "O4_x", "O4_y")]
    assert {"theta_rocker_range", "grashof", "min_transmission_deg", "P_x_min"} <= set(metrics)
    assert len(got["design"]) > 1
    for i in range(len(got["design"])):
        want = moved_by_hand(tmp_path, float(got["O4_x"][i]), float(got["O4_y"][i]))
        assert want["feasible_fraction"][0] >= 0.4  # compared at solved positions
        for k in metrics:
            assert same(got[k][i:i + 1], want[k], 1e-12), (i, k, got[k][i], want[k][0])


def test_a_ground_joints_coordinates_scan_as_drawings_with_it_moved_by_hand(tmp_path) -> None:
    drawn = write(tmp_path, "drawn.toml", drawing())
    got = scan(drawn, {"O4.x": (80.0, 100.0, 3), "O4.y": (-6.0, 6.0, 2)}, values=VALUES)
    assert list(got)[:3] == ["design", "O4_x", "O4_y"]
    assert got["O4_x"].tolist() == [80.0, 80.0, 90.0, 90.0, 100.0, 100.0]
    assert got["O4_y"].tolist() == [-6.0, 6.0] * 3
    check_against_moved(tmp_path, got)


def test_sampled_coordinates_too(tmp_path) -> None:
    drawn = write(tmp_path, "drawn.toml", drawing())
    got = scan(drawn, {"O4.x": (82.0, 98.0), "O4.y": (-5.0, 5.0)}, samples=3, seed=7, values=VALUES)
    assert np.all((got["O4_x"] >= 82) & (got["O4_x"] <= 98) & (np.abs(got["O4_y"]) <= 5))
    check_against_moved(tmp_path, got)


def test_one_coordinate_keeps_the_other_as_drawn(tmp_path) -> None:
    """O4.y alone: O4 moves up from (90, 0), the ground tilting (its angle a parameter)."""
    drawn = write(tmp_path, "drawn.toml", drawing())
    got = scan(drawn, {"O4.y": (-4.0, 4.0, 2)}, values=VALUES)
    got["O4_x"] = np.array([90.0, 90.0])
    check_against_moved(tmp_path, got)


def test_the_chunks_and_the_scheduler_change_nothing(tmp_path) -> None:
    drawn = write(tmp_path, "drawn.toml", drawing())
    vary = {"O4.x": (80.0, 100.0, 4), "coupler": (55.0, 65.0, 2)}
    one = scan(drawn, vary, values=VALUES, scheduler="synchronous")
    many = scan(drawn, vary, values=VALUES, scheduler="threads", workers=2, chunk=3)
    for k in one:
        assert np.array_equal(one[k], many[k], equal_nan=one[k].dtype.kind == "f"), k


def test_the_cli_reads_the_column_in_where_and_sort(cli, tmp_path) -> None:
    drawn = write(tmp_path, "drawn.toml", drawing())
    r = cli("scan", str(drawn), "--vary", "O4.x=80:100:5", "--vary", "O4.y=-5:5:3",
            "--where", "O4_x > 85 and O4_y >= 0", "--sort", "O4_x", "--desc", "-f", "csv",
            "--columns", "design,O4_x,O4_y")
    assert r.code == 0, r.err
    lines = r.out.splitlines()
    assert lines[0] == "design,O4_x (cm),O4_y (cm)"
    # 90, 95, 100 by 0, 5: the largest x first, ties in design order
    assert [tuple(map(float, ln.split(",")[1:])) for ln in lines[1:]] == [
        (100.0, 0.0), (100.0, 5.0), (95.0, 0.0), (95.0, 5.0), (90.0, 0.0), (90.0, 5.0)]




@pytest.mark.parametrize(("args", "message"), [
    (["--vary", "O2.x=-5:5:3"], "--vary O2.x: O2 is where the drawing is placed (the ground's first "
                                "joint): moving it moves the whole drawing; the fixed joints after "
                                "O2 can move: O4.x, O4.y"),
    (["--vary", "A.y=20:30:3"], "--vary A.y: A moves with crank, coupler: where it is follows from "
                                "the link lengths; vary those instead (crank, coupler, coupler_A_P)"),
    (["--vary", "P.x=20:30:3"], "P moves with coupler"),
    (["--vary", "O9.x=1:2:2"], "--vary O9.x: no joint 'O9' in"),
    (["--vary", "O4.z=1:2:2"], "--vary O4.z: a joint's coordinates are x and y, not 'z'"),
    (["--vary", "O4.x=80:90:2", "--vary", "ground=80:90:2"],
     "--vary O4.x: ground is O4's place too (derived from it); vary O4.x/O4.y or ground, not both"),
    (["--vary", "O4.x=80:90:2", "--set", "theta_ground=1"], "theta_ground is O4's place too"),
    (["--vary", "O4.x=80:90:2", "--vary", "O4.x=80:90:2"], "--vary O4.x is given twice"),
    (["--vary", "O4.x=80:90:2", "--samples", "3"], "--samples draws random designs"),
    (["--vary", "O4.x=80:90"], "--vary O4_x: give :N points for a grid"),
    (["--vary", "O4.x=1e200:1e200:1"], "--vary O4.x: ground: a length must be 0 or between 1e-100 "
                                       "and 1e+100 cm in magnitude, got 1e+200"),
    (["--vary", "O4.x=-5:5:3", "--vary", "O4.y=-1:1:2"], "--vary O4.x and O4.y: the range puts O4 on "
                                                         "O2, the ground's first joint"),
    (["--vary", "O4.x=0:0:1", "--vary", "O4.y=0:1:2"], "the range puts O4 on O2"),
])
def test_a_coordinate_that_cannot_vary_is_one_line(cli, tmp_path, args, message) -> None:
    drawn = write(tmp_path, "drawn.toml", drawing())
    r = cli("scan", str(drawn), *args)
    assert r.code == 2 and r.err.startswith("error: ") and r.err.count("\n") == 1, r.err
    assert message in r.err, r.err


def test_a_loops_file_has_no_coordinates_and_a_lone_ground_joint_cannot_move(cli, tmp_path) -> None:
    loops = write(tmp_path, "loops.toml", loops_text(from_toml(drawing()), "drawn.toml"))
    r = cli("scan", str(loops), "--vary", "O4.x=80:90:2")
    assert r.code == 2 and r.err.count("\n") == 1
    assert ("--vary O4.x: a joint's coordinate is varied in a joints file; " in r.err
            and "is in the loops form: vary its parameters (crank, coupler, rocker, ground, "
                "theta_ground, coupler_A_P)" in r.err), r.err
    slider = write(tmp_path, "slider.toml", SLIDER_CRANK)
    r = cli("scan", str(slider), "--vary", "O2.y=-1:1:3")
    assert r.code == 2 and "O2 is this drawing's only fixed joint" in r.err, r.err


def watt_moved(o6: tuple[float, float] | None = None) -> str:
    """test_joints_form's Watt drawing with its third fixed joint O6 at ``o6``: D redrawn
    where circles about C (|CD|) and O6 (|O6 D|) meet, on the side of C -> O6 it was drawn
    (derived here), every other joint where it was."""
    import tomllib

    from test_joints_form import watt_drawing

    text = watt_drawing()
    xy = {k: tuple(v) for k, v in tomllib.loads(text)["joints"].items()}
    if o6 is None:
        return text
    (cx, cy), (dx0, dy0), (ox, oy) = xy["C"], xy["D"], xy["O6"]
    r1, r2 = math.dist(xy["C"], xy["D"]), math.dist(xy["O6"], xy["D"])
    side = math.copysign(1.0, (ox - cx) * (dy0 - cy) - (oy - cy) * (dx0 - cx))
    ux, uy = o6[0] - cx, o6[1] - cy
    d = math.hypot(ux, uy)
    a = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    h = side * math.sqrt(r1 * r1 - a * a)
    d_new = (cx + a * ux / d - h * uy / d, cy + a * uy / d + h * ux / d)
    for name, (x, y) in (("O6", o6), ("D", d_new)):
        old = f"{name} = [{xy[name][0]!r}, {xy[name][1]!r}]"
        assert old in text
        text = text.replace(old, f"{name} = [{x!r}, {y!r}]")
    return text


def test_a_six_bars_third_fixed_joint_scans_as_drawings_with_it_moved_by_hand(tmp_path) -> None:
    """The Watt's O6 is ground_O2_O6 and theta_ground_O2_O6 from O2 (O4 stays)."""
    import tomllib

    values = [float(v) for v in range(0, 360, 30)]
    o6 = tomllib.loads(watt_moved())["joints"]["O6"]
    drawn = write(tmp_path, "watt.toml", watt_moved())
    got = scan(drawn, {"O6.x": (o6[0] - 4, o6[0] + 4, 2), "O6.y": (o6[1] - 3, o6[1] + 3, 2)}, values=values)
    crank = from_text(watt_moved(), "<watt>").parameters["crank"].value
    metrics = [k for k in got if k not in ("design", "O6_x", "O6_y")]
    assert "theta_link7_range" in metrics
    for i in range(len(got["design"])):
        moved = write(tmp_path, f"watt_{i}.toml", watt_moved((float(got["O6_x"][i]), float(got["O6_y"][i]))))
        want = scan(moved, {"crank": (crank, crank, 1)}, values=values)
        assert want["solved_fraction"][0] > 0.5
        for k in metrics:
            assert same(got[k][i:i + 1], want[k], 1e-12), (i, k, got[k][i], want[k][0])


def test_the_python_api_reads_coordinates_from_a_path_not_a_mechanism(tmp_path) -> None:
    from linkage.errors import InputError
    from linkage.kinematics.loading import load

    drawn = write(tmp_path, "drawn.toml", drawing())
    with pytest.raises(InputError, match="a joint's coordinate is read from a joints file: give its path"):
        scan(load(drawn), {"O4.x": (80.0, 90.0, 2)}, values=VALUES)
    assert scan(str(drawn), {"O4.x": (80.0, 90.0, 2)}, values=VALUES)["O4_x"].tolist() == [80.0, 90.0]

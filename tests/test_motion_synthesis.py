"""Motion generation through five poses (linkage.synthesize_motion, docs/motion_synthesis.md),
against four-bars built here: their poses are computed by sweeping them with the kinematics
engine, and the synthesis must list each of them again, defect-free, through its poses."""

from __future__ import annotations

import cmath
import math
import random
import re

import pytest

from linkage.errors import InputError
from linkage.kinematics.loading import from_text
from linkage.kinematics.sweep import sweep_mechanism
from linkage.synthesis.motion import mechanism_text, synthesize_motion
from linkage.synthesis.motion_curves import GRID


def circle_meet(c1: complex, r1: float, c2: complex, r2: float, side: float) -> complex:
    """A point at r1 from c1 and r2 from c2 (the side of c1 -> c2 by ``side``)."""
    d = abs(c2 - c1)
    x = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    return c1 + (c2 - c1) / d * complex(x, side * math.sqrt(r1 * r1 - x * x))


def poses_of(o2: complex, o4: complex, a: float, b: float, c: float, inputs: list[float],
             body: complex, turn: float) -> list[tuple[float, float, float]]:
    """The poses of a coupler frame (origin A + body rotated with AB, angle AB's + turn) at the
    input angles, by the engine's sweep of the four-bar drawn at the first."""
    a1 = o2 + a * cmath.exp(1j * math.radians(inputs[0]))
    b1 = circle_meet(a1, b, o4, c, 1.0)
    joints = {"O2": (o2.real, o2.imag), "A": (a1.real, a1.imag), "B": (b1.real, b1.imag),
              "O4": (o4.real, o4.imag)}
    result = sweep_mechanism(from_text(mechanism_text(joints, inputs[0], (inputs[0], inputs[-1])), "t"),
                             inputs, joints=True)
    out = []
    for p in result.positions:
        assert p.status == "converged"
        aj, bj = complex(*p.rates.joints["A"]), complex(*p.rates.joints["B"])
        th = cmath.phase(bj - aj)
        origin = aj + cmath.exp(1j * th) * body
        out.append((origin.real, origin.imag, math.degrees(th) + turn))
    return out


def found(m, o2: complex, o4: complex):
    size = max(abs(complex(p.x, p.y) - sum(complex(q.x, q.y) for q in m.poses) / 5) for p in m.poses)
    return [d for d in m.designs if abs(complex(*d.joints["O2"]) - o2) <= 1e-8 * size
            and abs(complex(*d.joints["O4"]) - o4) <= 1e-8 * size]




def test_a_four_bar_is_recovered_from_five_of_its_poses() -> None:
    o2, o4 = 0j, 4 + 0j
    poses = poses_of(o2, o4, 1.5, 4.0, 3.5, [30.0, 80.0, 140.0, 200.0, 290.0], complex(1.0, 0.8), 10.0)
    m = synthesize_motion(poses)
    assert len(m.burmester.cranks) == 4
    mine = found(m, o2, o4)
    assert len(mine) == 1
    d = mine[0]
    assert d.defects == () and d.grashof == "crank-rocker"
    assert d.links == pytest.approx({"input": 1.5, "coupler": 4.0, "output": 3.5, "ground": 4.0}, rel=1e-9)
    assert max(d.pose_error) <= 1e-9
    assert [round(v, 9) for v in d.input_deg] == pytest.approx([30.0, 80.0, 140.0, -160.0, -70.0], abs=1e-8)


def test_random_four_bars_are_recovered_and_every_listed_one_passes_through_its_poses() -> None:
    rng = random.Random(7)
    done = 0
    while done < 4:
        a, b, c, d = rng.uniform(0.5, 1.5), rng.uniform(3, 5), rng.uniform(3, 5), rng.uniform(3, 5)
        links = sorted((a, b, c, d))
        if links[0] + links[3] >= links[1] + links[2] - 0.3 or links[0] != a:
            continue  # a crank-rocker, clear of the change point
        o2 = complex(rng.uniform(-2, 2), rng.uniform(-2, 2))
        o4 = o2 + d * cmath.exp(1j * rng.uniform(-0.5, 0.5))
        start = rng.uniform(0, 360)
        inputs = [start + v for v in sorted(rng.sample(range(20, 340, 7), 4))]
        poses = poses_of(o2, o4, a, b, c, [start, *inputs], complex(rng.uniform(-1, 1), rng.uniform(-1, 1)),
                         rng.uniform(-90, 90))
        m = synthesize_motion(poses)
        mine = found(m, o2, o4)
        assert len(mine) == 1 and mine[0].defects == ()
        for design in m.designs:
            if "branch" in design.defect_names or "grashof" in design.defect_names:
                continue
            # the engine's sweep of the listed linkage, read here: its body at each pose's input
            # angle (the coupler's A and B as the pose's frame carries them) is the pose
            check_passes_through(design, m.poses)
        done += 1


def check_passes_through(design, poses) -> None:
    o2 = complex(*design.joints["O2"])
    values = [design.input_deg[0]]
    for v in design.input_deg[1:]:
        values.append(values[-1] + design.direction * ((design.direction * (v - values[-1])) % 360.0))
    steps = range(int(abs(values[-1] - values[0])))
    fine = sorted({*values, *(values[0] + design.direction * k for k in steps)},
                  key=lambda v: design.direction * v)
    text = mechanism_text(design.joints, values[0], (min(fine), max(fine)))
    result = sweep_mechanism(from_text(text, "t"), fine, joints=True)
    at = {v: p for v, p in zip(fine, result.positions)}
    a1, b1 = complex(*design.joints["A"]), complex(*design.joints["B"])
    p1 = poses[0]
    frame1 = cmath.exp(1j * math.radians(p1.angle_deg))
    za, zb = (a1 - complex(p1.x, p1.y)) / frame1, (b1 - complex(p1.x, p1.y)) / frame1
    size = max(abs(complex(p.x, p.y) - complex(q.x, q.y)) for p in poses for q in poses)
    for v, p in zip(values, poses):
        pos = at[v]
        assert pos.status == "converged"
        frame = cmath.exp(1j * math.radians(p.angle_deg))
        want_a, want_b = complex(p.x, p.y) + frame * za, complex(p.x, p.y) + frame * zb
        assert abs(complex(*pos.rates.joints["A"]) - want_a) <= 1e-9 * size
        assert abs(complex(*pos.rates.joints["B"]) - want_b) <= 1e-9 * size
        assert abs(complex(*pos.rates.joints["A"]) - o2) == pytest.approx(design.links["input"], rel=1e-9)


FIVE = [(0, 0, 0), (1, 0.2, 10), (2, 0.5, 25), (2.8, 1.2, 40), (3.2, 2, 60)]


@pytest.mark.parametrize("poses, said", [
    (FIVE[:2], "got 2"),
    ([*FIVE, (4, 3, 70)], "got 6"),
    ([FIVE[0], FIVE[1], FIVE[2], FIVE[3], FIVE[1]], "same pose"),
    ([FIVE[0], FIVE[1], (math.nan, 0, 0), FIVE[3], FIVE[4]], "poses[2]"),
    ([FIVE[0], FIVE[1], (1e300, 0, 0), FIVE[3], FIVE[4]], "poses[2]"),
    ("0,0,0", "list of 5 poses"),
])
def test_bad_poses_are_refused_with_one_line(poses, said) -> None:
    with pytest.raises(InputError, match=re.escape(said)):
        synthesize_motion(poses)


def test_the_transmission_floor_is_checked() -> None:
    with pytest.raises(InputError, match="min_transmission"):
        synthesize_motion(FIVE, min_transmission=95)


def cli_poses(poses) -> list[str]:
    return [w for p in poses for w in ("--pose", ",".join(repr(float(v)) for v in p))]


def test_the_command_writes_a_defect_free_design_that_sweeps_through_the_poses(tmp_path, capsys) -> None:
    from linkage.cli import run_cli

    o2, o4 = 0j, 4 + 0j
    poses = poses_of(o2, o4, 1.5, 4.0, 3.5, [30.0, 80.0, 140.0, 200.0, 290.0], complex(1.0, 0.8), 10.0)
    out = tmp_path / "design.toml"
    args = ["synthesize", "--motion", *cli_poses(poses), "--design", "11", "-o", str(out), "-f", "json"]
    assert run_cli(args) == 0
    m = synthesize_motion(poses)
    chosen = m.designs[10]
    assert chosen.defects == () and chosen.cranks == (3, 1)  # the four-bar the poses came from
    text = out.read_text()
    assert "design 11" in text and "DEFECTS" not in text
    mech = from_text(text, str(out))
    result = sweep_mechanism(mech, [30.0, 80.0, 140.0, 200.0, 290.0], joints=True)
    for p, pose in zip(result.positions, poses):
        aj, bj = complex(*p.rates.joints["A"]), complex(*p.rates.joints["B"])
        origin = aj + cmath.exp(1j * cmath.phase(bj - aj)) * complex(1.0, 0.8)
        assert abs(origin - complex(pose[0], pose[1])) <= 1e-9
    # the file is kept: a second run without --force is refused before any work
    capsys.readouterr()
    assert run_cli(["synthesize", "--motion", *cli_poses(poses), "-o", str(out)]) == 2
    assert "exists" in capsys.readouterr().err


@pytest.mark.parametrize("args, said", [
    (["--pose", "0,0,0"], "got 1"),
    (["--pose", "0,0,0", "--pose", "1,0,10", "--pose", "2,1,30"], "4 free numbers"),
    (["--pose", "0,0"], "write X,Y,DEG"),
    ([], "give 5 poses"),
    (["--function", "x", "--pose", "0,0,0"], "--motion takes poses"),
])
def test_the_command_refuses_bad_poses_with_one_line(args, said, capsys) -> None:
    from linkage.cli import run_cli

    assert run_cli(["synthesize", "--motion", *args]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and said in err[0]


def test_pose_options_without_motion_are_refused(capsys) -> None:
    from linkage.cli import run_cli

    assert run_cli(["synthesize", "--function", "x", "--x", "1:2", "--pose", "0,0,0"]) == 2
    assert "options of --motion" in capsys.readouterr().err


def test_three_poses_and_the_circle_points_of_a_four_bar_give_it_back() -> None:
    o2, o4 = 0.5 - 0.25j, 4.4 + 0.9j
    a, b, c = 1.2, 4.1, 3.3
    inputs = [40.0, 150.0, 260.0]
    poses = poses_of(o2, o4, a, b, c, inputs, complex(-0.4, 1.1), -25.0)
    a1 = o2 + a * cmath.exp(1j * math.radians(inputs[0]))
    b1 = circle_meet(a1, b, o4, c, 1.0)
    m = synthesize_motion(poses, circle_points=[(a1.real, a1.imag), (b1.real, b1.imag)])
    assert m.burmester is None and len(m.cranks) == 2
    design = m.designs[0]
    assert abs(complex(*design.joints["O2"]) - o2) <= 1e-9 and abs(complex(*design.joints["O4"]) - o4) <= 1e-9
    assert design.links == pytest.approx({"input": a, "coupler": b, "output": c, "ground": abs(o4 - o2)},
                                         rel=1e-9)
    assert design.defects == () and max(design.pose_error) <= 1e-9
    check_passes_through(design, m.poses)


def test_three_poses_say_what_is_free() -> None:
    three = FIVE[:3]
    with pytest.raises(InputError, match="4 free numbers, the two circle points"):
        synthesize_motion(three)
    with pytest.raises(InputError, match="must differ"):
        synthesize_motion(three, circle_points=[(1, 1), (1, 1)])
    with pytest.raises(InputError, match="five poses fix them"):
        synthesize_motion(FIVE, circle_points=[(1, 1), (2, 1)])


def test_four_poses_give_centre_and_circle_point_curves_through_the_four_bars_pivots(tmp_path) -> None:
    o2, o4 = 0.5 - 0.25j, 4.4 + 0.9j
    a, b, c = 1.2, 4.1, 3.3
    inputs = [40.0, 110.0, 190.0, 260.0]
    poses = poses_of(o2, o4, a, b, c, inputs, complex(-0.4, 1.1), -25.0)
    m = synthesize_motion(poses)
    curves = m.curves
    assert curves is not None and m.designs == () and len(curves.centre) > 100
    pts = [complex(p.x, p.y) for p in m.poses]
    size = max(abs(v - sum(pts) / 4) for v in pts)
    # every point: its circle point, carried through the four poses (the body's frame from
    # pose 1), stays at one distance from its centre point
    turn = [cmath.exp(1j * math.radians(p.angle_deg)) for p in m.poses]
    for g, w in zip(curves.centre, curves.circle):
        z = (w - pts[0]) / turn[0]
        lengths = [abs(d + r * z - g) for d, r in zip(pts, turn)]
        assert max(lengths) - min(lengths) <= 1e-9 * size
    # the four-bar's own pivots lie on the curves, to the grid's spacing
    a1 = o2 + a * cmath.exp(1j * math.radians(inputs[0]))
    b1 = circle_meet(a1, b, o4, c, 1.0)
    step = (curves.box[1] - curves.box[0]) / (GRID - 1)
    for ground, moving in ((o2, a1), (o4, b1)):
        k = int(abs(curves.centre - ground).argmin())
        assert abs(curves.centre[k] - ground) <= 2 * step
        assert abs(curves.circle[k] - moving) <= 0.1 * size


def test_the_curves_are_drawn_with_plot_and_only_for_four_poses(tmp_path, capsys) -> None:
    from linkage.cli import run_cli

    picture = tmp_path / "curves.png"
    assert run_cli(["synthesize", "--motion", *cli_poses(FIVE[:4]), "--plot", str(picture), "-f", "csv"]) == 0
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    lines = capsys.readouterr().out.splitlines()
    assert lines[0] == "centre_x,centre_y,circle_x,circle_y,spread" and len(lines) > 100
    assert run_cli(["synthesize", "--motion", *cli_poses(FIVE), "--plot", str(tmp_path / "x.png")]) == 2
    assert "give 4 poses" in capsys.readouterr().err and not (tmp_path / "x.png").exists()


def test_a_design_written_with_defects_says_them_not_that_it_runs_through_the_poses(tmp_path, capsys) -> None:
    """--design K of a design with defects is written as asked, its defects named on stderr; the
    defect-free one still says that its sweep runs through the poses."""
    from linkage.cli import run_cli

    o2, o4 = 0j, 4 + 0j
    poses = poses_of(o2, o4, 1.5, 4.0, 3.5, [30.0, 80.0, 140.0, 200.0, 290.0], complex(1.0, 0.8), 10.0)
    m = synthesize_motion(poses)
    bad = next(k for k, d in enumerate(m.designs) if d.defects)
    out = tmp_path / "bad.toml"
    capsys.readouterr()
    args = ["synthesize", "--motion", *cli_poses(poses), "--design", str(bad + 1), "-o", str(out)]
    assert run_cli(args) == 0
    err = capsys.readouterr().err
    assert out.exists() and "with defects: " + ", ".join(m.designs[bad].defect_names) in err
    assert "runs it through the poses" not in err


def test_four_poses_with_a_mechanism_file_output_are_refused(tmp_path, capsys) -> None:
    """Four poses give the centre-point and circle-point curves, no four-bar: -o FILE.toml is
    refused with one line (it was ignored, exit 0) and no file is written."""
    from linkage.cli import run_cli

    out = tmp_path / "four.toml"
    four = FIVE[:4]
    capsys.readouterr()
    assert run_cli(["synthesize", "--motion", *cli_poses(four), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "4 poses give the centre-point and circle-point curves" in err[0]
    assert not out.exists()


@pytest.mark.parametrize("text, said", [
    ("x,y,angle\n0,0,0\n", "line 1 ('x,y,angle'): must be a finite number"),
    ("0,0,0\n# a comment\n1,2\n", "line 3 ('1,2'): write X,Y,DEG"),
])
def test_a_poses_file_refusal_names_its_line_not_a_pose_option(tmp_path, capsys, text, said) -> None:
    """A header line said "--pose 1 must be a finite number ... got 'x'" (an option nobody gave)."""
    from linkage.cli import run_cli

    path = tmp_path / "poses.txt"
    path.write_text(text)
    capsys.readouterr()
    assert run_cli(["synthesize", "--motion", "--poses", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith(f"error: --poses {path} ") and said in err[0]


def test_poses_within_the_pose_tolerance_of_each_other_are_one_pose(capsys) -> None:
    """A fifth pose 1e-9 deg from the first (the same place) is the first again: four poses,
    a continuum of cranks. It was solved as five (exit 1, "1 real Burmester cranks" beside
    two certified real roots); exactly equal poses were already refused."""
    from linkage.cli import run_cli

    five = [*FIVE[:4], (FIVE[0][0], FIVE[0][1], FIVE[0][2] + 1e-9)]
    with pytest.raises(InputError, match=r"poses\[0\] and poses\[4\] are the same pose"):
        synthesize_motion(five)
    capsys.readouterr()
    assert run_cli(["synthesize", "--motion", *cli_poses(five)]) == 2
    assert "are the same pose" in capsys.readouterr().err
    synthesize_motion([*FIVE[:4], (FIVE[0][0], FIVE[0][1], FIVE[0][2] + 1e-3)])  # 1.7e-5 rad: a pose

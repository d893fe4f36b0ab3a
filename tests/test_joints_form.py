"""The joints form's core (issue 21, revolute joints): a drawing's loops derived by a cycle
basis; the drawn pose solves to the drawn coordinates, and other driver values give the
vector-loop twin's answers; a drawing that is not a mechanism of mobility 1 is refused."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from linkage import solve_system
from linkage.errors import InputError
from linkage.kinematics.loading import from_text, load
from linkage.problems.start import start_on_branch

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


def me581_drawing(theta2: float = 65.0, extra: str = "", links: str | None = None, driver: str = "") -> str:
    """worked example P3, docs/worked_examples.md's four-bar (r1..r4 = 90, 30, 60, 45 cm) drawn at
    theta2 on its open
    branch (theta3, theta4 by the law of cosines, derived here), with a coupler point P 30 cm
    from A at 40 deg to AB."""
    t2 = math.radians(theta2)
    ax, ay = 30 * math.cos(t2), 30 * math.sin(t2)
    dx, dy = 90 - ax, -ay
    d = math.hypot(dx, dy)
    a = (60 ** 2 - 45 ** 2 + d * d) / (2 * d)
    h = math.sqrt(60 ** 2 - a * a)
    bx, by = ax + a * dx / d - h * dy / d, ay + a * dy / d + h * dx / d
    t3 = math.atan2(by - ay, bx - ax)
    px, py = ax + 30 * math.cos(t3 + math.radians(40)), ay + 30 * math.sin(t3 + math.radians(40))
    links = links if links is not None else ('crank = ["O2", "A"]\ncoupler = ["A", "B", "P"]\n'
                                             'rocker = ["O4", "B"]')
    return (f'name = "ME581 drawn"\nlength_unit = "cm"\nground = ["O2", "O4"]\n[joints]\nO2 = [0, 0]\n'
            f"A = [{ax!r}, {ay!r}]\nB = [{bx!r}, {by!r}]\nO4 = [90, 0]\nP = [{px!r}, {py!r}]\n{extra}"
            f'[links]\n{links}\n[driver]\nlink = "crank"\n{driver or f"value = {theta2!r}"}\n')


def joints_at(text: str) -> tuple[dict[str, tuple[float, float]], list[float]]:
    from linkage.kinematics.rates import rates_at

    m = from_text(text, "<drawing>")
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged
    return rates_at(m, r.x).joints, [math.degrees(v) for v in r.x]


def test_the_drawn_pose_solves_to_the_drawn_coordinates() -> None:
    text = me581_drawing()
    placed, _ = joints_at(text)
    doc_joints = {line.split(" = ")[0]: eval(line.split(" = ")[1])
                  for line in text.split("[joints]\n")[1].split("[links]")[0].splitlines()}
    for name, (x, y) in doc_joints.items():
        assert placed[name] == pytest.approx((x, y), abs=1e-9), name


@pytest.mark.parametrize("theta2", [0.0, 20.0, 60.0, 100.0, 280.0, 330.0])
@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_other_driver_values_give_the_vector_loop_twins_answers(theta2: float, branch: str) -> None:
    drawing = from_text(me581_drawing(), "<drawing>").with_values({"theta_crank": theta2}, {})
    twin = load(SAMPLES / "fourbar_me581.toml").with_values({"theta2": theta2}, {})
    got = solve_system(start_on_branch(drawing, branch, False).problem(), tol=1e-14)
    want = solve_system(start_on_branch(twin, branch, False).problem(), tol=1e-14)
    assert got.converged and want.converged
    diff = [((math.degrees(g - w) + 180) % 360) - 180 for g, w in zip(got.x, want.x)]
    assert diff == pytest.approx([0.0, 0.0], abs=1e-12)


def test_the_coupler_point_rides_on_the_coupler() -> None:
    placed, q = joints_at(me581_drawing(theta2=100.0))
    ax, ay = placed["A"]
    t = math.radians(q[0] + 40)
    assert placed["P"] == pytest.approx((ax + 30 * math.cos(t), ay + 30 * math.sin(t)), abs=1e-12)


@pytest.mark.parametrize(("links", "extra", "message"), [
    ('crank = ["O2", "A"]\ncoupler = ["A", "B", "P"]\nrocker = ["O4", "B"]\nbrace = ["A", "O4"]', "",
     "mobility 0 (5 bodies with the ground, 6 revolute pairs: 3 x 4 - 2 x 6): this is a structure"),
    ('crank = ["O2", "A"]\ncoupler = ["A", "B", "P"]\nrocker = ["C", "B"]\nlink = ["C", "O4"]',
     "C = [100, 20]\n", "mobility 2 (5 bodies with the ground, 5 revolute pairs: 3 x 4 - 2 x 5): "
                        "name 1 more driver"),
    ('crank = ["O2", "A"]\ncoupler = ["A", "B", "P"]\nrocker = ["O4", "B"]', "C = [5, 5]\n",
     "joints.C: is on no link"),
    ('crank = ["O2", "A"]\ncoupler = ["A", "Q", "P"]\nrocker = ["O4", "B"]', "",
     "links.coupler: 'Q' is not a joint"),
])
def test_a_drawing_that_is_not_a_mechanism_is_refused(links: str, extra: str, message: str) -> None:
    with pytest.raises(InputError) as e:
        from_text(me581_drawing(links=links, extra=extra), "<drawing>")
    assert message in str(e.value)


def _mirrored(text: str) -> str:
    """The drawing with B reflected in the line A -> O4: the crossed assembly of the same
    links at the same crank angle (P, on the coupler, follows it)."""
    joints = {line.split(" = ")[0]: eval(line.split(" = ")[1])
              for line in text.split("[joints]\n")[1].split("[links]")[0].splitlines()}
    (ax, ay), (bx, by), (px, py) = joints["A"], joints["B"], joints["P"]
    ux, uy = 90 - ax, -ay
    n = math.hypot(ux, uy)
    ux, uy = ux / n, uy / n

    def reflect(x: float, y: float) -> tuple[float, float]:
        along = (x - ax) * ux + (y - ay) * uy
        return 2 * (ax + along * ux) - x, 2 * (ay + along * uy) - y

    for name, (x, y) in (("B", (bx, by)), ("P", (px, py))):
        rx, ry = reflect(x, y)
        text = text.replace(f"{name} = [{x!r}, {y!r}]", f"{name} = [{rx!r}, {ry!r}]")
    return text


@pytest.mark.parametrize("branch", ["open", "crossed"])
@pytest.mark.parametrize("value", [100.0, 280.0, 65.5])
def test_a_driver_value_off_the_drawing_is_solved_there_on_the_drawn_assembly(branch: str,
                                                                              value: float) -> None:
    """A drawing whose [driver] value is not its drawn angle was refused (even 1e-6 deg
    off): now it is solved at the value, on the assembly the drawing shows, reached from
    it along that assembly, and says where it was drawn. The joints are the law of cosines'
    drawing at that value (me581_drawing), mirrored for the crossed assembly."""
    pick = _mirrored if branch == "crossed" else (lambda t: t)
    m = from_text(pick(me581_drawing(driver=f"value = {value!r}")), "<drawing>")
    assert math.degrees(m.driver.value) == pytest.approx(value, abs=1e-12)
    assert m.drawing_note == (f"<drawing>: crank is drawn at 65 deg; solved at [driver] value = {value:g} "
                              "deg, on the drawing's branch")
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged
    from linkage.kinematics.rates import rates_at

    placed = rates_at(m, r.x).joints
    there = pick(me581_drawing(theta2=value - 360.0 * (value > 180.0)))
    want = from_text(there, "<drawing>").extra["drawing"].xy
    for name, xy in want.items():
        assert placed[name] == pytest.approx(xy, abs=1e-9), (name, branch)
    assert m.derivation.name_of(list(r.x), m.driver.value) == branch


def test_a_driver_value_the_drawn_assembly_does_not_reach_is_refused() -> None:
    """ME581's crank cannot reach 180 deg (a triple rocker): one line, never another assembly."""
    with pytest.raises(InputError, match=re.escape("driver.value: 180 deg is not reached from the drawing "
                                                   "(crank is drawn at 65 deg) on its branch")):
        from_text(me581_drawing(driver="value = 180"), "<drawing>")


def test_a_driver_value_left_out_is_the_drawn_angle() -> None:
    m = from_text(me581_drawing(theta2=59.9992722, driver="# value: the drawn angle"), "<drawing>")
    assert math.degrees(m.driver.value) == pytest.approx(59.9992722, abs=1e-12)
    assert m.drawing_note is None
    rounded = from_text(me581_drawing(theta2=65.0, driver=f"value = {65.0 + 4e-7!r}"), "<drawing>")
    assert rounded.drawing_note is None  # within the drawing's rounding: the drawn pose


def test_a_hand_drawn_driver_off_by_rounding_is_accepted_with_a_note(cli, tmp_path) -> None:
    """The newcomer's file: "60 deg, but crank is drawn at 59.9992722 deg" was an error;
    now a note after the output (exit 0), and the sweep keeps the drawing's assembly."""
    path = tmp_path / "hand.toml"
    for branch in ("open", "crossed"):
        text = me581_drawing(theta2=59.9992722, driver="value = 60")
        path.write_text(_mirrored(text) if branch == "crossed" else text)
        r = cli("solve", str(path), "-f", "plain")
        assert r.code == 0, r.err
        assert r.err == (f"note: {path}: crank is drawn at 59.9992722 deg; solved at [driver] value = "
                         "60 deg, on the drawing's branch\n")
        r = cli("sweep", str(path), "--from", "0", "--to", "100", "--step", "10", "-f", "csv")
        assert r.code == 0 and "drawn at 59.9992722" in r.err
        rows = [line.split(",") for line in r.out.splitlines()]
        k = rows[0].index("branch")
        assert {row[k] for row in rows[1:]} == {branch}


def test_a_driver_not_turning_about_the_ground_is_refused() -> None:
    text = me581_drawing().replace('link = "crank"', 'link = "coupler"')
    with pytest.raises(InputError, match="coupler must turn about a ground joint"):
        from_text(text, "<drawing>")


def watt_drawing() -> str:
    """The Watt six-bar sample drawn from its own joints at its driver value (30 deg): two
    loops, a ternary rocker (O4, B, C) and three fixed joints."""
    from linkage.kinematics.rates import rates_at

    m = load(SAMPLES / "watt_sixbar.toml")
    r = solve_system(m.problem(), tol=1e-14)
    xy = rates_at(m, r.x).joints
    joints = "\n".join(f"{k} = [{x!r}, {y!r}]" for k, (x, y) in xy.items())
    return (f'name = "Watt drawn"\nlength_unit = "mm"\nground = ["O2", "O4", "O6"]\n[joints]\n{joints}\n'
            '[links]\ncrank = ["O2", "A"]\ncoupler = ["A", "B"]\nrocker = ["O4", "B", "C"]\n'
            'link6 = ["C", "D"]\nlink7 = ["O6", "D"]\n[driver]\nlink = "crank"\nvalue = 30\n')


@pytest.mark.parametrize("theta2", [0.0, 45.0, 120.0, 250.0])
def test_a_six_bar_drawing_gives_its_vector_loop_twins_answers(theta2: float) -> None:
    drawing = from_text(watt_drawing(), "<drawing>")
    assert len(drawing.loops) == 2
    got = solve_system(drawing.with_values({"theta_crank": theta2}, {}).problem(), tol=1e-14)
    twin = load(SAMPLES / "watt_sixbar.toml").with_values({"theta2": theta2}, {})
    want = solve_system(twin.problem(), tol=1e-14)
    assert got.converged and want.converged
    diff = [((math.degrees(g - w) + 180) % 360) - 180 for g, w in zip(got.x, want.x)]
    assert diff == pytest.approx([0.0] * 4, abs=1e-12)


def test_a_drawing_off_its_value_converts_to_loops_on_the_drawn_assembly() -> None:
    """linkage convert of such a drawing: its loops' guesses are the drawing's branch at
    the value, so the loops file solves to the drawing's joints there too."""
    from linkage.files import parse_toml
    from linkage.kinematics.rates import rates_at
    from linkage.problems.toml_text import loops_text

    text = _mirrored(me581_drawing(driver="value = 100"))
    converted = loops_text(parse_toml(text, "<drawing>"), "<drawing>", from_text(text, "<drawing>"))
    assert "# crank is drawn at 65 deg; solved at [driver] value = 100 deg" in converted
    m = from_text(converted, "<loops>")
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged and m.derivation.name_of(list(r.x), m.driver.value) == "crossed"
    want = from_text(_mirrored(me581_drawing(theta2=100.0)), "<drawing>").extra["drawing"].xy
    placed = rates_at(m, r.x).joints
    for name in ("A", "B", "O4"):
        assert placed[name] == pytest.approx(want[name], abs=1e-9), name


def test_a_drawing_without_a_closed_form_off_its_value_keeps_the_drawn_assembly() -> None:
    """The rapier drive (no derived closed form) drawn at 60 deg with value = 200: solved
    from the drawing there, it is the position a sweep reaches from the drawing by
    continuation (kinematics.continuation), on the drawing's det J sign."""
    import linkage

    text = (SAMPLES / "rapier_drive_joints.toml").read_text()
    drawn = from_text(text, "<rapier>")
    assert not drawn.derivation.complete and math.degrees(drawn.driver.value) == pytest.approx(60.0)
    m = from_text(text.replace("\nvalue = 60 ", "\nvalue = 200 "), "<rapier>")
    assert m.drawing_note is not None and "drawn at 60 deg" in m.drawing_note
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged
    swept = linkage.sweep(drawn, [60.0 + 10.0 * k for k in range(15)]).positions[-1]
    assert swept.input == 200.0 and swept.status == "converged"
    got = {u.name: math.degrees(v) if u.kind == "angle" else v for u, v in zip(m.unknowns, r.x)}
    assert got == pytest.approx(swept.solution, abs=1e-8)

"""Sliders in the joints form (issue 21): a link sliding along a line fixed to the ground or
to a turning link, a slider as the driver, and a drawing placed where it was drawn (its
``origin``). References: the slider-crank's closed form derived here, and the vector-loop
samples solved by our solver."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from linkage import solve_system
from linkage.errors import InputError
from linkage.kinematics.loading import from_text, load
from linkage.kinematics.rates import rates_at
from linkage.problems.start import start_on_branch

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
R2, R3, E = 40.0, 120.0, 10.0
SHIFT = (1.25, -2.5)


def slider_crank(theta2: float, open_branch: bool = True) -> tuple[float, float]:
    """theta3 (rad) and the slider's x for crank r2 at theta2 (deg), coupler r3, the
    slider's line y = e: sin(theta3) = (e - r2 sin(theta2)) / r3."""
    t2 = math.radians(theta2)
    t3 = math.asin((E - R2 * math.sin(t2)) / R3)
    if not open_branch:
        t3 = math.pi - t3
    return t3, R2 * math.cos(t2) + R3 * math.cos(t3)


GROUND_LINE = 'block = { on = "ground", angle = 0 }'


def slider_crank_drawing(theta2: float = 45.0, driver: str = "", sliders: str = GROUND_LINE) -> str:
    t3, s = slider_crank(theta2)
    driver = driver or f'link = "crank"\nvalue = {theta2!r}'
    ox, oy = SHIFT
    ax, ay = ox + R2 * math.cos(math.radians(theta2)), oy + R2 * math.sin(math.radians(theta2))
    return (f'name = "slider-crank drawn"\nlength_unit = "mm"\nground = ["O2"]\n[joints]\n'
            f"O2 = [{ox!r}, {oy!r}]\nA = [{ax!r}, {ay!r}]\nB = [{ox + s!r}, {oy + E!r}]\n"
            f"P = [{ax + 50 * math.cos(t3 + 0.3)!r}, {ay + 50 * math.sin(t3 + 0.3)!r}]\n"
            '[links]\ncrank = ["O2", "A"]\ncoupler = ["A", "B", "P"]\nblock = ["B"]\n'
            f"[sliders]\n{sliders}\n[driver]\n{driver}\n")


def test_the_drawn_slider_crank_is_placed_where_it_was_drawn() -> None:
    text = slider_crank_drawing()
    m = from_text(text, "<drawing>")
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged
    placed = rates_at(m, r.x).joints
    drawn = {line.split(" = ")[0]: eval(line.split(" = ")[1])
             for line in text.split("[joints]\n")[1].split("[links]")[0].splitlines()}
    assert set(drawn) <= set(placed)
    for name, xy in drawn.items():
        assert placed[name] == pytest.approx(xy, abs=1e-9), name


@pytest.mark.parametrize("theta2", [0.0, 30.0, 90.0, 180.0, 250.0, 359.0])
@pytest.mark.parametrize("open_branch", [True, False])
def test_a_drawn_slider_crank_gives_the_closed_form(theta2: float, open_branch: bool) -> None:
    m = from_text(slider_crank_drawing(), "<drawing>").with_values({"theta_crank": theta2}, {})
    assert [u.name for u in m.unknowns] == ["theta_coupler", "s_block"]
    m = start_on_branch(m, "open" if open_branch else "crossed", False)
    r = solve_system(m.problem(), tol=1e-14)
    t3, s = slider_crank(theta2, open_branch)
    assert r.converged
    assert math.remainder(r.x[0] - t3, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)
    # the travel is measured from the foot of O2 on the line: the closed form's x
    assert r.x[1] == pytest.approx(s, rel=1e-12)


@pytest.mark.parametrize("s", [90.0, 120.0, 155.0])
def test_a_slider_can_drive(s: float) -> None:
    _, s0 = slider_crank(45.0)
    m = from_text(slider_crank_drawing(driver=f'slider = "block"\nvalue = {s0!r}'), "<drawing>")
    assert m.driver.name == "s_block" and m.driver.kind == "length"
    r = solve_system(m.with_values({"s_block": s}, {}).problem(), tol=1e-14)
    assert r.converged
    theta2, theta3 = r.x
    # the crank pin is r2 from O2 and r3 from B = (s, e): both circles, independently
    ax, ay = R2 * math.cos(theta2), R2 * math.sin(theta2)
    assert math.hypot(s - ax, E - ay) == pytest.approx(R3, rel=1e-12)
    assert (ax + R3 * math.cos(theta3), ay + R3 * math.sin(theta3)) == pytest.approx((s, E), abs=1e-11)


def rapier_drawing() -> tuple[str, dict[str, tuple[float, float]]]:
    """The rapier drive (worked example P5) drawn from its vector-loop sample at 60 deg, moved by SHIFT:
    link 4 carries B, C and D; the rapier slides along the ground's x direction carrying D
    and its tip E."""
    m = load(SAMPLES / "rapier_drive.toml")
    r = solve_system(m.problem(), tol=1e-14)
    xy = {k: (x + SHIFT[0], y + SHIFT[1]) for k, (x, y) in rates_at(m, r.x).joints.items() if k}
    joints = "\n".join(f"{k} = [{x!r}, {y!r}]" for k, (x, y) in xy.items())
    return (f'name = "rapier drawn"\nlength_unit = "mm"\nground = ["A0", "C0"]\n[joints]\n{joints}\n'
            '[links]\ncrank = ["A0", "A"]\ncoupler = ["A", "B"]\nlink4 = ["B", "C", "D"]\n'
            'rocker = ["C0", "C"]\nrapier = ["D", "E"]\n'
            '[sliders]\nrapier = { on = "ground", angle = 0 }\n'
            '[driver]\nlink = "crank"\nvalue = 60\n'), xy


@pytest.mark.parametrize("theta", [60.0, 0.0, 95.0, 200.0, 330.0])
def test_the_drawn_rapier_places_every_joint_as_its_twin(theta: float) -> None:
    text, drawn = rapier_drawing()
    m = from_text(text, "<drawing>").with_values({"theta_crank": theta}, {})
    twin = load(SAMPLES / "rapier_drive.toml").with_values({"theta12": theta}, {})
    got, want = solve_system(m.problem(), tol=1e-14), solve_system(twin.problem(), tol=1e-14)
    assert got.converged and want.converged
    placed, reference = rates_at(m, got.x).joints, rates_at(twin, want.x).joints
    for name in drawn:
        x, y = reference[name]
        assert placed[name] == pytest.approx((x + SHIFT[0], y + SHIFT[1]), abs=1e-9), name
    # the rapier's travel: D's x from A0's foot on its line; the twin's s16 is E's x
    assert got.x[3] == pytest.approx(want.x[3] - 1100.0, rel=1e-12)


def inverted_drawing() -> str:
    """The inverted slider-crank sample drawn at 60 deg (its comment's figures: theta4 =
    150 deg exactly, s = 50 sqrt(3)): the block on the crank pin A slides along the rocker,
    whose line runs parallel to O4 -> C (C a point on the rocker), offset by e = 10."""
    t4 = math.radians(150.0)
    ax, ay = 40 * math.cos(math.radians(60)), 40 * math.sin(math.radians(60))
    return ('name = "inverted drawn"\nlength_unit = "mm"\nground = ["O2", "O4"]\n[joints]\n'
            f"O2 = [0, 0]\nO4 = [100, 0]\nA = [{ax!r}, {ay!r}]\n"
            f"C = [{100 + 80 * math.cos(t4)!r}, {80 * math.sin(t4)!r}]\n"
            '[links]\ncrank = ["O2", "A"]\nrocker = ["O4", "C"]\nblock = ["A"]\n'
            '[sliders]\nblock = { on = "rocker", line = ["O4", "C"] }\n'
            '[driver]\nlink = "crank"\nvalue = 60\n')


@pytest.mark.parametrize("theta", [60.0, 0.0, 130.0, 240.0])
@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_a_slider_on_a_turning_link_gives_its_twins_answers(theta: float, branch: str) -> None:
    m = from_text(inverted_drawing(), "<drawing>")
    assert [u.name for u in m.unknowns] == ["theta_rocker", "s_block"]
    assert m.parameters["e_block"].value == pytest.approx(10.0, abs=1e-12)
    twin = load(SAMPLES / "inverted_slider_crank.toml")
    # the branches are the sign of s: the twin's other branch is its guess's mirror
    sign = 1 if branch == "open" else -1
    got = solve_system(m.with_values({"theta_crank": theta}, {"s_block": sign * 80.0,
                                                               "theta_rocker": 150.0 if sign > 0 else -20.0}
                                     ).problem(), tol=1e-14)
    want = solve_system(twin.with_values({"theta2": theta}, {"s": sign * 80.0,
                                                            "theta4": 150.0 if sign > 0 else -20.0}
                                         ).problem(), tol=1e-14)
    assert got.converged and want.converged
    assert got.x[1] == pytest.approx(want.x[0], rel=1e-12)
    assert math.remainder(got.x[0] - want.x[1], 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(("sliders", "message"), [
    ('block = { on = "ground" }', "sliders.block: a slider needs its line: angle = DEG"),
    ('block = { on = "ground", angle = 0, line = ["O2", "O2"] }', "a slider needs its line"),
    ('block = { on = "block", angle = 0 }', "sliders.block.on: must name the body its line is fixed to"),
    ('block = { on = "coupler", angle = 0 }', "its first joint B is on coupler too"),
    ('block = { on = "ground", line = ["O2", "A"] }', "sliders.block.line: must be two joints of ground"),
    ('block = { on = "ground", angle = 0, speed = 3 }', "sliders.block.speed: unknown key"),
    ('crank = { on = "ground", angle = 0 }', "links.block: must list at least two joints"),
])
def test_a_slider_that_cannot_be_is_refused(sliders: str, message: str) -> None:
    with pytest.raises(InputError, match=re.escape(message)):
        from_text(slider_crank_drawing(sliders=sliders), "<drawing>")


def test_a_drawing_driven_by_a_sliding_link_or_an_unreachable_travel_is_refused() -> None:
    with pytest.raises(InputError, match=re.escape('block slides: drive it by its travel, [driver] slider')):
        from_text(slider_crank_drawing(driver='link = "block"'), "<drawing>")
    with pytest.raises(InputError, match=re.escape("driver.value: 1000 mm is not reached from the drawing "
                                                   "(block is drawn at travel 146.883114 mm)")):
        from_text(slider_crank_drawing(driver='slider = "block"\nvalue = 1000'), "<drawing>")
    # a travel the drawing's branch reaches: solved there (a driver value off the drawing is accepted)
    m = from_text(slider_crank_drawing(driver='slider = "block"\nvalue = 140'), "<drawing>")
    assert m.driver.value == 140.0 and "block is drawn at travel 146.883114 mm" in m.drawing_note
    assert solve_system(m.problem(), tol=1e-14).converged
    with pytest.raises(InputError, match=re.escape("driver: name one: link = NAME")):
        from_text(slider_crank_drawing(driver='slider = "block"\nlink = "crank"'), "<drawing>")

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
from linkage.problems.loops import from_text, load
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


def test_a_driver_value_that_is_not_the_drawing_is_refused() -> None:
    with pytest.raises(InputError, match=re.escape("driver.value: 70 deg, but crank is drawn at 65")):
        from_text(me581_drawing(driver="value = 70"), "<drawing>")


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

"""The joints-form samples (issue 21, done-when 1): each solves at its drawn driver value to
its drawn coordinates, gives its vector-loop twin's answers (the twin file solved by our
solver) at other driver values on every assembly branch, and the commands run on it.

Independent references written here: the ME581 four-bar by the law of cosines and the
inverted slider-crank's closed form in 50-digit mpmath, and the offset slider-crank's
closed form sin(theta3) = (e - r2 sin(theta2)) / r3.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

import mpmath
import pytest
import tomllib

from linkage import solve_system
from linkage.kinematics.loading import load
from linkage.kinematics.rates import rates_at
from linkage.problems.derive import sign_text
from linkage.problems.loops import Mechanism
from linkage.problems.start import start_on_branch

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
EPS = sys.float_info.epsilon
FULL_TURN = (0.0, 90.0, 180.0, 270.0, 359.999999)
ME581_LIMIT = math.degrees(math.acos(-0.375))
"""Where the ME581 crank stops: |O4 - A| = r3 + r4, cos(theta2) = (r1^2 + r2^2 - (r3 + r4)^2)
/ (2 r1 r2) = -3/8 (about 112.0243 deg)."""


@dataclass(frozen=True)
class Twin:
    twin: str
    names: dict[str, str]
    """The twin's unknown -> the drawing's derived unknown."""
    values: tuple[float, ...]
    """Driver values (deg) at which both are compared, the drawn one first."""
    shift: tuple[str, float] | None = None
    """A twin unknown that is the drawing's plus a constant (the rapier's tip, 1100 mm ahead of D)."""


JOINT_SAMPLES = {
    "fourbar_me581_joints.toml": Twin(
        "fourbar_me581.toml", {"theta3": "theta_coupler", "theta4": "theta_rocker"},
        (65.0, 0.0, 40.0, 100.0, 250.0, ME581_LIMIT - 1e-6, 1e-6 - ME581_LIMIT)),
    "crank_rocker_joints.toml": Twin(
        "crank_rocker.toml", {"theta3": "theta_coupler", "theta4": "theta_rocker"}, (30.0, *FULL_TURN)),
    "slider_crank_joints.toml": Twin(
        "slider_crank.toml", {"theta3": "theta_coupler", "s": "s_block"}, (45.0, *FULL_TURN)),
    "inverted_slider_joints.toml": Twin(
        "inverted_slider_crank.toml", {"s": "s_block", "theta4": "theta_rocker"}, (60.0, *FULL_TURN)),
    "watt_sixbar_joints.toml": Twin(
        "watt_sixbar.toml", {"theta3": "theta_coupler", "theta4": "theta_rocker", "theta6": "theta_link6",
                             "theta7": "theta_link7"}, (30.0, *FULL_TURN)),
    "stephenson_sixbar_joints.toml": Twin(
        "stephenson_sixbar.toml", {"theta3": "theta_coupler", "theta4": "theta_rocker",
                                   "theta5": "theta_link5", "theta6": "theta_link6"}, (30.0, *FULL_TURN)),
    "rapier_drive_joints.toml": Twin(
        "rapier_drive.toml", {"theta13": "theta_coupler", "theta14": "theta_link4", "theta15": "theta_rocker",
                              "s16": "s_rapier"}, (60.0, 0.0, 90.0, 180.0, 270.0, 359.0), ("s16", 1100.0)),
}
NEAR_LIMIT = {ME581_LIMIT - 1e-6, 1e-6 - ME581_LIMIT}


def test_every_joints_sample_is_listed_here() -> None:
    assert sorted(p.name for p in SAMPLES.glob("*_joints.toml")) == sorted(JOINT_SAMPLES)


def solved(m: Mechanism) -> dict[str, float]:
    """The mechanism solved from its own guess: unknown -> value (deg or length)."""
    return solved_and_placed(m)[0]


def solved_and_placed(m: Mechanism) -> tuple[dict[str, float], dict[str, tuple[float, float]]]:
    """... and its named joints' places."""
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged, r.message
    joints = {k: v for k, v in rates_at(m, r.x).joints.items() if k}
    return dict(zip([u.name for u in m.unknowns], m.problem().to_display(r.x))), joints


Places = dict[str, tuple[float, float]]


def same_places(got: Places, want: Places, bound: float) -> None:
    """The joints both name (the twin names no coupler point a drawing adds to give a line,
    the drawing no slider's foot) in the same places, within ``bound`` (length unit)."""
    shared = set(got) & set(want)
    assert len(shared) >= 3
    for j in shared:
        assert math.dist(got[j], want[j]) <= bound, (j, got[j], want[j])


def conditioning(m: Mechanism, answer: dict[str, float]) -> float:
    """What double precision determines of the answer (deg or length): a residual of 4
    rounding errors of the mechanism's size, through the inverse Jacobian (|J^-1|_inf, by
    Gauss-Jordan here). 1e-6 deg from the ME581's limit it is 7e-10 deg (6e-12 of theta4):
    there 1e-12 is more than double precision holds (measured: 3e-11 deg between the
    drawing and its twin, 4e-12 deg from the 50-digit law of cosines)."""
    p = m.problem()
    q = [math.radians(answer[u.name]) if u.kind == "angle" else answer[u.name] for u in m.unknowns]
    n = len(q)
    a = [list(map(float, row)) + [float(i == j) for j in range(n)] for i, row in enumerate(p.J(q))]
    for c in range(n):
        k = max(range(c, n), key=lambda r: abs(a[r][c]))
        a[c], a[k] = a[k], a[c]
        a[c] = [v / a[c][c] for v in a[c]]
        for r in range(n):
            if r != c:
                a[r] = [v - a[r][c] * w for v, w in zip(a[r], a[c])]
    inverse = max(sum(abs(v) for v in row[n:]) for row in a)
    return 4 * EPS * m.length_scale * inverse * 180.0 / math.pi


def close(got: float, want: float, kind: str, slack: float = 0.0) -> bool:
    """To 1e-12 relative (of 1 deg or 1 length unit at least), angles modulo a turn."""
    diff = math.remainder(got - want, 360.0) if kind == "angle" else got - want
    return abs(diff) <= max(1e-12 * max(abs(want), 1.0), slack)


# --- (1) the drawn pose --------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(JOINT_SAMPLES))
def test_the_drawn_driver_value_gives_the_drawn_coordinates(name: str) -> None:
    path = SAMPLES / name
    drawn = tomllib.loads(path.read_text())["joints"]
    m = load(path)
    assert m.driver.value * 180.0 / math.pi == pytest.approx(JOINT_SAMPLES[name].values[0], abs=1e-12)
    r = solve_system(m.problem(), tol=1e-14)
    assert r.converged
    placed = rates_at(m, r.x).joints
    assert set(drawn) <= set(placed)
    for joint, (x, y) in drawn.items():
        px, py = placed[joint]
        assert max(abs(px - x), abs(py - y)) <= 1e-9, (name, joint, (px, py), (x, y))


# --- (2) the vector-loop twin, every branch ------------------------------------------------

def branch_starts(twin: Mechanism, value: float) -> list[str]:
    """The twin's assemblies at ``value`` as sign strings (one sign per two-way closed-form
    step): the drawing is started on the same signs, whatever each names them."""
    at = twin.with_values({twin.driver.name: value}, {})
    return [sign_text(at.derivation.branch_signs(b, at.driver.value)) for b in at.problem().reference()]


CLOSED_FORM_CASES = [(name, v, signs)
                     for name, t in sorted(JOINT_SAMPLES.items()) if t.shift is None
                     for v in t.values
                     for signs in branch_starts(load(SAMPLES / t.twin), v)]


@pytest.mark.parametrize(("name", "value", "signs"), CLOSED_FORM_CASES,
                         ids=[f"{n.removesuffix('_joints.toml')}-{v:g}-{s}" for n, v, s in CLOSED_FORM_CASES])
def test_each_branch_gives_the_vector_loop_twins_answers(name: str, value: float, signs: str) -> None:
    spec = JOINT_SAMPLES[name]
    twin = load(SAMPLES / spec.twin)
    drawing = load(SAMPLES / name)
    want, at = solved_and_placed(start_on_branch(twin.with_values({twin.driver.name: value}, {}),
                                                 signs, False))
    got, placed = solved_and_placed(start_on_branch(drawing.with_values({drawing.driver.name: value}, {}),
                                                    signs, False))
    same_places(placed, at, 1e-9)
    assert sorted(got) == sorted(spec.names.values())
    kinds = {u.name: u.kind for u in drawing.unknowns}
    slack = conditioning(drawing, got) if value in NEAR_LIMIT else 0.0
    for t, d in spec.names.items():
        assert close(got[d], want[t], kinds[d], slack), (name, value, signs, d, got[d], want[t], slack)


def follow(m: Mechanism, guess: dict[str, float], start: float, target: float
           ) -> tuple[dict[str, float], dict[str, tuple[float, float]]]:
    """The assembly through ``guess`` at ``start``, followed in steps of at most 5 deg to
    ``target`` (no closed form to name it), and its joints there."""
    steps = max(1, math.ceil(abs(target - start) / 5.0))
    q, placed = guess, {}
    for k in range(1, steps + 1):
        q, placed = solved_and_placed(m.with_values({m.driver.name: start + (target - start) * k / steps}, q))
    return q, placed


RAPIER = JOINT_SAMPLES["rapier_drive_joints.toml"]
# P5's assembly (the book's guess) and a second one found from (218, 359, 198 deg, -343.5 mm)
RAPIER_BRANCHES = [{"theta13": 200.0, "theta14": 80.0, "theta15": 180.0, "s16": 400.0},
                   {"theta13": 218.0, "theta14": 359.0, "theta15": 198.0, "s16": -343.5}]


@pytest.mark.parametrize("value", RAPIER.values)
@pytest.mark.parametrize("branch", [0, 1])
def test_the_rapier_follows_its_twin_on_two_assemblies(value: float, branch: int) -> None:
    twin, drawing = load(SAMPLES / RAPIER.twin), load(SAMPLES / "rapier_drive_joints.toml")
    guess = RAPIER_BRANCHES[branch]
    assert RAPIER.shift is not None
    shifted, ahead = RAPIER.shift
    want, at = follow(twin, guess, 60.0, value)
    mapped = {RAPIER.names[t]: v - (ahead if t == shifted else 0.0) for t, v in guess.items()}
    got, placed = follow(drawing, mapped, 60.0, value)
    assert set(placed) == set(at) == {"A0", "A", "B", "C", "C0", "D", "E"}
    same_places(placed, at, 1e-9)
    kinds = {u.name: u.kind for u in drawing.unknowns}
    for t, d in RAPIER.names.items():
        assert close(got[d] + (ahead if t == shifted else 0.0), want[t], kinds[d]), (value, branch, d)
    if branch == 0 and value == 60.0:  # P5's answer
        assert [want[t] for t in RAPIER.names] == pytest.approx([188.572556, 67.394934, 175.143712,
                                                                 -216.940343], abs=1e-6)


# --- independent closed forms --------------------------------------------------------------

mpmath.mp.dps = 50


def me581_law_of_cosines(theta2: float, branch: str) -> tuple[float, float]:
    """theta3, theta4 (deg) of r1..r4 = 90, 30, 60, 45: B where the circles about A (r3) and
    O4 (r4) meet, on the left of A -> O4 for the open branch."""
    t2 = mpmath.radians(mpmath.mpf(theta2))
    a = mpmath.mpc(30 * mpmath.cos(t2), 30 * mpmath.sin(t2))
    d = abs(90 - a)
    x = (60 ** 2 - 45 ** 2 + d * d) / (2 * d)
    h = mpmath.sqrt(60 ** 2 - x * x) * (1 if branch == "open" else -1)
    b = a + (90 - a) / d * mpmath.mpc(x, h)
    return float(mpmath.degrees(mpmath.arg(b - a))), float(mpmath.degrees(mpmath.arg(b - 90)))


@pytest.mark.parametrize("theta2", JOINT_SAMPLES["fourbar_me581_joints.toml"].values)
@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_the_me581_drawing_gives_the_law_of_cosines(theta2: float, branch: str) -> None:
    m = load(SAMPLES / "fourbar_me581_joints.toml").with_values({"theta_crank": theta2}, {})
    got = solved(start_on_branch(m, branch, False))
    slack = conditioning(m, got) if theta2 in NEAR_LIMIT else 0.0
    t3, t4 = me581_law_of_cosines(theta2, branch)
    if theta2 in NEAR_LIMIT:  # the bound is needed there: 1e-12 is more than doubles hold
        assert slack > 1e-12 * max(abs(t3), abs(t4))
    assert close(got["theta_coupler"], t3, "angle", slack), (got, t3, slack)
    assert close(got["theta_rocker"], t4, "angle", slack), (got, t4, slack)


@pytest.mark.parametrize("theta2", JOINT_SAMPLES["slider_crank_joints.toml"].values)
@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_the_slider_crank_drawing_gives_its_closed_form(theta2: float, branch: str) -> None:
    r2, r3, e = 40.0, 120.0, 10.0
    t2 = math.radians(theta2)
    t3 = math.asin((e - r2 * math.sin(t2)) / r3)
    if branch == "crossed":
        t3 = math.pi - t3
    s = r2 * math.cos(t2) + r3 * math.cos(t3)
    m = load(SAMPLES / "slider_crank_joints.toml").with_values({"theta_crank": theta2}, {})
    assert m.parameters["e_block"].value == pytest.approx(e, abs=1e-12)
    got = solved(start_on_branch(m, branch, False))
    assert close(got["theta_coupler"], math.degrees(t3), "angle"), (got, math.degrees(t3))
    assert close(got["s_block"], s, "length"), (got, s)


@pytest.mark.parametrize("theta2", JOINT_SAMPLES["inverted_slider_joints.toml"].values)
@pytest.mark.parametrize("sign", [1, -1])
def test_the_inverted_slider_drawing_gives_its_closed_form(theta2: float, sign: int) -> None:
    """A - O4 = (s + i e) e^(i theta4): s = +-sqrt(|A - O4|^2 - e^2), theta4 = arg(A - O4)
    - atan2(e, s), with crank 40, O2O4 = 100, e = 10 mm."""
    t2 = mpmath.radians(mpmath.mpf(theta2))
    d = mpmath.mpc(40 * mpmath.cos(t2) - 100, 40 * mpmath.sin(t2))
    s = sign * mpmath.sqrt(abs(d) ** 2 - 100)
    t4 = mpmath.degrees(mpmath.arg(d) - mpmath.atan2(10, s))
    m = load(SAMPLES / "inverted_slider_joints.toml").with_values({"theta_crank": theta2}, {})
    got = solved(start_on_branch(m, "+" if sign > 0 else "-", False))
    assert close(got["s_block"], float(s), "length"), (got, s)
    assert close(got["theta_rocker"], float(t4), "angle"), (got, t4)


# --- (3) the commands ----------------------------------------------------------------------

@pytest.mark.parametrize("name", sorted(JOINT_SAMPLES))
def test_solve_sweep_and_draw_run_on_each_sample(cli, tmp_path, name: str) -> None:
    path = str(SAMPLES / name)
    for args in (["solve", path], ["sweep", path], ["draw", path, "-o", str(tmp_path / "x.png")]):
        run = cli(*args)
        assert run.code == 0, (args, run.err)
    assert (tmp_path / "x.png").stat().st_size > 1000


def test_the_mechanisms_page_shows_the_sample_beside_its_drawing() -> None:
    """docs/mechanisms.md leads with the four-bar's file beside its picture: that file is the
    sample's (its comments and description aside)."""
    readme = (SAMPLES.parent / "docs" / "mechanisms.md").read_text()
    cell = readme.split('<td width="50%"><img src="fourbar_me581_joints.png"', 1)[1]
    shown = tomllib.loads(cell.split("```toml\n", 1)[1].split("```", 1)[0])
    sample = tomllib.loads((SAMPLES / "fourbar_me581_joints.toml").read_text())
    sample.pop("description")
    assert shown == sample
    assert "linkage draw sample_inputs/fourbar_me581_joints.toml -o docs/fourbar_me581_joints.png" in readme
    assert (SAMPLES.parent / "docs" / "fourbar_me581_joints.png").stat().st_size > 1000

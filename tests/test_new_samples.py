"""The three samples of issue 19 (an inverted slider-crank, a four-bar in Norton's names, a
Stephenson III six-bar): each loads, solves and sweeps to the figures in its header comment.

The reference is written here, independently of linkage's code: circle intersections in
50-digit mpmath, confirmed as roots of the loop equations by mpmath.findroot.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import mpmath
import pytest

import linkage
from linkage.kinematics.loading import load

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
INVERTED = SAMPLES / "inverted_slider_crank.toml"
ABCD = SAMPLES / "fourbar_abcd.toml"
STEPHENSON = SAMPLES / "stephenson_sixbar.toml"

DIGITS = 50


def cis(deg: mpmath.mpf) -> mpmath.mpc:
    """e^(i deg): cospi and sinpi keep multiples of 30 deg exact."""
    x = mpmath.mpf(deg) / 180
    return mpmath.mpc(mpmath.cospi(x), mpmath.sinpi(x))


def expj(t: mpmath.mpf) -> mpmath.mpc:
    """e^(i t), t in radians."""
    return mpmath.mpc(mpmath.cos(t), mpmath.sin(t))


def arg_deg(z: mpmath.mpc) -> mpmath.mpf:
    """The angle of z in degrees, in (-180, 180]."""
    return mpmath.atan2(z.imag, z.real) / (mpmath.pi / 180)


def circles(p: mpmath.mpc, rp: float, q: mpmath.mpc, rq: float, sigma: int) -> mpmath.mpc | None:
    """The point at distance rp from p and rq from q, left of p -> q for sigma = +1 and
    right for -1 (law of cosines along pq, the half chord across); None if none."""
    d = q - p
    dist = abs(d)
    along = (mpmath.mpf(rp) ** 2 - mpmath.mpf(rq) ** 2 + dist**2) / (2 * dist)
    h2 = mpmath.mpf(rp) ** 2 - along**2
    if h2 < 0:
        return None
    return p + (along + sigma * 1j * mpmath.sqrt(h2)) * d / dist


# ---- inverted slider-crank: A = r2 e^(i t2), O4 = r1 e^(i t1), A - O4 = (s + i e) e^(i t4)
INV = {"r1": 100, "r2": 40, "e": 10, "theta1": 0}


def inverted(theta2: float, sigma: int) -> dict[str, mpmath.mpf]:
    """sigma = +1: s > 0 (link 4 points from O4 toward A), -1: s < 0."""
    a = INV["r2"] * cis(theta2)
    o4 = INV["r1"] * cis(INV["theta1"])
    d = a - o4
    s = sigma * mpmath.sqrt(abs(d) ** 2 - mpmath.mpf(INV["e"]) ** 2)
    return {"s": s, "theta4": arg_deg(d) - mpmath.atan2(INV["e"], s) / (mpmath.pi / 180)}


def inverted_loops(theta2: float) -> Callable[..., list]:
    def f(s, t4):
        z = (INV["r2"] * cis(theta2) - s * expj(t4) - INV["e"] * expj(t4 + mpmath.pi / 2)
             - INV["r1"] * cis(INV["theta1"]))
        return [z.real, z.imag]
    return f


# ---- four-bar, Norton's names: a crank, b coupler, c rocker, d ground
NORTON = {"a": 40, "b": 120, "c": 80, "d": 100, "theta1": 0}


def fourbar(theta2: float, sigma: int, a: float, b: float, c: float, d: float,
            theta1: float = 0) -> dict[str, mpmath.mpf] | None:
    """sigma = +1: B left of A -> O4 (open), -1: right (crossed)."""
    pa = a * cis(theta2)
    o4 = d * cis(theta1)
    pb = circles(pa, b, o4, c, sigma)
    if pb is None:
        return None
    return {"theta3": arg_deg(pb - pa), "theta4": arg_deg(pb - o4)}


def fourbar_loops(theta2: float, a: float, b: float, c: float, d: float,
                  theta1: float = 0) -> Callable[..., list]:
    def f(t3, t4):
        z = a * cis(theta2) + b * expj(t3) - c * expj(t4) - d * cis(theta1)
        return [z.real, z.imag]
    return f


# ---- Stephenson III: the crank-rocker above, its coupler carries C (r5 at theta3 + delta);
# dyad C -D (r6 at theta5) - O6 (r7 at theta6 from O6), O6 = g e^(i gamma)
STEPH = {"r1": 100, "r2": 40, "r3": 120, "r4": 80, "r5": 60, "delta": 30, "r6": 100, "r7": 90,
         "g": 160, "gamma": 110}


def stephenson(theta2: float, sigma1: int, sigma2: int) -> dict[str, mpmath.mpf] | None:
    """sigma1: the four-bar's branch (+1 open); sigma2: D left (+1) or right of C -> O6."""
    k = STEPH
    first = fourbar(theta2, sigma1, k["r2"], k["r3"], k["r4"], k["r1"])
    if first is None:
        return None
    c = k["r2"] * cis(theta2) + k["r5"] * cis(first["theta3"] + k["delta"])
    o6 = k["g"] * cis(k["gamma"])
    pd = circles(c, k["r6"], o6, k["r7"], sigma2)
    if pd is None:
        return None
    return {**first, "theta5": arg_deg(pd - c), "theta6": arg_deg(pd - o6)}


def stephenson_loops(theta2: float) -> Callable[..., list]:
    k = STEPH

    def f(t3, t4, t5, t6):
        one = k["r2"] * cis(theta2) + k["r3"] * expj(t3) - k["r4"] * expj(t4) - k["r1"]
        two = (k["r2"] * cis(theta2) + k["r5"] * expj(t3 + k["delta"] * mpmath.pi / 180) + k["r6"] * expj(t5)
               - k["r7"] * expj(t6) - k["g"] * cis(k["gamma"]))
        return [one.real, one.imag, two.real, two.imag]
    return f


# ---- the samples: their reference, their loop equations and the figures in their headers
CASES = {
    "inverted_slider_crank": (INVERTED, 60, inverted, inverted_loops, (1, -1)),
    "fourbar_abcd": (ABCD, 40, lambda t, sg: fourbar(t, sg, **NORTON), lambda t: fourbar_loops(t, **NORTON),
                     (1, -1)),
    "stephenson_sixbar": (STEPHENSON, 30, lambda t, sg: stephenson(t, 1, sg), stephenson_loops, (-1, 1)),
}
"""name -> (file, driver value, reference(theta2, sigma), loop equations(theta2), (the guess's
sigma, the other))."""

HEADER = {  # exactly as printed in each file's header comment
    "inverted_slider_crank": ({"s": "86.603", "theta4": "150.000"}, {"s": "-86.603", "theta4": "-16.826"}),
    "fourbar_abcd": ({"theta3": "20.298", "theta4": "57.325"}, {"theta3": "-60.978", "theta4": "-98.005"}),
    "stephenson_sixbar": (
        {"theta3": "22.409", "theta4": "55.268", "theta5": "111.441", "theta6": "6.554"},
        {"theta3": "22.409", "theta4": "55.268", "theta5": "-178.081", "theta6": "-73.194"},
    ),
}


def wrapped(a: float, b: float) -> float:
    """|a - b| for angles in degrees, modulo 360."""
    return abs((a - b + 180.0) % 360.0 - 180.0)


def close(name: str, got: float, want: float) -> float:
    return abs(got - want) if name == "s" else wrapped(got, want)


@pytest.fixture(autouse=True)
def fifty_digits():
    with mpmath.workdps(DIGITS):
        yield


@pytest.mark.parametrize("name", sorted(CASES))
def test_header_figures_are_the_closed_form_to_the_printed_decimals(name):
    path, t2, ref, _, (mine, other) = CASES[name]
    for sigma, figures in zip((mine, other), HEADER[name]):
        exact = ref(t2, sigma)
        assert exact is not None and set(exact) == set(figures)
        for key, text in figures.items():
            assert mpmath.nstr(exact[key], 3 + len(text.split(".")[0].lstrip("-")), strip_zeros=False) == \
                   text, (name, sigma, key)
    # the figures are written in the header as printed
    head = path.read_text().split("\nname = ")[0]
    for figures in HEADER[name]:
        for text in figures.values():
            assert text in head


@pytest.mark.parametrize("name", sorted(CASES))
def test_closed_form_is_a_root_of_the_loop_equations(name):
    _path, t2, ref, loops, branches = CASES[name]
    for sigma in branches:
        exact = ref(t2, sigma)
        q = [exact[k] if k == "s" else exact[k] * mpmath.pi / 180 for k in exact]
        assert max(abs(v) for v in loops(t2)(*q)) < mpmath.mpf(10) ** -45
        # Newton in 50 digits from the figures rounded to 3 decimals lands on the same root
        start = [mpmath.mpf(mpmath.nstr(v, 6)) for v in q]
        root = mpmath.findroot(loops(t2), start, tol=mpmath.mpf(10) ** -60)
        assert max(abs(a - b) for a, b in zip(root, q)) < mpmath.mpf(10) ** -30


def printed(value: mpmath.mpf, text: str) -> bool:
    """value rounds to text (3 decimals)."""
    return abs(value - mpmath.mpf(text)) <= mpmath.mpf("0.0005")


def o6c(theta2: float, sigma1: int) -> mpmath.mpf:
    k = STEPH
    first = fourbar(theta2, sigma1, k["r2"], k["r3"], k["r4"], k["r1"])
    c = k["r2"] * cis(theta2) + k["r5"] * cis(first["theta3"] + k["delta"])
    return abs(c - k["g"] * cis(k["gamma"]))


def test_the_stephenson_header_claims():
    # crossed four-bar at 30 deg: C out of the dyad's reach, loop 2 does not close
    crossed = fourbar(30, -1, **NORTON)
    assert printed(crossed["theta3"], "-56.437") and printed(crossed["theta4"], "-89.296")
    assert printed(o6c(30, -1), "212.471") and o6c(30, -1) > STEPH["r6"] + STEPH["r7"]
    assert stephenson(30, -1, 1) is None and stephenson(30, -1, -1) is None
    # open branch, every degree: |O6C| between about 95 and 154 mm, inside 10 .. 190
    with mpmath.workdps(20):
        reach = [o6c(t, 1) for t in range(360)]
    assert 94.5 < min(reach) < 95.5 and 153.5 < max(reach) < 154.5
    assert abs(STEPH["r6"] - STEPH["r7"]) < min(reach) and max(reach) < STEPH["r6"] + STEPH["r7"]
    for text in ("-56.437", "-89.296", "212.471", "about 95 and 154 mm", "10 .. 190"):
        assert text in STEPHENSON.read_text().split("\nname = ")[0]


def test_the_inverted_slider_header_claims():
    exact = inverted(60, 1)
    assert abs(exact["s"] - 50 * mpmath.sqrt(3)) < mpmath.mpf(10) ** -45
    assert abs(exact["theta4"] - 150) < mpmath.mpf(10) ** -45
    line = arg_deg(INV["r2"] * cis(60) - INV["r1"])
    assert printed(line, "156.587")
    assert abs(line - mpmath.atan2(INV["e"], exact["s"]) * 180 / mpmath.pi - 150) < mpmath.mpf(10) ** -45
    head = INVERTED.read_text().split("\nname = ")[0]
    assert "156.587" in head and "50 sqrt(3)" in head


@pytest.mark.parametrize("name", sorted(CASES))
def test_file_loads_and_solve_converges_to_the_closed_form(cli, name):
    path, t2, ref, _, (mine, _other) = CASES[name]
    m = load(path)
    exact = ref(t2, mine)
    assert m.closed_form is None and m.driver.name == "theta2"
    assert sorted(u.name for u in m.unknowns) == sorted(exact)
    run = cli("solve", str(path), "--format", "json")
    assert run.code == 0, run.err
    doc = json.loads(run.out)
    assert doc["converged"] is True
    for key, value in exact.items():
        assert close(key, doc["solution"][key], float(value)) < 1e-9, (key, doc["solution"][key])


@pytest.mark.parametrize("name", sorted(CASES))
def test_a_full_turn_converges_everywhere_on_the_branch_of_the_guess(name):
    path, _, ref, _, (mine, _other) = CASES[name]
    values = list(range(0, 361, 10))
    result = linkage.sweep(str(path), values)
    assert len(result.positions) == len(values)
    worst = 0.0
    for p, t2 in zip(result.positions, values):
        assert p.status == "converged", (t2, p.status)
        exact = ref(t2, mine)
        assert exact is not None
        for key, value in exact.items():
            worst = max(worst, close(key, p.solution[key], float(value)))
    assert worst < 1e-9

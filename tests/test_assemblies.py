"""Every assembly by homotopy continuation (linkage assemblies), against references derived
here independently: the law of cosines at 50 digits for four-bars, the closed form derived
from the loops for every sample that has one, and one-dimensional scans refined at 50
digits for the two samples whose loops are coupled (the rapier drive, the offset slider)."""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import mpmath
import numpy as np
import pytest

import linkage
from linkage.homotopy import PolySystem, solve
from linkage.kinematics.loading import from_text, load

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
mpmath.mp.dps = 50


def _angles_equal(a: float, b: float, tol: float = 1e-9) -> bool:
    return abs(math.remainder(a - b, 2 * math.pi)) <= tol


def _same_set(found: list[tuple[float, ...]], want: list[tuple[float, ...]], kinds: list[str],
              size: float, tol: float = 1e-9) -> bool:
    if len(found) != len(want):
        return False
    left = list(want)
    for q in found:
        for w in left:
            if all(_angles_equal(a, b, tol) if k == "angle" else abs(a - b) <= tol * size
                   for a, b, k in zip(q, w, kinds)):
                left.remove(w)
                break
        else:
            return False
    return True


# --- the polynomial engine on systems whose roots are known -------------------------------

def test_the_engine_finds_every_root_of_a_system_with_roots_of_unity():
    """y = x^2, x = y^2: (0, 0), (1, 1) and the two complex cube roots of unity."""
    sols = solve(PolySystem(2, ({(2, 0): 1, (0, 1): -1}, {(0, 2): 1, (1, 0): -1})))
    roots = sorted((complex(e.x[0]) for e in sols.endpoints), key=lambda z: (z.real, z.imag))
    want = sorted([0, 1, complex(-0.5, math.sqrt(3) / 2), complex(-0.5, -math.sqrt(3) / 2)],
                  key=lambda z: (z.real, z.imag))
    assert [e.kind for e in sols.endpoints] == ["finite"] * 4
    assert all(abs(a - b) < 1e-14 for a, b in zip(roots, want))


def test_a_path_to_infinity_is_classified_not_dropped():
    """x y = 1, x = 2: Bezout's bound 2, one finite root (2, 1/2), one path to infinity."""
    sols = solve(PolySystem(2, ({(1, 1): 1, (0, 0): -1}, {(1, 0): 1, (0, 0): -2})))
    assert sorted(e.kind for e in sols.endpoints) == ["finite", "infinite"]
    (x,) = [e.x for e in sols.endpoints if e.kind == "finite"]
    assert abs(x[0] - 2) < 1e-15 and abs(x[1] - 0.5) < 1e-15


def test_a_triple_root_is_singular_with_its_cycle_numbers():
    """(x - 1)^3 from x^3 - 1: x = 1 solves every system of the homotopy (cycle 1), and the
    other two paths meet it as a square root (cycle 2). All three are singular, none is
    reported as a clean root, and no estimate is far from 1."""
    sols = solve(PolySystem(1, ({(3,): 1, (2,): -3, (1,): 3, (0,): -1},)))
    assert [e.kind for e in sols.endpoints] == ["singular"] * 3
    assert sorted(e.cycle for e in sols.endpoints) == [1, 2, 2]
    assert all(abs(e.x[0] - 1) < 1e-5 for e in sols.endpoints)


# --- mechanisms ---------------------------------------------------------------------------

CLOSED = ["fourbar_me581.toml", "fourbar_me581_theta4.toml", "crank_rocker.toml", "fourbar_abcd.toml",
          "slider_crank.toml", "inverted_slider_crank.toml", "watt_sixbar.toml", "stephenson_sixbar.toml",
          "crank_rocker_joints.toml", "slider_crank_joints.toml", "inverted_slider_joints.toml",
          "watt_sixbar_joints.toml", "stephenson_sixbar_joints.toml", "fourbar_me581_joints.toml"]


@pytest.mark.parametrize("name", CLOSED)
def test_every_assembly_of_a_closed_form_sample_is_its_closed_forms(name):
    """At the file's driver value and three others, the real assemblies are the closed
    form's (Derivation.solutions, every sign branch), each named as the closed form names
    it, and the loops close to rounding."""
    m = load(SAMPLES / name)
    kinds = [u.kind for u in m.unknowns]
    scale = math.pi / 180 if m.driver.kind == "angle" else 1.0
    for shift in (0.0, 37.0, 131.0, 250.0):
        value = (m.driver.value / scale + shift if m.driver.kind == "angle"
                 else m.driver.value * (1 + shift / 400))
        a = linkage.assemblies(m, value)
        want = [tuple(q) for _, q in m.derivation.solutions(a.driver)]
        assert _same_set([s.q for s in a.real], want, kinds, m.length_scale), (name, value)
        names = set(m.derivation.named_solutions(a.driver))
        for s in a.real:
            assert s.residual <= 1e-12
            assert s.branch in names
        assert a.failed == 0 and a.unresolved == 0
        assert sum(a.multiplicity) + a.complex_count + a.infinite == a.bound <= a.bezout


def _fourbar_text(r1: float, r2: float, r3: float, r4: float, theta2: float) -> str:
    return f"""
name = "random four-bar"
length_unit = "mm"
[parameters]
r1 = {r1!r}
r2 = {r2!r}
r3 = {r3!r}
r4 = {r4!r}
theta1 = 0
[driver]
name = "theta2"
value = {theta2!r}
[unknowns]
theta3 = 0
theta4 = 90
[[loops]]
name = "O2-A-B-O4"
vectors = [{{ length = "r2", angle = "theta2" }}, {{ length = "r3", angle = "theta3" }},
           {{ length = "r4", angle = "theta4", sign = -1 }}, {{ length = "r1", angle = "theta1", sign = -1 }}]
"""


def _law_of_cosines(r1, r2, r3, r4, theta2_deg):
    """B on the circle of radius r3 about A and r4 about O4 = (r1, 0), at 50 digits:
    (theta3, theta4) of each assembly, [] where the circles do not meet."""
    t2 = mpmath.radians(mpmath.mpf(theta2_deg))
    ax, ay = r2 * mpmath.cos(t2), r2 * mpmath.sin(t2)
    dx, dy = r1 - ax, -ay
    d = mpmath.sqrt(dx * dx + dy * dy)
    along = (r3 * r3 - r4 * r4 + d * d) / (2 * d)
    h2 = r3 * r3 - along * along
    if h2 < 0:
        return []
    out = []
    for sign in (1, -1):
        h = sign * mpmath.sqrt(h2)
        bx = ax + (along * dx - h * dy) / d
        by = ay + (along * dy + h * dx) / d
        out.append((float(mpmath.atan2(by - ay, bx - ax)), float(mpmath.atan2(by, bx - r1))))
    return out


def test_random_fourbars_against_the_law_of_cosines_at_50_digits():
    """60 random four-bars (link ratios over two decades, any input angle): the count of
    real assemblies (2 or 0) and both assemblies to 1e-9 rad."""
    rng = random.Random(2026)
    seen = {0: 0, 2: 0}
    for _ in range(60):
        r = [10 ** rng.uniform(-1, 1) for _ in range(4)]
        theta2 = rng.uniform(-180, 180)
        m = from_text(_fourbar_text(*r, theta2), "random")
        a = linkage.assemblies(m)
        want = _law_of_cosines(*[mpmath.mpf(x) for x in r], theta2)
        assert _same_set([s.q for s in a.real], want, ["angle", "angle"], m.length_scale), (r, theta2)
        seen[len(want)] += 1
    assert seen[0] >= 5 and seen[2] >= 5  # both outcomes were tried (50 and 10 of 60 with this seed)


@pytest.mark.parametrize("scale", [1e-6, 1e-3, 1.0, 1e3])
def test_the_answer_does_not_depend_on_the_length_scale(scale):
    """The ME581 four-bar from micrometres to kilometres: the same two assemblies."""
    m = from_text(_fourbar_text(90 * scale, 30 * scale, 60 * scale, 45 * scale, 65.0), "scaled")
    a = linkage.assemblies(m)
    want = _law_of_cosines(*[mpmath.mpf(90), 30, 60, 45], 65.0)
    assert _same_set([s.q for s in a.real], want, ["angle", "angle"], m.length_scale)


def _roots_by_scan(g, lo: float, hi: float, n: int = 4000) -> list[mpmath.mpf]:
    """Every root of g on [lo, hi): each sign change on an n-point grid, bisected at 50
    digits, kept where g vanishes there (not where g jumps: the edge of a range where the
    other loop closes)."""
    xs = [mpmath.mpf(lo) + (hi - lo) * k / n for k in range(n + 1)]
    vals = [g(x) for x in xs]
    out = []
    for a, b, fa, fb in zip(xs, xs[1:], vals, vals[1:]):
        if fa * fb > 0:
            continue
        for _ in range(200):
            c = (a + b) / 2
            fc = g(c)
            if fa * fc <= 0:
                b, fb = c, fc
            else:
                a, fa = c, fc
        if abs(g(a)) < mpmath.mpf(10) ** -30 * (1 + abs(vals[0])):
            out.append(a)
    return out


def test_the_rapier_drives_assemblies_against_a_one_dimensional_scan():
    """Loop 2's y gives theta14 from theta13 (two ways); loop 1 then asks |C - C0| = a5, one
    equation in theta13: its roots by a scan refined at 50 digits, each completed by hand.
    Four real assemblies at 60 deg, the book's among them, and two at 200 deg."""
    a1, b1, d1, a2, a3, a4, a5, b4, a6 = (mpmath.mpf(v)
                                          for v in (340, 520, 623, 250, 1225, 350, 600, 600, 1100))
    m = load(SAMPLES / "rapier_drive.toml")
    for theta12, count in ((60.0, 4), (200.0, 2)):
        t12 = mpmath.radians(theta12)
        A = a2 * mpmath.expj(t12)
        c0 = mpmath.mpc(-d1, -a1)
        want = []
        for branch in (1, -1):
            def t14(t13, branch=branch, A=A):
                s = (A.imag + a3 * mpmath.sin(t13) + b1) / b4  # Im: A + a3 e^(i t13) - b4 e^(i t14) = -b1
                if abs(s) > 1:
                    return None
                base = mpmath.asin(s)
                return base if branch == 1 else mpmath.pi - base

            def gap(t13, t14=t14, A=A, c0=c0):
                u = t14(t13)
                if u is None:
                    return mpmath.mpf(1)  # no sign change where loop 2 cannot close
                C = A + a3 * mpmath.expj(t13) - a4 * mpmath.expj(u)
                return abs(C - c0) ** 2 - a5 ** 2

            for t13 in _roots_by_scan(gap, 0.0, 2 * math.pi):
                u = t14(t13)
                C = A + a3 * mpmath.expj(t13) - a4 * mpmath.expj(u)
                t15 = mpmath.arg(C - c0)
                s16 = (A + a3 * mpmath.expj(t13) - b4 * mpmath.expj(u) + a6).real
                want.append((float(t13), float(u), float(t15), float(s16)))
        a = linkage.assemblies(m, theta12)
        kinds = [u.kind for u in m.unknowns]
        assert len(want) == count
        assert _same_set([s.q for s in a.real], want, kinds, m.length_scale), theta12
    book = (math.radians(188.572556), math.radians(67.394934), math.radians(175.143712), -216.940343)
    a = linkage.assemblies(m, 60.0)
    assert any(_same_set([s.q], [book], kinds, m.length_scale, tol=1e-8) for s in a.real)


def test_the_offset_sliders_assemblies_against_a_one_dimensional_scan():
    """Eq. 4 gives theta15 from theta14 (two ways); eqs. 1-2 say the vector they leave is
    along theta14: one equation in theta14, scanned and refined at 50 digits."""
    m = load(SAMPLES / "offset_slider.toml")
    p = {k: mpmath.mpf(q.value) for k, q in m.parameters.items()}
    b1, c1, a1, a2, a4, a5 = (p[k] for k in ("b1", "c1", "a1", "a2", "a4", "a5"))
    t12 = mpmath.mpf(m.driver.value)
    want = []
    for branch in (1, -1):
        def t15(t14, branch=branch):
            s = (a1 - a4 * mpmath.sin(t14)) / a5
            if abs(s) > 1:
                return None
            base = mpmath.asin(s)
            return base if branch == 1 else mpmath.pi - base

        def across(t14, t15=t15):
            u = t15(t14)
            if u is None:
                return mpmath.mpf(1)
            vx = a2 * mpmath.cos(t12) - b1 - a5 * mpmath.cos(u)
            vy = c1 + a2 * mpmath.sin(t12) - a5 * mpmath.sin(u)
            return vx * mpmath.sin(t14) - vy * mpmath.cos(t14)

        for t14 in _roots_by_scan(across, 0.0, 2 * math.pi):
            u = t15(t14)
            vx = a2 * mpmath.cos(t12) - b1 - a5 * mpmath.cos(u)
            vy = c1 + a2 * mpmath.sin(t12) - a5 * mpmath.sin(u)
            s4 = vx * mpmath.cos(t14) + vy * mpmath.sin(t14)
            s6 = b1 + a5 * mpmath.cos(u) + a4 * mpmath.cos(t14)
            want.append({"theta14": float(t14), "theta15": float(u), "s4": float(s4), "s6": float(s6)})
    names = [u.name for u in m.unknowns]
    want_q = [tuple(w[n] for n in names) for w in want]
    a = linkage.assemblies(m)
    assert _same_set([s.q for s in a.real], want_q, [u.kind for u in m.unknowns], m.length_scale)


def test_within_a_hair_of_a_limit_both_assemblies_are_found_and_flagged_by_their_own_condition():
    """The ME581's limit is at theta2 = 112.0243128... deg: inside it the two assemblies are
    found as the closed form gives them, flagged near_limit where their own condition passes
    1e6 (3e-10 deg inside), not 1.3e-5 deg inside (condition 8e3); 1e-10 deg outside there
    is none (the loops cannot close by 1e-12 of the size), not a double root."""
    m = load(SAMPLES / "fourbar_me581.toml")
    for value, flagged in ((112.0243, False), (112.02431283, False), (112.024312837, True)):
        a = linkage.assemblies(m, value)
        want = [tuple(q) for _, q in m.derivation.solutions(a.driver)]
        assert _same_set([s.q for s in a.real], want, ["angle", "angle"], m.length_scale, tol=1e-7)
        assert all(s.singular == flagged for s in a.real), value
    for value in (112.02431283714216, 112.0243129, 112.02432, 112.03):
        a = linkage.assemblies(m, value)
        assert a.real == () and a.complex_count == 2 and a.unresolved == 0, value


def _crossing_reference(theta2_deg):
    """The change-point crank-rocker (r1 = 100, r2 = 40, r3 = 120, r4 = 60: 40 + 120 = 100 +
    60) by the law of cosines at 50 digits."""
    return _law_of_cosines(mpmath.mpf(100), mpmath.mpf(40), mpmath.mpf(120), mpmath.mpf(60), theta2_deg)


def test_near_a_change_point_both_crossing_assemblies_are_found_where_double_precision_separates_them():
    """An adversary's pass found two assemblies 1.3e-6 rad off, 5e-6 rad apart, 1e-4 deg
    from a change point (Newton stopped on an overshoot), and one of two called complex at
    1e-6 deg. Now both are found to 1e-12 where they are apart by more than their own
    uncertainty, and where they are not (at the change point, or 1e-6 deg from it: 3e-8
    rad apart, uncertainty 1e-7) they are one double assembly, flagged, not one and a
    complex."""
    m = load(SAMPLES / "crank_rocker.toml").with_values({"r2": 40, "r4": 60}, {})
    a = linkage.assemblies(m, 1e-4)
    # each to its own uncertainty: rounding times its condition (3.8e6): 8e-10 rad
    assert _same_set([s.q for s in a.real], _crossing_reference(1e-4), ["angle", "angle"], 1.0, tol=1e-9)
    assert a.multiplicity == (1, 1) and all(s.singular for s in a.real)
    for value in (0.0, 1e-6):
        a = linkage.assemblies(m, value)
        assert len(a.real) == 1 and a.multiplicity == (2,) and a.real[0].singular
        assert a.complex_count == 0 and a.unresolved == 0
        ref = _crossing_reference(value)
        assert all(abs(math.remainder(x - y, 2 * math.pi)) < 2e-6
                   for r in ref for x, y in zip(a.real[0].q, r))


def test_a_six_bar_at_its_four_bars_change_point_has_two_double_assemblies():
    """The Stephenson six-bar with r4 = 60 at theta2 = 0: the four-bar's double root times the
    dyad's two assemblies: 2, each double (it printed 4, the double root twice)."""
    m = load(SAMPLES / "stephenson_sixbar.toml").with_values({"r4": 60}, {})
    a = linkage.assemblies(m, 0.0)
    assert len(a.real) == 2 and a.multiplicity == (2, 2) and a.unresolved == 0


def test_a_linkage_that_moves_with_its_driver_held_is_not_isolated():
    """A rhombus (r1 = r2 = r3 = r4) at theta2 = 0 folds with A on O4: the coupler turns
    freely. It listed 3 'assemblies' (4 with another seed)."""
    m = load(SAMPLES / "crank_rocker.toml").with_values({"r1": 1, "r2": 1, "r3": 1, "r4": 1}, {})
    a = linkage.assemblies(m, 0.0)
    assert a.continuum and a.real == ()


def test_a_linkage_that_moves_with_its_driver_held_is_not_called_unassemblable():
    """Its report said "not isolated: the loops close all along a curve here" and then "no real
    assembly: the mechanism cannot be assembled here", which the first line contradicts."""
    from linkage.render.assemblies import assemblies_report
    from linkage.render.report import Text

    m = load(SAMPLES / "crank_rocker.toml").with_values({"r1": 1, "r2": 1, "r3": 1, "r4": 1}, {})
    lines = [b.text for b in assemblies_report(linkage.assemblies(m, 0.0), 6, False).blocks()
             if isinstance(b, Text)]
    assert any(line.startswith("not isolated") for line in lines)
    assert not any("cannot be assembled" in line for line in lines)


def test_a_rocker_driven_four_bars_mirror_assembly_is_named_as_branch_takes_it():
    """Both assemblies of the rocker-driven ME581 at theta4 = 120 are open; the second is
    'open (mirror)', the name --branch takes (both printed 'open')."""
    m = load(SAMPLES / "fourbar_me581_theta4.toml")
    a = linkage.assemblies(m, 120.0)
    assert sorted(s.branch for s in a.real) == ["open", "open (mirror)"]
    named = m.derivation.named_solutions(a.driver)
    for s in a.real:
        assert _same_set([s.q], [tuple(named[s.branch][1])], ["angle", "angle"], 90.0)


# --- the command --------------------------------------------------------------------------

def test_the_command_lists_every_assembly_and_counts_the_paths(cli):
    r = cli("assemblies", str(SAMPLES / "watt_sixbar.toml"), "-f", "plain")
    assert r.code == 0, r.err
    assert ("4 paths (the linear-product Bezout number of the grouping {z}, {w}; total degree 16): "
            "4 real assemblies, 0 complex, 0 at infinity" in r.out)
    for name in ("open/open", "open/crossed", "crossed/open", "crossed/crossed"):
        assert f" {name} " in r.out


def test_no_assembly_is_exit_1_with_a_line_saying_so(cli):
    r = cli("assemblies", str(SAMPLES / "fourbar_me581.toml"), "--set", "theta2=180", "-f", "plain")
    assert r.code == 1
    assert "no real assembly: the mechanism cannot be assembled here" in r.out


def test_json_and_csv_carry_the_counts_and_every_table(cli, tmp_path):
    r = cli("assemblies", str(SAMPLES / "rapier_drive.toml"), "-f", "json")
    doc = json.loads(r.out)
    assert (doc["bezout"], doc["bound"], doc["real"], doc["complex"], doc["infinite"], doc["failed"]) == (
        8, 6, 4, 2, 0, 0)
    names = [t["name"] for t in doc["tables"]]
    assert names == ["assemblies", "joints", "paths"]
    r = cli("assemblies", str(SAMPLES / "rapier_drive.toml"), "--paths", "-f", "plain")
    assert "Paths" in r.out and "cycle" in r.out and "endgame" in r.out


def test_a_path_to_a_limit_position_takes_the_endgame_and_a_clean_root_does_not():
    """Tracked to t = 1 itself, a path that ends at a nonsingular root needs no endgame; a
    near-double root (the ME581 3e-10 deg inside its limit position) is not, and takes it."""
    m = load(SAMPLES / "fourbar_me581.toml")
    clean = linkage.assemblies(m)
    assert [e.endgame for e in clean.solutions.endpoints] == [False, False]
    limit = linkage.assemblies(m, 112.024312837)
    assert [e.endgame for e in limit.solutions.endpoints] == [True, True]
    assert len(limit.real) == 2


@pytest.mark.parametrize("args,says", [
    (["--set", "theta2=nan"], "theta2"),
    (["--set", "nosuch=1"], "nosuch"),
    (["--seed", "-1"], "seed"),
])
def test_bad_input_is_one_line_and_exit_2(cli, args, says):
    r = cli("assemblies", str(SAMPLES / "fourbar_me581.toml"), *args)
    assert r.code == 2
    assert says in r.err and r.err.strip().count("\n") == 0


def test_the_polynomial_system_is_the_loops():
    """At a real assembly the polynomials vanish, and z w = 1 holds: the system is the
    loops, not a look-alike; a point off the assembly does not make them vanish."""
    from linkage.kinematics.assemblies import assembly_system

    m = load(SAMPLES / "rapier_drive.toml")
    system = assembly_system(m, m.driver.value)
    for s in linkage.assemblies(m).real:
        x = []
        for u, v in zip(m.unknowns, s.q):
            z = complex(math.cos(v), math.sin(v))
            x += [z, z.conjugate()] if u.kind == "angle" else [v / m.length_scale]
        assert np.abs(system.evaluate(np.array([x]))).max() < 1e-13
        assert system.realness(np.array(x)) == 0.0
        x[0] *= complex(math.cos(1e-3), math.sin(1e-3))
        assert np.abs(system.evaluate(np.array([x]))).max() > 1e-5

"""The one-at-a-time sweep on the derived closed form (issue 19): branch names and signs,
re-entry, limit positions, feasible ranges and transmission angles for every dyadic
mechanism, checked against references derived here (the law of cosines and circle
intersections in 50-digit mpmath), not against the code under test."""

from __future__ import annotations

import math
from pathlib import Path

import mpmath as mp
import numpy as np
import pytest

import linkage
from derived_reference import abcd_text
from linkage.errors import InputError
from linkage.kinematics.loading import load

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
mp.mp.dps = 50


def abcd(tmp_path: Path, links: tuple[float, float, float, float], driver: str, value: float = 30.0):
    path = tmp_path / f"abcd_{driver}.toml"
    guesses = {n: g for n, g in (("theta2", 30.0), ("theta3", 20.0), ("theta4", 60.0)) if n != driver}
    path.write_text(abcd_text(links, driver, value, guesses))
    return load(path)


def deg(x) -> mp.mpf:
    return x * 180 / mp.pi


def rad(x) -> mp.mpf:
    return mp.mpf(x) * mp.pi / 180


def circles(p, r, q, s):
    """The two points X with |X - p| = r and |X - q| = s (mpmath complex), or []."""
    dvec = q - p
    dist = abs(dvec)
    x = (r * r - s * s + dist * dist) / (2 * dist)
    if r * r - x * x < 0:
        return []
    h = mp.sqrt(r * r - x * x)
    u = dvec / dist
    return [p + x * u + sgn * h * 1j * u for sgn in (1, -1)]


def crank_driven(links, theta2_deg, name):
    """(theta3, theta4) in degrees (mpmath) of the assembly called ``name`` (open where
    sin(theta4 - theta3) > 0, worked example P3, docs/worked_examples.md), driven by theta2; None if none."""
    a, b, c, d = (mp.mpf(x) for x in links)
    A = a * mp.expj(rad(theta2_deg))
    for B in circles(A, b, mp.mpf(d), c):
        t3, t4 = mp.arg(B - A), mp.arg(B - d)
        if (mp.sin(t4 - t3) > 0) == (name == "open"):
            return deg(t3), deg(t4)
    return None


def is_open(t3_deg: float, t4_deg: float) -> bool:
    return math.sin(math.radians(t4_deg - t3_deg)) > 0


def wrap(x: float) -> float:
    return math.remainder(x, 360.0)


NON_GRASHOF = (60.0, 50.0, 70.0, 100.0)  # s + l = 150 > p + q = 130: every joint has limits
GRASHOF = (40.0, 120.0, 80.0, 100.0)      # the crank-rocker of crank_rocker.toml


# --- 1. names: the configuration's, under every driver -------------------------------------

@pytest.mark.parametrize("links", [GRASHOF, NON_GRASHOF])
@pytest.mark.parametrize("driver", ["theta2", "theta3", "theta4"])
def test_a_configuration_has_its_name_under_every_driver(tmp_path, links, driver):
    """A four-bar written with names a, b, c, d (no closed_form key) driven by the crank,
    the coupler or the rocker: every swept position is labelled open exactly where
    sin(theta4 - theta3) > 0 of that configuration. A sweep follows one assembly by its
    signs (issue 19): a sign string (+, -) that assembly whatever its name; --branch open /
    crossed the assembly that carries the name where it first appears, which keeps the
    label under the crank (each name is one sign branch, reported by its name) and may
    change it under the coupler or the rocker (reported by its signs)."""
    m = abcd(tmp_path, links, driver)
    assert m.closed_form is None and m.derivation.summary == "closed form: loop 1"
    d = m.derivation
    values = [float(v) for v in range(0, 360, 3)]
    seen = set()
    runs = {}
    for branch in ("+", "-", None, "open", "crossed"):
        r = linkage.sweep(m, values, branch=branch)
        solved = [p for p in r.positions if p.solution]
        assert solved, branch
        labels = {}
        for p in solved:
            full = {**p.solution, driver: p.input}
            label = "open" if is_open(full["theta3"], full["theta4"]) else "crossed"
            assert p.branch == label, (branch, p)
            seen.add(label)
            labels[p.input] = label
        signs = {d.signs_of([math.radians(p.solution[u.name]) for u in m.unknowns],
                            math.radians(p.input)) for p in solved}
        assert len(signs) == 1, (branch, signs)
        runs[branch] = labels
        if branch in ("+", "-"):
            # crank-driven, each name is one sign branch and the sweep reports it by name;
            # driven by the coupler or the rocker the names cut across the signs
            assert (r.branch in ("open", "crossed")) == (driver == "theta2"), r.branch
            assert signs == {(1.0,) if branch == "+" else (-1.0,)}
        if branch in ("open", "crossed"):
            if driver == "theta2":
                assert set(labels.values()) == {branch} and r.branch == branch
            else:
                assert r.branch == ("+" if signs == {(1.0,)} else "-")
            # the first driver value where either assembly carries the name
            first = min(v for side in ("+", "-") for v, name in runs[side].items() if name == branch)
            assert labels[first] == branch, (branch, first)
    assert seen == {"open", "crossed"}


def test_the_crank_driven_configuration_is_found_by_name_from_the_coupler_and_the_rocker(tmp_path):
    """The open assembly at theta2 = 30 deg (law of cosines) is the one the coupler-driven
    and the rocker-driven files call open at its theta3 and theta4."""
    t3, t4 = (float(x) for x in crank_driven(GRASHOF, 30, "open"))
    for driver, value, other in (("theta3", t3, "theta4"), ("theta4", t4, "theta3")):
        m = abcd(tmp_path, GRASHOF, driver)
        r = linkage.sweep(m, [value], branch="open")
        (p,) = r.positions
        assert p.status == "converged" and p.branch == "open"
        if abs(wrap(p.solution["theta2"] - 30.0)) > 1e-9:
            # both assemblies at that value are open: the mirror is the other one
            p = linkage.sweep(m, [value], branch="open (mirror)").positions[0]
        assert abs(wrap(p.solution["theta2"] - 30.0)) < 1e-9
        assert abs(wrap(p.solution[other] - (t4 if other == "theta4" else t3))) < 1e-9


# --- 2. limits exactly ---------------------------------------------------------------------

def _limit_references(links, driver):
    """The limit positions (deg, mpmath) of a non-Grashof four-bar by the law of cosines:
    crank: |A - O4| = b + c; coupler: |b e^(i t3) - d| = a + c; rocker: |d + c e^(i t4)| = a + b
    (the other bound never binds for NON_GRASHOF)."""
    a, b, c, d = (mp.mpf(x) for x in links)
    if driver == "theta2":
        cos = (a * a + d * d - (b + c) ** 2) / (2 * a * d)
    elif driver == "theta3":
        cos = (b * b + d * d - (a + c) ** 2) / (2 * b * d)
    else:
        cos = ((a + b) ** 2 - d * d - c * c) / (2 * d * c)
    t = deg(mp.acos(cos))
    return t, 360 - t


@pytest.mark.parametrize("driver", ["theta2", "theta3", "theta4"])
def test_limit_positions_are_the_law_of_cosines_to_a_few_ulps(tmp_path, driver):
    m = abcd(tmp_path, NON_GRASHOF, driver)
    values = [float(v) for v in range(0, 360)]
    r = linkage.sweep(m, values, branch="+")
    refs = _limit_references(NON_GRASHOF, driver)
    assert len(r.toggles) == 2
    for got, want in zip(sorted(r.toggles), sorted(refs)):
        assert abs(got - float(want)) <= 8 * math.ulp(float(want)), (got, want)
    # the feasible ranges are bounded by them: one arc through 0 (or 180 for the rocker)
    lo, hi = sorted(float(t) for t in refs)
    want_ranges = [(lo, hi)] if driver == "theta4" else [(0.0, lo), (hi, 359.0)]
    assert len(r.feasible_ranges) == len(want_ranges)
    for (a, b), (c, d) in zip(r.feasible_ranges, want_ranges):
        assert abs(a - c) <= 1e-12 and abs(b - d) <= 1e-12
    # and the solved positions are exactly those inside them
    for p in r.positions:
        inside = any(a <= p.input <= b for a, b in want_ranges)
        assert (p.status == "converged") == inside, p


def test_the_numpy_twin_of_the_limit_search_agrees_with_mpmath(tmp_path):
    from linkage.problems.derive_limits import assembles, limit_between, limits_between_np

    m = abcd(tmp_path, NON_GRASHOF, "theta2")
    d = m.derivation
    scale = math.pi / 180.0
    a = np.array([93.0, 266.0])
    b = np.array([94.0, 267.0])
    got = limits_between_np(d, a, b, [(1.0,)], scale)
    refs = sorted(float(t) for t in _limit_references(NON_GRASHOF, "theta2"))
    for g, s, want in zip(got, (limit_between(d, x, y, [(1.0,)], scale) for x, y in zip(a, b)), refs):
        assert g == s and abs(g - want) <= 8 * math.ulp(want)
        assert assembles(d, g, [(1.0,)], scale) >= 0.0  # the last driver value that assembles


def test_positions_within_1e_9_deg_of_a_limit_are_accurate_to_their_conditioning(tmp_path):
    """At 1e-9 deg inside a crank limit the answer moves like sqrt of the distance to it:
    each angle must agree with 50-digit mpmath at the same double driver value within a
    few ulps of its own sensitivity to that value (|dtheta/dtheta2| ulp(theta2))."""
    m = abcd(tmp_path, NON_GRASHOF, "theta2")
    lim = _limit_references(NON_GRASHOF, "theta2")[0]
    for branch in ("open", "crossed"):
        v = float(lim) - 1e-9
        r = linkage.sweep(m, [v - 2.0, v - 1.0, v], branch=branch)
        p = r.positions[-1]
        assert p.status == "converged" and p.branch == branch
        h = mp.mpf("1e-30")
        here = crank_driven(NON_GRASHOF, mp.mpf(v), branch)
        before = crank_driven(NON_GRASHOF, mp.mpf(v) - h, branch)
        for j, name in enumerate(("theta3", "theta4")):
            slope = abs((here[j] - before[j]) / h)
            bound = 8 * (float(slope) * math.ulp(v) + math.ulp(float(here[j])))
            err = abs(p.solution[name] - float(here[j]))
            assert err <= bound, (branch, name, err, bound)
            assert slope > 1e3  # the test is near the limit indeed


# --- 3. transmission angles ------------------------------------------------------------------

@pytest.mark.parametrize("driver", ["theta2", "theta3", "theta4"])
def test_transmission_angle_is_the_law_of_cosines_at_every_position(tmp_path, driver):
    """mu from cos(mu) = (b^2 + c^2 - |A - O4|^2) / (2 b c), with A from the crank angle."""
    m = abcd(tmp_path, GRASHOF, driver)
    a, b, c, d = GRASHOF
    r = linkage.sweep(m, [float(v) for v in range(0, 360, 3)])
    checked = 0
    for p in r.positions:
        if p.solution is None:
            continue
        t2 = math.radians(p.input if driver == "theta2" else p.solution["theta2"])
        ao4 = a * a + d * d - 2 * a * d * math.cos(t2)
        cos_mu = (b * b + c * c - ao4) / (2 * b * c)
        if abs(cos_mu) > 0.99:
            continue  # acos is ill-conditioned there; the reference would be the weak one
        assert abs(p.transmission - math.degrees(math.acos(cos_mu))) < 1e-9, p
        checked += 1
    assert checked >= 10


# --- 4. the Watt six-bar ------------------------------------------------------------------------

def watt_refs(r5=70.0, r6=110.0, r7=80.0, g=120.0, gamma=60.0):
    """The Watt six-bar of watt_sixbar.toml (loop 1 the crank-rocker) by circle
    intersections in mpmath: theta2 -> {name: (theta3, theta4, theta6, theta7)} (deg), each
    loop open where its output turns anticlockwise from its coupler."""
    def solve(theta2):
        out = {}
        for n1 in ("open", "crossed"):
            t = crank_driven(GRASHOF, theta2, n1)
            t3, t4 = t
            C = r5 * mp.expj(rad(t4 + 40))
            O6 = g * mp.expj(rad(gamma))
            for D in circles(C, mp.mpf(r6), O6, mp.mpf(r7)):
                t6, t7 = deg(mp.arg(D - C)), deg(mp.arg(D - O6))
                n2 = "open" if mp.sin(rad(t7 - t6)) > 0 else "crossed"
                out[f"{n1}/{n2}"] = (t3, t4, t6, t7)
        return out
    return solve


def test_the_watt_sixbar_is_named_and_followed_by_loop(tmp_path):
    m = load(SAMPLES / "watt_sixbar.toml")
    assert m.closed_form is None
    ref = watt_refs()
    values = [float(v) for v in range(0, 360, 10)]
    for branch, signs in (("open/open", "++"), ("open/crossed", "+-"), ("crossed/open", "-+"),
                          ("crossed/crossed", "--")):
        by_name = linkage.sweep(m, values, branch=branch)
        by_signs = linkage.sweep(m, values, branch=signs)
        assert by_name.summary == {"converged": len(values)}
        assert [p.solution for p in by_name.positions] == [p.solution for p in by_signs.positions]
        for p in by_name.positions:
            assert p.branch == branch
            want = ref(mp.mpf(p.input))[branch]
            for name, w in zip(("theta3", "theta4", "theta6", "theta7"), want):
                assert abs(wrap(p.solution[name] - float(w))) < 1e-9, (branch, p.input, name)
    c = linkage.sweep(m, values).classification
    assert [x["type"] for x in c["loops"]] == ["Grashof crank-rocker", "change point"]  # 70+120 = 110+80


def short_watt(tmp_path: Path):
    """watt_sixbar.toml with r6 = r7 = 60: its second loop parts over part of the cycle."""
    text = (SAMPLES / "watt_sixbar.toml").read_text()
    for old, new in (("r6 = { value = 110", "r6 = { value = 60"), ("r7 = { value = 80", "r7 = { value = 60")):
        assert old in text
        text = text.replace(old, new)
    path = tmp_path / "watt_short.toml"
    path.write_text(text)
    return load(path)


def test_watt_sixbar_second_loop_limits_and_reentry_on_its_signs(tmp_path):
    """With r6 = r7 = 60 the second loop parts where |O6 - C| = 120 (C on the rocker's
    extension): its two limits in theta2 are those roots (mpmath), the feasible ranges lie
    between them, and after the gap the sweep re-enters on the same signs."""
    m = short_watt(tmp_path)
    values = [float(v) for v in range(0, 360)]
    r = linkage.sweep(m, values, branch="open/crossed")

    def gap(theta2):
        t4 = crank_driven(GRASHOF, theta2, "open")[1]
        C = 70 * mp.expj(rad(t4 + 40))
        return abs(120 * mp.expj(rad(60)) - C) - 120

    assert len(r.toggles) == 2
    for t in r.toggles:
        want = mp.findroot(gap, (mp.mpf(t) - mp.mpf("0.01"), mp.mpf(t) + mp.mpf("0.01")), solver="anderson")
        assert abs(t - float(want)) <= 16 * math.ulp(float(want)), (t, want)
    solved = [p for p in r.positions if p.solution]
    unsolved = [p for p in r.positions if not p.solution]
    assert solved and unsolved and all(p.status == "no_solution" for p in unsolved)
    assert any("re-entered" in p.note for p in solved)
    ref = watt_refs(r6=60.0, r7=60.0)
    for p in solved:
        assert p.branch == "open/crossed"
        assert any(a <= p.input <= b for a, b in r.feasible_ranges)
        want = ref(mp.mpf(p.input))["open/crossed"]
        assert abs(wrap(p.solution["theta6"] - float(want[2]))) < 1e-8, p
    for p in unsolved:
        assert "open/crossed" not in ref(mp.mpf(p.input))
    # the transmission reported is the loop farthest from 90 deg
    p = solved[0]
    mu1 = abs(wrap(p.solution["theta4"] - p.solution["theta3"]))
    mu2 = abs(wrap(p.solution["theta7"] - p.solution["theta6"]))
    assert abs(p.transmission - max((mu1, mu2), key=lambda mu: abs(mu - 90.0))) < 1e-9


# --- --branch ----------------------------------------------------------------------------------

def test_branch_errors_name_the_argument_and_the_choices(tmp_path):
    m = abcd(tmp_path, GRASHOF, "theta3")
    with pytest.raises(InputError, match=r"branch.*open or crossed"):
        linkage.sweep(m, [30.0], branch="sideways")
    with pytest.raises(InputError, match=r"branch.*open/open.*\+-"):
        linkage.sweep(SAMPLES / "watt_sixbar.toml", [30.0], branch="open")
    with pytest.raises(InputError, match=r"branch needs a closed form; .*rapier_drive.toml has none: "
                                         r"loop 1 has 3 unknowns"):
        linkage.sweep(SAMPLES / "rapier_drive.toml", [30.0], branch="open")


def test_branch_on_the_command_line(cli):
    run = cli("sweep", str(SAMPLES / "watt_sixbar.toml"), "--from", "0", "--to", "20", "--step", "10",
              "--branch", "crossed/open", "--format", "json")
    import json

    doc = json.loads(run.out)
    assert run.code == 0 and doc["branch"] == "crossed/open"
    assert {p["branch"] for p in doc["positions"]} == {"crossed/open"}
    bad = cli("sweep", str(SAMPLES / "watt_sixbar.toml"), "--branch", "sideways")
    assert bad.code == 2 and bad.err.startswith("error: --branch must be") and len(bad.err.splitlines()) == 1


def test_slider_crank_limits_are_the_arcsines_and_each_arc_is_reentered(tmp_path):
    """A slider-crank whose coupler (25) is shorter than crank plus offset (40 + 10): it
    assembles where |e - r2 sin(theta2)| <= r3, two arcs bounded by arcsin((e +- r3) / r2)
    (mpmath); a sweep on one branch solves both arcs (re-entering the second), labelled
    open where the coupler points the way the slide grows (cos(theta3) > 0)."""
    text = (SAMPLES / "slider_crank.toml").read_text()
    assert 'r3 = { value = 120' in text
    path = tmp_path / "short_slider.toml"
    path.write_text(text.replace('r3 = { value = 120', 'r3 = { value = 25'))
    m = load(path)
    r2, r3, e = mp.mpf(40), mp.mpf(25), mp.mpf(10)
    hi, lo = deg(mp.asin((e + r3) / r2)), deg(mp.asin((e - r3) / r2))
    want = sorted(float(t) for t in (hi, 180 - hi, 180 - lo, 360 + lo))
    values = [float(v) for v in range(0, 360)]
    for branch in ("open", "crossed", "+", "-"):
        r = linkage.sweep(m, values, branch=branch)
        assert len(r.toggles) == 4
        for got, w in zip(r.toggles, want):
            assert abs(got - w) <= 8 * math.ulp(w), (branch, got, w)
        ranges = [(0.0, want[0]), (want[1], want[2]), (want[3], 359.0)]
        assert len(r.feasible_ranges) == len(ranges)
        for got_range, want_range in zip(r.feasible_ranges, ranges):
            assert list(got_range) == pytest.approx(list(want_range), abs=1e-12)
        for p in r.positions:
            inside = any(a <= p.input <= b for a, b in ranges)
            assert (p.status == "converged") == inside, (branch, p)
            if p.solution is not None:
                label = "open" if math.cos(math.radians(p.solution["theta3"])) > 0 else "crossed"
                assert p.branch == label
                if branch in ("open", "crossed"):
                    assert label == branch
        assert any("re-entered" in p.note for p in r.positions)


def test_an_unassembled_sliver_between_two_grid_points_is_found(tmp_path):
    """b + c = 139.99 just short of the crank's farthest reach a + d = 140: the four-bar
    parts for 2.9 deg either side of theta2 = 180, between the grid points 175 and 185.
    Both limits are found (the margin's dip, then bisection), to a few ulps of the law of
    cosines, and the feasible ranges leave the sliver out."""
    links = (40.0, 69.99, 70.0, 100.0)
    m = abcd(tmp_path, links, "theta2")
    values = [float(v) for v in range(5, 360, 10)]
    r = linkage.sweep(m, values, branch="open")
    a, b, c, d = (mp.mpf(x) for x in links)
    t = deg(mp.acos((a * a + d * d - (b + c) ** 2) / (2 * a * d)))
    want = [float(t), float(360 - t)]
    assert 177.0 < want[0] < 180.0 < want[1] < 183.0
    assert len(r.toggles) == 2
    for got, w in zip(r.toggles, want):
        # near 180 deg the reach |A - O4| is nearly stationary, so its rounding moves the
        # root by eps |A - O4| / (d|A - O4| / dtheta2): that, in degrees, plus a few ulps
        reach = mp.sqrt(a * a + d * d - 2 * a * d * mp.cos(rad(w)))
        slope = a * d * abs(mp.sin(rad(w))) / reach
        bound = 8 * math.ulp(w) + 8 * 2.0**-52 * float(deg(reach / slope))
        assert abs(got - w) <= bound, (got, w, bound)
    assert [list(x) for x in r.feasible_ranges] == [[5.0, r.toggles[0]], [r.toggles[1], 355.0]]


def test_watt_positions_within_1e_9_deg_of_the_second_loops_limit_are_accurate(tmp_path):
    """1e-9 deg inside each limit of the short Watt six-bar's second loop, every angle
    agrees with 50-digit mpmath at the same double theta2 within a few ulps of its own
    sensitivity to theta2 (theta6 and theta7 move like the square root of the distance)."""
    m = short_watt(tmp_path)
    branch = "open/crossed"
    ranges = linkage.sweep(m, [float(v) for v in range(0, 360, 5)], branch=branch).feasible_ranges
    ref = watt_refs(r6=60.0, r7=60.0)
    ends = [(b, -1.0) for a, b in ranges if b < 355.0] + [(a, 1.0) for a, b in ranges if a > 0.0]
    assert len(ends) == 2
    for end, inward in ends:
        v = end + inward * 1e-9
        r = linkage.sweep(m, [v + inward * 2.0, v + inward * 1.0, v], branch=branch)
        p = r.positions[-1]
        assert p.status == "converged" and p.branch == branch
        h = mp.mpf("1e-30") * inward
        here, near = ref(mp.mpf(v))[branch], ref(mp.mpf(v) + h)[branch]
        for j, name in enumerate(("theta3", "theta4", "theta6", "theta7")):
            slope = abs((near[j] - here[j]) / h)
            bound = 8 * (float(slope) * math.ulp(v) + math.ulp(float(here[j])))
            assert abs(wrap(p.solution[name] - float(here[j]))) <= bound, (end, name, bound)
            if j >= 2:
                assert slope > 1e3  # the second loop is near its limit indeed


def test_a_sign_string_on_the_batch_engine_is_the_branch_of_that_name():
    """A sign string is followed as the name of its sign branch where each name is one (a
    crank-driven four-bar), so the batch engine, which follows names, follows it too."""
    values = np.linspace(0.0, 360.0, 2001)
    r = linkage.sweep(SAMPLES / "crank_rocker.toml", values, branch="-", batch=True)
    assert r.branch == "crossed" and r.summary == {"converged": 2001}
    for p in r.positions[::97]:
        assert p.branch == "crossed" and not is_open(p.solution["theta3"], p.solution["theta4"])


@pytest.mark.parametrize("name", ["crank_rocker.toml", "watt_sixbar.toml", "fourbar_me581.toml",
                                  "fourbar_me581_theta4.toml"])
def test_a_command_line_sweep_of_a_derived_closed_form_does_not_import_numpy(name):
    """The limits and followed branches of a command-line sweep come from the scalar rules:
    numpy's import cost a fresh `linkage sweep FILE` more than the sweep (cold start 4.4x
    of `import rich.table` against the 2.0x target, linkage bench)."""
    import subprocess
    import sys

    code = ("import sys, runpy, io, contextlib\n"
            f"sys.argv = ['linkage', 'sweep', {str(SAMPLES / name)!r}]\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n"
            "    try:\n"
            "        runpy.run_module('linkage', run_name='__main__')\n"
            "    except SystemExit as e:\n"
            "        assert e.code == 0, e.code\n"
            "print('HEAVY', [m for m in ('numpy', 'scipy', 'matplotlib') if m in sys.modules])\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "HEAVY []" in proc.stdout


@pytest.mark.parametrize("values", [[0.0, 90.0, 180.0, 270.0, 360.0], [-360.0 + 90.0 * k for k in range(9)]])
def test_a_coarse_grid_reports_no_limit_where_the_linkage_does_not_assemble(values):
    """The ME581 four-bar (90, 30, 60, 45 cm) reaches theta2 = +-acos(-3/8) only (r3 and r4 in
    line: 30^2 + 90^2 - 5400 cos = 105^2). Swept every 90 deg, the unassembled 180 was searched
    for a dip as if it assembled: 180, 214.38 (and -180, -145.62) were reported as limits."""
    limit = math.degrees(math.acos(-3.0 / 8.0))
    expected = sorted(t + 360.0 * k for t in (limit, 360.0 - limit) for k in (-2, -1, 0, 1)
                      if values[0] <= t + 360.0 * k <= values[-1])
    result = linkage.sweep(str(SAMPLES / "fourbar_me581.toml"), values)
    assert len(result.toggles) == len(expected)
    assert all(abs(a - b) <= 1e-9 for a, b in zip(result.toggles, expected))

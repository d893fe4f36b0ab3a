"""Issue 18, closed forms: accurate to their conditioning near limits, one branch rule
whatever the driver, closed_form claims checked as an identity of the loops, and every
numpy twin equal to its scalar rule (linkage.problems.assembly, closed_form).

References are 50-digit mpmath circle intersections written here, independently of the
code under test (law of cosines on exact binary inputs, no shared formula).
"""

from __future__ import annotations

import json
import math
import random
from pathlib import Path

import numpy as np
import pytest

from linkage.errors import ParseError
from linkage.kinematics.loading import load, parse_mechanism
from linkage.problems import assembly
from linkage.problems.closed_form import (
    MIRROR,
    fourbar_positions,
    grashof,
    grashof_np,
    slider_crank_positions,
    transmission,
    transmission_np,
)

mp = pytest.importorskip("mpmath")

ROOT = Path(__file__).resolve().parent.parent
SAMPLES = ROOT / "sample_inputs"
EPS = 2.0 ** -52
BOUND_ULPS = 2.0
"""The accuracy bound: |computed - exact| <= BOUND_ULPS * eps * (kappa + |y|), kappa the
componentwise condition of y = f(x): sum over inputs x_i of |dy/dx_i| |x_i| (the
answer's change when every input is perturbed by one part in 1/eps), |y| the rounding
of the answer itself (angles are at most pi). Measured: at most 0.42 over 1,200 limit
cases; the former formulas (h = sqrt(r^2 - a^2), d = |A - O4| from coordinates) reach
5.9 on these same cases."""


# --- independent 50-digit references ---------------------------------------------------------

def _wrap(a):
    return (a + mp.pi) % (2 * mp.pi) - mp.pi


def mp_crank(r1, r2, r3, r4, t1, t2):
    """[(theta3, theta4)] of a four-bar driven by theta2: B on the circle about O4 (r4)
    and about A (r3), by the law of cosines in the triangle O4-A-B."""
    o4 = mp.mpc(r1 * mp.cos(t1), r1 * mp.sin(t1))
    a = mp.mpc(r2 * mp.cos(t2), r2 * mp.sin(t2))
    d = abs(a - o4)
    c = (r4 ** 2 + d ** 2 - r3 ** 2) / (2 * r4 * d)  # cos of the angle at O4
    if abs(c) > 1:
        return []
    base = mp.arg(a - o4)
    out = []
    for s in (1, -1):
        b = o4 + r4 * mp.expj(base + s * mp.acos(c))
        out.append((mp.arg(b - a), mp.arg(b - o4)))
    return out


def mp_rocker(r1, r2, r3, r4, t1, t4):
    """[(theta2, theta3)] of a four-bar driven by theta4: A about O2 (r2) and B (r3)."""
    b = mp.mpc(r1 * mp.cos(t1), r1 * mp.sin(t1)) + r4 * mp.expj(t4)
    d = abs(b)
    c = (r2 ** 2 + d ** 2 - r3 ** 2) / (2 * r2 * d)
    if abs(c) > 1:
        return []
    out = []
    for s in (1, -1):
        a = r2 * mp.expj(mp.arg(b) + s * mp.acos(c))
        out.append((mp.arg(a), mp.arg(b - a)))
    return out


def mp_slider(r2, r3, e, t2):
    """[(theta3, s)]: A = r2 e^(i t2), B = (s, e) with |B - A| = r3."""
    dy = e - r2 * mp.sin(t2)
    if abs(dy) > r3:
        return []
    dx = mp.sqrt(r3 ** 2 - dy ** 2)
    return [(mp.atan2(dy, sx), r2 * mp.cos(t2) + sx) for sx in (dx, -dx)]


def _distance(a, b, kinds):
    return max(abs(_wrap(x - y)) if k == "angle" else abs(x - y) for x, y, k in zip(a, b, kinds))


def _conditioning(ref_fn, x, sol, kinds):
    """kappa of each output at the solution ``sol`` of ref_fn(*x): central differences
    at 50 digits, each input moved by one part in 1e25, the branch followed by nearness."""
    kappa = [mp.mpf(0)] * len(sol)
    for i, xi in enumerate(x):
        if xi == 0:
            continue
        h = abs(xi) * mp.mpf("1e-25")
        ends = []
        for step in (h, -h):
            moved = list(x)
            moved[i] = xi + step
            ends.append(min(ref_fn(*moved), key=lambda s: _distance(s, sol, kinds)))
        for j in range(len(sol)):
            diff = _wrap(ends[0][j] - ends[1][j]) if kinds[j] == "angle" else ends[0][j] - ends[1][j]
            kappa[j] += abs(diff / (2 * h)) * abs(xi)
    return kappa


def _limit_cases(kind, rng, count):
    """(inputs, driver index) within 1e-9 to 1e-3 deg of a limit, inputs exact doubles."""
    out = []
    with mp.workdps(50):
        while len(out) < count:
            scale = 10 ** rng.uniform(-3, 3)
            t1 = 0.0 if rng.random() < 0.5 else rng.uniform(-math.pi, math.pi)
            if kind == "slider":
                r2, r3 = (scale * 10 ** rng.uniform(-1, 1) for _ in range(2))
                e = rng.uniform(-1.0, 1.0) * min(r2, r3)
                sin_star = (mp.mpf(e) - rng.choice((1, -1)) * mp.mpf(r3)) / r2
                if abs(sin_star) > 1:
                    continue
                star = mp.asin(sin_star) if rng.random() < 0.5 else mp.pi - mp.asin(sin_star)
                x, fn = [r2, r3, e, None], mp_slider
            else:
                r1, r2, r3, r4 = (scale * 10 ** rng.uniform(-1, 1) for _ in range(4))
                if kind == "crank":
                    far, near = r3 + mp.mpf(r4), abs(r3 - mp.mpf(r4))
                    d = rng.choice((far, near))
                    c = (mp.mpf(r1) ** 2 + mp.mpf(r2) ** 2 - d * d) / (2 * mp.mpf(r1) * r2)
                else:
                    far, near = r2 + mp.mpf(r3), abs(r2 - mp.mpf(r3))
                    d = rng.choice((far, near))
                    c = (d * d - mp.mpf(r1) ** 2 - mp.mpf(r4) ** 2) / (2 * mp.mpf(r1) * r4)
                if abs(c) > 1:
                    continue
                star = t1 + rng.choice((1, -1)) * mp.acos(c)
                x, fn = [r1, r2, r3, r4, t1, None], (mp_crank if kind == "crank" else mp_rocker)
            away = mp.radians(10 ** rng.uniform(-9, -3))
            first = rng.choice((1, -1))
            for s in (first, -first):  # the side of the limit where it assembles
                x[-1] = float(_wrap(star + s * away))
                if fn(*[mp.mpf(v) for v in x]):
                    out.append((list(x), fn))
                    break
    return out


def _computed(kind, x):
    if kind == "crank":
        return assembly.fourbar_by_crank(*x), ("angle", "angle")
    if kind == "rocker":
        return assembly.fourbar_by_rocker(*x), ("angle", "angle")
    return assembly.slider_crank(*x), ("angle", "length")


@pytest.mark.parametrize("kind", ["crank", "rocker", "slider"])
def test_closed_form_positions_near_limits_are_within_ulps_of_their_conditioning(kind):
    """Within 1e-9 to 1e-3 deg of a limit (random four-bars driven either way and
    slider-cranks over six decades of size), every closed-form output is within
    BOUND_ULPS * eps * (kappa + |y|) of the 50-digit answer for the same double inputs."""
    rng = random.Random({"crank": 11, "rocker": 12, "slider": 13}[kind])
    worst = 0.0
    with mp.workdps(50):
        for x, fn in _limit_cases(kind, rng, 60):
            got, kinds = _computed(kind, x)
            exact = fn(*[mp.mpf(v) for v in x])
            assert got, (kind, x)
            for sol in got:
                ref = min(exact, key=lambda s: _distance(s, sol, kinds))
                kappa = _conditioning(fn, [mp.mpf(v) for v in x], ref, kinds)
                for j, k in enumerate(kinds):
                    err = abs(_wrap(sol[j] - ref[j])) if k == "angle" else abs(sol[j] - ref[j])
                    allowed = EPS * (kappa[j] + abs(ref[j]))
                    ratio = float(err / allowed)
                    worst = max(worst, ratio)
                    assert ratio <= BOUND_ULPS, (kind, x, j, float(err), float(allowed))
    assert worst > 0.0  # the comparison saw rounding at all


def test_the_closed_form_reference_near_limits_is_accurate_to_its_conditioning(cli):
    """The JSON reference, the "(closed form ...)" line and the true-error column come
    from the closed form at the driver value the loops are solved at. It was evaluated at
    the driver rounded to 12 digits and printed 2.3e-5 deg (4e-7 rad) off the exact answer
    at theta2 = 112.02431283704 (1e-12 deg inside the limit 112.0243128370421...)."""
    with mp.workdps(50):
        for shown in ("112.02431283704", "112.0243128370421", "112.024312836999", "112.0243118"):
            run = cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--set", f"theta2={shown}",
                      "--format", "json", "--tol", "1e-14")
            assert run.code == 0, run.err
            doc = json.loads(run.out)
            x = [mp.mpf(v) for v in (90.0, 30.0, 60.0, 45.0, 0.0, math.radians(float(shown)))]
            exact = mp_crank(*x)
            for branch, sol in doc["reference"].items():
                got = (math.radians(sol["theta3"]), math.radians(sol["theta4"]))
                ref = min(exact, key=lambda s: _distance(s, got, ("angle", "angle")))
                assert (math.sin(got[1] - got[0]) > 0) == (branch == "open")
                kappa = _conditioning(mp_crank, x, ref, ("angle", "angle"))
                for j in range(2):
                    # + 2 ulps of the degree conversion the JSON carries
                    allowed = BOUND_ULPS * EPS * (kappa[j] + abs(ref[j])) + 4 * EPS * math.pi
                    assert abs(float(_wrap(got[j] - ref[j]))) <= allowed, (shown, branch, j)


# --- one branch rule ------------------------------------------------------------------------

def _by_rocker_file(m2, theta4_deg):
    """The rocker-driven file of the same linkage at theta4 (deg)."""
    m4 = load(SAMPLES / "fourbar_me581_theta4.toml")
    return m4.with_values({k: m2.parameters[k].value for k in ("r1", "r2", "r3", "r4")} | {
        m4.driver.name: theta4_deg}, {})


def test_branch_labels_of_theta4_driven_fourbars_follow_the_configuration_rule():
    """One rule for a configuration, whatever the driver: open where sin(theta4 - theta3)
    > 0 (README). The same configuration once was "open" in fourbar_me581.toml and
    "crossed" in fourbar_me581_theta4.toml (about 200 of the random positions tried).
    Both rocker-driven assemblies stay in the closed form under distinct keys."""
    from linkage.kinematics.continuation import Solver

    rng = random.Random(18)
    base = load(SAMPLES / "fourbar_me581.toml")
    checked = shared = 0
    for _ in range(150):
        lengths = {"r2": rng.uniform(15, 60), "r3": rng.uniform(30, 90), "r4": rng.uniform(20, 80)}
        m2 = base.with_values(lengths, {})
        theta2 = rng.uniform(-180, 180)
        ref2 = m2.with_values({"theta2": theta2}, {}).problem().reference()
        for branch, sol in (ref2 or {}).items():
            t3, t4 = sol["theta3"], sol["theta4"]
            if abs(math.sin(math.radians(t4 - t3))) < 1e-9:
                continue
            rule = "open" if math.sin(math.radians(t4 - t3)) > 0 else "crossed"
            assert branch == rule
            m4 = _by_rocker_file(m2, t4)
            ref4 = m4.problem().reference()
            assert len(ref4) == 2 and len(set(ref4)) == 2
            shared += any(k.endswith(MIRROR) for k in ref4)
            key = min(ref4, key=lambda k: abs(math.remainder(ref4[k]["theta2"] - theta2, 360.0)))
            assert abs(math.remainder(ref4[key]["theta2"] - theta2, 360.0)) < 1e-6
            assert key.removesuffix(MIRROR) == rule, (lengths, theta2, branch, key)
            # the sweep's label of that solution, in each file
            for m, q in ((m2, (t3, t4)), (m4, (ref4[key]["theta2"], ref4[key]["theta3"]))):
                solver = Solver(m, "newton", 1e-12, 50)
                assert solver.branch([math.radians(v) for v in q], 1.0) == rule
            checked += 1
    assert checked > 100 and shared > 10


def test_branch_open_picks_the_same_assembly_in_both_files(cli):
    """`solve --branch open` at the same configuration: fourbar_me581.toml at theta2 = 65
    and fourbar_me581_theta4.toml at that position's theta4 give the same linkage."""
    run2 = cli("solve", str(SAMPLES / "fourbar_me581.toml"), "--branch", "open", "--format", "json")
    sol2 = json.loads(run2.out)["solution"]
    run4 = cli("solve", str(SAMPLES / "fourbar_me581_theta4.toml"), "--set",
               f"theta4={sol2['theta4']!r}", "--branch", "open", "--format", "json")
    assert run4.code == 0, run4.err
    doc4 = json.loads(run4.out)
    assert doc4["branch"] == "open"
    assert abs(doc4["solution"]["theta2"] - 65.0) < 1e-9
    assert abs(doc4["solution"]["theta3"] - sol2["theta3"]) < 1e-9


def test_both_rocker_driven_assemblies_of_one_label_are_selectable(cli):
    """At the ME581's own theta4 both assemblies are open: `--branch open` starts from the
    one with sin(theta3 - theta2) < 0 (theta2 = 65 deg), `--branch "open (mirror)"` from
    the other; `--branch crossed` names the assemblies there."""
    path = str(SAMPLES / "fourbar_me581_theta4.toml")
    plain = json.loads(cli("solve", path, "--branch", "open", "--format", "json").out)
    mirror = json.loads(cli("solve", path, "--branch", "open" + MIRROR, "--format", "json").out)
    assert plain["branch"] == mirror["branch"] == "open"
    assert abs(plain["solution"]["theta2"] - 65.0) < 1e-9
    assert abs(mirror["solution"]["theta2"] - 65.0) > 1.0
    for doc in (plain, mirror):
        t3 = math.radians(doc["solution"]["theta3"])
        assert math.sin(math.radians(114.827770616) - t3) > 0
    run = cli("solve", path, "--branch", "crossed")
    assert run.code == 2 and "assemblies: open, open (mirror)" in run.err


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_rocker_driven_sweeps_label_each_position_by_its_configuration(branch):
    """Every solved position of a rocker-driven sweep carries the label of its own
    configuration. The sweep follows one assembly by its signs (issue 19): the one that
    carries the requested name where the name first appears; along it the label turns
    from open to crossed, every position where the linkage assembles is solved on it
    (none off_branch, none jumping to the mirror assembly); the batch engine says the same."""
    from linkage.kinematics.batch import CODE_STATUS, batch_sweep
    from linkage.kinematics.sweep import sweep

    m = load(SAMPLES / "fourbar_me581_theta4.toml")
    values = [float(v) for v in range(100, 260)]
    result = sweep(m, values, branch=branch)
    first, assembly = None, set()
    for p in result.positions:
        ref = fourbar_positions(90.0, 30.0, 60.0, 45.0, 0.0, theta4=math.radians(p.input))
        labels = {k.removesuffix(MIRROR) for k in ref}
        if p.status != "converged":
            assert not ref and p.status == "no_solution", p
            continue
        side = math.sin(math.radians(p.input - p.solution["theta3"]))
        assert p.branch == ("open" if side > 0 else "crossed"), p
        # one of the reference's two assemblies, on one side of O2-B throughout
        near = [s for s in ref.values() if abs(math.remainder(
            math.degrees(s["theta2"]) - p.solution["theta2"], 360.0)) < 1e-7]
        assert len(near) == 1, p
        t2, t4 = math.radians(p.solution["theta2"]), math.radians(p.input)
        bx, by = 90.0 + 45.0 * math.cos(t4), 45.0 * math.sin(t4)
        assembly.add(math.cos(t2) * by - math.sin(t2) * bx > 0)
        if first is None and branch in labels:
            first = p
    assert len(assembly) == 1
    assert first is not None and first.branch == branch
    assert result.summary.get("converged") and not result.summary.get("off_branch")
    assert {p.branch for p in result.positions if p.solution} == {"open", "crossed"}
    assert not [t for t in result.toggles if 105 < t < 255]
    batch = batch_sweep(m, values, branch=branch)
    assert [CODE_STATUS[int(c)] for c in batch.status] == [p.status for p in result.positions]
    # (the scan follows a branch by its signs, as issue 19 asks: tests/test_derived_scan.py)


# --- closed_form claims ---------------------------------------------------------------------

CLAIM = """
name = "claims a different ground"
length_unit = "mm"
closed_form = "fourbar"
[parameters]
r1 = {{ value = 100, unit = "mm" }}
r2 = {{ value = 10, unit = "mm" }}
r3 = {{ value = 10, unit = "mm" }}
r4 = {{ value = 10, unit = "mm" }}
theta1 = {{ value = 0, unit = "deg" }}
[driver]
name = "theta2"
value = 60
unit = "deg"
[unknowns]
theta3 = {{ guess = 40, unit = "deg" }}
theta4 = {{ guess = 100, unit = "deg" }}
[[loops]]
name = "L"
vectors = [{vectors}]
"""
TRUE_LOOP = ('{ length = "r2", angle = "theta2" }, { length = "r3", angle = "theta3" }, '
             '{ length = "r4", angle = "theta4", sign = -1 }, { length = "r1", angle = "theta1", sign = -1 }')


def test_a_false_closed_form_claim_is_refused(cli, tmp_path):
    """r1 = 100 claimed while the loop's ground is a literal 15: the claim has no assembly
    at the probe angles, so it once passed, and `sweep` said no_solution everywhere where
    the same file without the claim assembles. Now refused at load, one line, exit 2."""
    lie = CLAIM.format(vectors=TRUE_LOOP.replace('{ length = "r1", angle = "theta1", sign = -1 }',
                                                 '{ length = 15, angle = 0, sign = -1 }'))
    path = tmp_path / "lie.toml"
    path.write_text(lie)
    with pytest.raises(ParseError, match="does not describe"):
        load(path)
    for command in ("solve", "sweep"):
        run = cli(command, str(path))
        assert run.code == 2, run.err
        lines = [ln for ln in run.err.splitlines() if ln.strip()]
        assert len(lines) == 1 and lines[0].startswith("error: ") and "closed_form" in lines[0], run.err
    honest = tmp_path / "honest.toml"
    honest.write_text(lie.replace('closed_form = "fourbar"\n', ""))
    assert cli("sweep", str(honest), "--from", "0", "--to", "90", "--step", "30").code == 0


@pytest.mark.parametrize("vectors", [
    TRUE_LOOP,
    # the same loop walked the other way round (every sign flipped), and started elsewhere
    '{ length = "r2", angle = "theta2", sign = -1 }, { length = "r3", angle = "theta3", sign = -1 }, '
    '{ length = "r4", angle = "theta4" }, { length = "r1", angle = "theta1" }',
    '{ length = "r4", angle = "theta4", sign = -1 }, { length = "r1", angle = "theta1", sign = -1 }, '
    '{ length = "r2", angle = "theta2" }, { length = "r3", angle = "theta3" }',
    # the ground written as the literal it equals
    TRUE_LOOP.replace('{ length = "r1", angle = "theta1", sign = -1 }',
                      '{ length = 100, angle = 0, sign = -1 }'),
])
def test_a_true_closed_form_claim_is_an_identity_of_the_loops(tmp_path, vectors):
    path = tmp_path / "ok.toml"
    path.write_text(CLAIM.format(vectors=vectors).replace("r2 = { value = 10", "r2 = { value = 95"))
    assert load(path).closed_form == "fourbar"


@pytest.mark.parametrize("vectors", [
    TRUE_LOOP.replace('{ length = "r3", angle = "theta3" }',
                      '{ length = "r3", angle = "theta3", offset = 1e-3 }'),
    TRUE_LOOP.replace('sign = -1 }', 'sign = 1 }', 1),
    TRUE_LOOP.replace('{ length = "r4", angle = "theta4", sign = -1 }',
                      '{ length = "r4", angle = "theta4" }'),
])
def test_a_claim_that_differs_anywhere_is_refused(tmp_path, vectors):
    path = tmp_path / "no.toml"
    path.write_text(CLAIM.format(vectors=vectors))
    with pytest.raises(ParseError, match="does not describe"):
        load(path)


def test_every_sample_claim_still_holds():
    for path in sorted(SAMPLES.glob("*.toml")):
        m = load(path)
        if m.closed_form:
            assert m.closed_form in ("fourbar", "slider_crank")


# --- twins ----------------------------------------------------------------------------------

def _random_links(rng, n):
    scale = 10.0 ** rng.uniform(-3, 3, n)
    return [scale * 10.0 ** rng.uniform(-1, 1, n) for _ in range(4)]


def _close(a, b, ulps=4.0):
    a, b = np.asarray(a, float), np.asarray(b, float)
    both_nan = np.isnan(a) & np.isnan(b)
    return both_nan | (np.abs(a - b) <= ulps * np.spacing(np.maximum(np.maximum(np.abs(a), np.abs(b)), 1.0)))


def test_the_circle_intersection_twin_is_its_scalar_rule():
    """IEEE arithmetic only (+ - * / sqrt, sorting): bit for bit."""
    rng = np.random.default_rng(1)
    d, r, rho, _ = _random_links(rng, 4000)
    a, h, ok = assembly.triangle_np(d, r, rho)
    for i in range(len(d)):
        got = assembly.triangle(float(d[i]), float(r[i]), float(rho[i]))
        assert (got is not None) == bool(ok[i])
        if got is not None:
            assert got == (a[i], h[i])


def test_the_circle_intersection_twin_orders_by_comparisons_as_sorted_does():
    """triangle_np orders its three distances by comparisons (descending_np), not a sort:
    the same values as sorted(..., reverse=True) wherever there is no NaN (ties, zeros,
    infinities, scalars beside arrays), and with a NaN the twin still refuses the
    position as the scalar rule does."""
    rng = np.random.default_rng(3)
    pool = np.array([0.0, 1.0, 2.0, 3.0, 1e-300, 1e300, np.inf, 0.5])
    p, q, s = (pool[rng.integers(0, len(pool), 5000)] for _ in range(3))
    got = np.stack(assembly.descending_np(p, q, s))
    assert np.array_equal(got, -np.sort(-np.stack((p, q, s)), axis=0))
    x, y, z = assembly.descending_np(np.array([2.0, 5.0, 0.5]), 3.0, 1.0)  # two scalars
    assert [list(v) for v in (x, y, z)] == [[3.0, 5.0, 3.0], [2.0, 3.0, 1.0], [1.0, 1.0, 0.5]]
    for bad in ([np.nan, 1.0, 1.0], [1.0, np.nan, 1.0], [1.0, 1.0, np.nan], [np.nan] * 3,
                [np.inf, 1.0, 1.0], [1.0, np.inf, np.inf], [1.0, 1.0, 0.0], [1.0, 0.0, 0.0]):
        a, h, ok = assembly.triangle_np(*(np.array([v]) for v in bad))
        want = assembly.triangle(*bad)
        assert bool(ok[0]) == (want is not None), bad
        if want is None:
            assert np.isnan(h[0]), bad
        else:
            assert np.array_equal([a[0], h[0]], want, equal_nan=True), bad


@pytest.mark.parametrize("kind", ["crank", "rocker", "slider"])
def test_the_closed_form_position_twins_are_their_scalar_rules(kind):
    """Same operations; numpy's sin/cos/atan2 may differ from the C library's by an ulp,
    which a position far from its limits carries as an ulp or two."""
    rng = np.random.default_rng(2)
    r1, r2, r3, r4 = _random_links(rng, 3000)
    t1 = np.where(rng.random(3000) < 0.5, 0.0, rng.uniform(-np.pi, np.pi, 3000))
    drv = rng.uniform(-np.pi, np.pi, 3000)
    if kind == "crank":
        sols, ok = assembly.fourbar_by_crank_np(r1, r2, r3, r4, t1, drv)
    elif kind == "rocker":
        sols, ok = assembly.fourbar_by_rocker_np(r1, r2, r3, r4, t1, drv)
    else:
        e = rng.uniform(-1, 1, 3000) * r4
        sols, ok = assembly.slider_crank_np(r2, r3, e, drv)
    seen = 0
    for i in range(3000):
        if kind == "slider":
            got = assembly.slider_crank(float(r2[i]), float(r3[i]), float(e[i]), float(drv[i]))
        else:
            fn = assembly.fourbar_by_crank if kind == "crank" else assembly.fourbar_by_rocker
            got = fn(*(float(v[i]) for v in (r1, r2, r3, r4, t1, drv)))
        assert bool(got) == bool(ok[i])
        if not got:
            continue
        h = min(abs(got[0][0] - got[1][0]), 2 * math.pi - abs(got[0][0] - got[1][0]))
        if h < 1e-6:  # within 1e-12 of a limit the last ulps of sin and cos are amplified
            continue
        for side, (x, y) in zip(got, sols):
            assert _close(side[0], x[i], 64) and _close(side[1], y[i], 64), (kind, i, side, x[i], y[i])
        seen += 1
    assert seen > 300


def test_the_branch_rule_twins_are_their_scalar_rules():
    rng = np.random.default_rng(3)
    t3, t4, t2 = (rng.uniform(-7, 7, 5000) for _ in range(3))
    away = np.abs(np.sin(t4 - t3)) > 1e-12
    scalar = [assembly.is_open(a, b) for a, b in zip(t3[away], t4[away])]
    assert (assembly.is_open_np(t3, t4)[away] == scalar).all()
    assert (assembly.slider_is_open_np(t3) == [assembly.slider_is_open(a) for a in t3]).all()
    r1, r2, r3, _ = _random_links(rng, 5000)
    t1 = rng.uniform(-np.pi, np.pi, 5000)
    got = assembly.rocker_angle_np(r1, r2, r3, t1, t2, t3)
    want = [assembly.rocker_angle(*(float(v[i]) for v in (r1, r2, r3, t1, t2, t3))) for i in range(5000)]
    assert _close(got, want, 64).all()
    # every engine's label of the same solution: the sweep's rule, the batch's columns
    from linkage.kinematics.batch import _on_branch_columns
    for name in ("fourbar_me581.toml", "fourbar_me581_theta4.toml", "slider_crank.toml", "crank_rocker.toml"):
        m = load(SAMPLES / name)
        names = [u.name for u in m.unknowns]
        cols = [np.degrees(rng.uniform(-np.pi, np.pi, 400)) if u.kind == "angle" else rng.uniform(-9, 9, 400)
                for u in m.unknowns]
        drivers = np.zeros(400)  # (a crank's value does not enter the open/crossed rule)
        if m.driver.name == "theta4":  # the rocker's angle that closes each configuration
            v = {k: q.value for k, q in m.parameters.items()}
            drivers = assembly.rocker_angle_np(v["r1"], v["r2"], v["r3"], v["theta1"],
                                               np.radians(cols[0]), np.radians(cols[1]))
        # the scalar rule, written here: open where sin(theta4 - theta3) > 0 (four-bar, theta4
        # the rocker's, the driver where it drives), cos(theta3) > 0 (slider-crank)
        t3 = np.radians(cols[names.index("theta3")])
        if name == "slider_crank.toml":
            scalar = np.array([math.cos(a) > 0.0 for a in t3])
        else:
            t4 = drivers if m.driver.name == "theta4" else np.radians(cols[names.index("theta4")])
            scalar = np.array([math.sin(b - a) > 0.0 for a, b in zip(t3, t4)])
        assert (scalar == [m.derivation.words_of([math.radians(c[i]) if u.kind == "angle" else c[i]
                                                  for c, u in zip(cols, m.unknowns)], float(drivers[i]))
                           == ["open"] for i in range(400)]).all(), name
        vector = _on_branch_columns(m, cols, names, np.ones(400), "open", drivers)
        assert (scalar == vector).all(), name


def test_the_transmission_angle_twin_is_its_scalar_rule():
    rng = np.random.default_rng(4)
    t3, t4 = rng.uniform(-1000, 1000, 5000), rng.uniform(-1000, 1000, 5000)
    got = transmission_np(t3, t4)
    assert [float(g) for g in got] == [transmission(float(a), float(b)) for a, b in zip(t3, t4)]
    assert ((got >= 0) & (got <= 180)).all()


def test_the_grashof_twin_is_its_scalar_rule():
    rng = np.random.default_rng(5)
    links = _random_links(rng, 3000)
    # and change points: s + l = p + q exactly
    ties = rng.uniform(1, 10, (4, 200))
    ties[3] = ties[0] + ties[1] - ties[2]
    ties = ties[:, ties[3] > 0]
    r = [np.concatenate((a, b)) for a, b in zip(links, ties)]
    got = grashof_np(*r)
    assert list(got) == [grashof(*(float(v[i]) for v in r)) for i in range(len(r[0]))]
    assert "change point" in set(got) and "triple rocker" in set(got)


def test_parse_still_accepts_slider_claims():
    doc = {"name": "s", "length_unit": "mm", "closed_form": "slider_crank",
           "parameters": {"r2": {"value": 40, "unit": "mm"}, "r3": {"value": 120, "unit": "mm"},
                          "e": {"value": 10, "unit": "mm"}},
           "driver": {"name": "theta2", "value": 30, "unit": "deg"},
           "unknowns": {"theta3": {"guess": 0, "unit": "deg"}, "s": {"guess": 150, "unit": "mm"}},
           "loops": [{"name": "L", "vectors": [{"length": "r2", "angle": "theta2"},
                                               {"length": "r3", "angle": "theta3"},
                                               {"length": "s", "angle": 0, "sign": -1},
                                               {"length": "e", "angle": 90, "sign": -1}]}]}
    m = parse_mechanism(doc)
    ref = slider_crank_positions(40.0, 120.0, 10.0, math.radians(30.0))
    assert set(ref) == {"open", "crossed"} and m.closed_form == "slider_crank"

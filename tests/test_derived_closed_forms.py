"""The derived closed forms (linkage.problems.derive, dyads) checked independently.

Every reference is worked out here in mpmath at 50 digits (tests/derived_reference.py):
the loops evaluated term by term, Newton polished by mpmath.findroot, and the textbook
formulas (two circles, a line and a circle, Cramer) written out again. Nothing is
compared with the code under test. Figures (worst closed form vs polished Newton, the
worst near-limit ratio to the answer's own sensitivity) are printed by
``python -m pytest -q -s tests/test_derived_closed_forms.py -k figures``.
"""

from __future__ import annotations

import math
import random
from pathlib import Path
from typing import Any

import mpmath
import numpy as np
import pytest
from mpmath import mpf

import derived_reference as ref
from linkage.kinematics.loading import load
from linkage.problems import derive, dyads, find_steps, steps
from ulps import assert_ulps

SAMPLES = Path(__file__).resolve().parent.parent / "sample_inputs"
EPS = 2.0 ** -52
FIGURES: dict[str, Any] = {}


@pytest.fixture(autouse=True, scope="module")
def _print_figures() -> Any:
    """The worst figures of the run, printed at the end (seen with ``-s``)."""
    yield
    for key, (value, where) in sorted(FIGURES.items()):
        print(f"\n{key}: {value} ({where})")


def _worst(key: str, value: Any, where: str) -> None:
    old = FIGURES.get(key)
    if old is None or value > old[0]:
        FIGURES[key] = (value, where)


# --- 1. 200 random mechanisms, both branches --------------------------------------------------

def _assembled(rng: random.Random, case: ref.Case, lo: float = -180.0, hi: float = 180.0,
               want: int = 2) -> tuple[ref.Case, Any] | None:
    """The case at a random driver value where it assembles away from a limit (the
    discriminant, relative, above 1e-6: nearer ones are section 2's)."""
    for _ in range(60):
        c, m = ref.with_driver_value(case, round(rng.uniform(lo, hi), 6))
        sols, disc = ref.reference(c, ref.Inputs(m))
        if len(sols) >= want and disc > 1e-6:
            return c, m
    return None


def _mechanisms() -> list[tuple[ref.Case, Any, ref.Sol | None]]:
    """200 mechanisms at a driver value each: 40 four-bars x 3 drivers (one configuration,
    given as the third item, driven by its input, coupler and output angle), 30 offset
    slider-cranks, 30 inverted slider-cranks (half with a perpendicular offset), 15 Watt
    six-bars and 5 of the two-loop pair."""
    rng = random.Random(19)
    out: list[tuple[ref.Case, Any, ref.Sol | None]] = []
    fourbars = 0
    while fourbars < 40:
        case, _ = ref.make_fourbar(rng)
        got = _assembled(rng, case)
        if got is None:
            continue
        c, m = got
        config = ref.reference(c, ref.Inputs(m))[0][rng.randrange(2)]
        trio = [(c, m, config)]
        for role in ("cp", "out"):
            name = c.roles["angles"][role]
            other = c.with_driver(name, math.degrees(float(config[name])))
            trio.append((other, other.mechanism(), config))
        if all(ref.reference(x, ref.Inputs(mm))[1] > 1e-6 for x, mm, _ in trio):
            out += trio
            fourbars += 1
    for make, count in ((ref.make_slider, 30), (lambda r: ref.make_inverted(r, False), 15),
                        (lambda r: ref.make_inverted(r, True), 15), (ref.make_watt, 15),
                        (ref.make_pair, 5)):
        made = 0
        while made < count:
            case, _ = make(rng)
            got = _assembled(rng, case, want=4 if case.family == "pair" else 2)
            if got is not None:
                out.append((*got, None))
                made += 1
    assert len(out) == 200
    return out


with mpmath.workdps(ref.DPS):
    MECHANISMS = _mechanisms()


def _scale(m: Any) -> float:
    return max(abs(q.value) for q in m.parameters.values() if q.kind == "length")


def _words(case: ref.Case, inp: ref.Inputs, sol: ref.Sol) -> str | None:
    """The conventional name of a configuration, computed here: open where
    sin(theta_out - theta_coupler) > 0 for a four-bar loop (read input, coupler, output);
    a slider-crank open where the coupler points the way the slide grows."""
    ang = case.roles.get("angles", {})

    def fourbar(cp: str, out: str, off_cp: Any = 0, off_out: Any = 0) -> str:
        return "open" if mpmath.sin(sol[out] + off_out - sol[cp] - off_cp) > 0 else "crossed"

    if case.family == "fourbar":
        return fourbar(ang["cp"], ang["out"])
    if case.family == "watt":
        return f"{fourbar(ang['cp'], ang['out'])}/{fourbar(ang['cp2'], ang['out2'])}"
    if case.family == "slider":
        _, phi = inp.term(0, 2, {case.roles["s"]: 1})
        return "open" if mpmath.cos(sol[ang["cp"]] - phi) > 0 else "crossed"
    return None


def _check(case: ref.Case, m: Any, where: str) -> list[tuple[str, ref.Sol]]:
    """Section 1's claims for one mechanism at its driver value; returns (name, solution)."""
    inp = ref.Inputs(m)
    refs, _ = ref.reference(case, inp)
    der = m.derivation
    assert der.complete, where
    d = m.driver.value
    sols = der.solutions(d)
    assert len(sols) == len(refs), f"{where}: {len(sols)} solutions, the formulas give {len(refs)}"
    scale = _scale(m)
    matched = set()
    named = []
    for signs, q in sols:
        assert all(math.isfinite(x) for x in q), where
        sol = ref.as_sol(m, q)
        for li in range(len(m.loops)):
            res = abs(inp.residual(li, sol)) / inp.size(li, sol) / EPS
            _worst("residual_ulps", float(res), where)
            assert res <= 16, f"{where}: loop {li + 1} residual {float(res):.1f} ulps of its size"
        root = ref.polish(inp, sol)
        dn = ref.distance(m, root, q, scale)
        _worst("newton", float(dn), where)
        assert dn <= 1e-12, f"{where}: {signs} is {float(dn):.3g} from Newton polished"
        dists = [ref.distance(m, r, root, scale) for r in refs]
        best = min(range(len(refs)), key=lambda i: dists[i])
        assert dists[best] < mpf(10) ** -40, f"{where}: Newton's root is not one of the formulas'"
        matched.add(best)
        for u in m.unknowns:  # lengths relative to themselves too (the brief's measure)
            if u.kind == "length" and abs(root[u.name]) > 0:
                rel = abs(root[u.name] - q[[x.name for x in m.unknowns].index(u.name)]) / abs(root[u.name])
                _worst("length_rel_self", float(rel), where)
        assert der.signs_of(q, d) == signs, where
        want = _words(case, inp, {**root, m.driver.name: mpf(d)})
        name = der.name_of(q, d)
        if want is not None:
            assert name == want, f"{where}: {signs} is named {name!r}, the rule says {want!r}"
        named.append((name, root))
    assert len(matched) == len(refs), f"{where}: two closed-form solutions are one configuration"
    if case.family == "inverted":  # no conventional name: "+" is the larger slide
        by_name = {n: r[case.roles["s"]] for n, r in named}
        assert set(by_name) == {"+", "-"} and by_name["+"] > by_name["-"], where
    # the names as named_solutions gives them: a second of one name is its mirror
    keys = []
    for name, _ in named:
        key = name
        while key in keys:
            key += " (mirror)"
        keys.append(key)
    assert list(der.named_solutions(d)) == keys, where
    return named


def test_random_mechanisms_closed_form_is_newton_polished() -> None:
    with mpmath.workdps(ref.DPS):
        shared: dict[int, list[str]] = {}
        for k, (case, m, config) in enumerate(MECHANISMS):
            where = f"{case.family} {k}" + (f" driven by {case.roles['driven']}" if config else "")
            named = _check(case, m, where)
            if config is None:
                continue
            # the trio's shared configuration: its joints are where all three angles agree
            angles = case.roles["angles"].values()
            d = m.driver.name
            same = [n for n, r in named
                    if max(abs(ref.wrap((mpf(m.driver.value) if a == d else r[a]) - config[a]))
                           for a in angles) < 1e-9]
            assert len(same) == 1, f"{where}: the shared configuration is not one of its solutions"
            shared.setdefault(k // 3, []).append(same[0])
        for trio, names in shared.items():
            config = MECHANISMS[3 * trio][2]
            want = _words(MECHANISMS[3 * trio][0], None, config)  # type: ignore[arg-type]
            assert names == [want] * 3, f"four-bar {trio}: one configuration named {names}, rule {want}"


# --- 2. near limits: accurate to the answer's own sensitivity --------------------------------

BUMP = mpf("1e-16")


def _near_limit_cases() -> list[tuple[ref.Case, Any]]:
    """Ten four-bar trios (each driver), the slider-cranks and the offset inverted ones."""
    picked = [(c, m) for c, m, _ in MECHANISMS[:30]]
    picked += [(c, m) for c, m, _ in MECHANISMS[120:150:3]]  # slider-cranks
    picked += [(c, m) for c, m, _ in MECHANISMS[165:180:2]]  # inverted, with an offset
    return picked


def _sensitivity(case: ref.Case, m: Any, driver: float, exact: ref.Sol, scale: float) -> list[Any]:
    """How far each unknown of ``exact`` moves when the inputs move by 1e-16 relative:
    the sum over inputs of the larger move of the two directions (the first-order bound
    for every input moving at once)."""
    total = [mpf(0)] * len(m.unknowns)
    for key in ref.Inputs(m, driver=driver).keys():
        worst = [mpf(0)] * len(m.unknowns)
        for factor in (1 + BUMP, 1 - BUMP):
            sols, _ = ref.reference(case, ref.Inputs(m, (key, factor), driver))
            near = min(sols, key=lambda s: ref.distance(m, s, exact, scale))
            for j, u in enumerate(m.unknowns):
                move = near[u.name] - exact[u.name]
                move = abs(ref.wrap(move)) if u.kind == "angle" else abs(move)
                worst[j] = max(worst[j], move)
        total = [t + w for t, w in zip(total, worst)]
    return total


def _ratios(case: ref.Case, m: Any, driver: float) -> list[tuple[float, str]]:
    """Each unknown's error over its sensitivity, for every closed-form solution at
    ``driver`` (the floor: half an ulp of the answer, what a double can hold)."""
    scale = _scale(m)
    exact, _ = ref.reference(case, ref.Inputs(m, driver=driver))
    got = m.derivation.solutions(driver)
    params = {k: v.value for k, v in m.parameters.items()}
    where = f"{case.family} {params} driven by {case.roles.get('driven', 'in')} at {driver!r}"
    assert len(got) == len(exact), f"{where}: {len(got)} solutions, exact {len(exact)}"
    out = []
    for _, q in got:
        sol = min(exact, key=lambda s: ref.distance(m, s, q, scale))
        sens = _sensitivity(case, m, driver, sol, scale)
        for j, u in enumerate(m.unknowns):
            err = sol[u.name] - q[j]
            err = abs(ref.wrap(err)) if u.kind == "angle" else abs(err)
            ratio = float(err / max(sens[j], mpf(math.ulp(q[j])) / 2))
            out.append((ratio, f"{where}: {u.name} off by {float(err):.3g}, sensitivity "
                               f"{float(sens[j]):.3g}"))
    return out


def test_near_limits_within_the_answers_own_sensitivity() -> None:
    """Within 1e-9 deg and 1e-6 deg of every limit position (computed here in mpmath),
    on both sides, the closed form is within twice its own sensitivity of the exact
    answer (a naive acos of the law of cosines measures 3.2 on the same four-bars), and
    on the far side it assembles nowhere, as the formula says."""
    ratios: list[tuple[float, str]] = []
    with mpmath.workdps(ref.DPS):
        for case, m in _near_limit_cases():
            for limit in ref.limits(case, ref.Inputs(m)):
                for delta_deg in (1e-9, 1e-6):
                    for side in (1, -1):
                        driver = float(limit + side * mpmath.radians(delta_deg))
                        ratios += [(r, f"{w} ({delta_deg} deg from a limit)")
                                   for r, w in _ratios(case, m, driver)]
    worst = max(ratios)
    FIGURES["near_limit"] = (worst[0], f"{worst[1]}; {len(ratios)} values")
    assert len(ratios) > 500
    assert worst[0] <= 2, worst[1]


# --- 3. the classical cases against formulas written here; the numpy twins ------------------

def _pairs(rng: random.Random, n: int, big: float = 100.0) -> list[tuple[float, float]]:
    return [(rng.uniform(-big, big), rng.uniform(-big, big)) for _ in range(n)]


def _z(p: tuple[float, float]) -> Any:
    return mpmath.mpc(p[0], p[1])


def _ang_err(exact: Any, got: float) -> float:
    return float(abs(ref.wrap(exact - got)))


def _cases_two_angles(rng: random.Random, n: int) -> list[tuple[Any, ...]]:
    return list(zip(_pairs(rng, n), _pairs(rng, n), _pairs(rng, n)))


def test_two_angles_is_the_circle_intersection() -> None:
    """P e^(ia) + Q e^(ib) + K = 0: X = P e^(ia) at |P| from 0 and |Q| from -K, sigma = +1
    on the left of 0 -> -K; a = arg(X / P), b = arg((-K - X) / Q)."""
    rng = random.Random(3)
    worst, checked = 0.0, 0
    with mpmath.workdps(ref.DPS):
        for p, q, k in _cases_two_angles(rng, 400):
            pts, disc = ref.circles(mpmath.mpc(0), abs(_z(p)), -_z(k), abs(_z(q)))
            for sigma, x in zip((1.0, -1.0), pts or [None, None]):
                got = dyads.two_angles(p, q, k, sigma)
                if x is None:
                    assert got is None or disc > -1e-14
                    continue
                if disc < 1e-6:
                    continue  # near tangency: section 2 measures those against conditioning
                a = _ang_err(mpmath.arg(x / _z(p)), got[0])
                b = _ang_err(mpmath.arg((-_z(k) - x) / _z(q)), got[1])
                worst = max(worst, a, b)
                checked += 1
    FIGURES["dyad two angles"] = (worst, f"{checked} solutions")
    assert checked > 300 and worst <= 1e-13


def test_a_line_and_a_circle_cases() -> None:
    """e^(ia) (P + s D) + K = 0: |s + P/D| = |K|/|D|, a = arg(-K / (P + s D)); and
    P e^(ia) + s E + K = 0: |s + K/E| = |P|/|E|, a = arg(-(K + s E) / P); sigma = +1 is the
    larger s."""
    rng = random.Random(4)
    worst_a = worst_s = 0.0
    checked = 0
    with mpmath.workdps(ref.DPS):
        for p, dd, k in _cases_two_angles(rng, 400):
            zp, zd, zk = _z(p), _z(dd), _z(k)
            for fn, z, r, angle_of in (
                    (dyads.angle_and_its_length, zp / zd, abs(zk) / abs(zd),
                     lambda s, zp=zp, zd=zd, zk=zk: mpmath.arg(-zk / (zp + s * zd))),
                    (dyads.angle_and_other_length, zk / zd, abs(zp) / abs(zd),
                     lambda s, zp=zp, zd=zd, zk=zk: mpmath.arg(-(zk + s * zd) / zp))):
                roots, disc = ref.line_circle(z, r)
                for sigma, s in zip((1.0, -1.0), roots or [None, None]):
                    got = fn(p, dd, k, sigma)
                    if s is None:
                        assert got is None or disc > -1e-14
                        continue
                    if disc < 1e-6:
                        continue
                    worst_a = max(worst_a, _ang_err(angle_of(s), got[0]))
                    worst_s = max(worst_s, float(abs(s - got[1]) / max(abs(s), r)))
                    checked += 1
    FIGURES["dyad line-circle"] = ((worst_a, worst_s), f"{checked} solutions (rad, relative)")
    assert checked > 600 and worst_a <= 1e-13 and worst_s <= 1e-13


def test_two_lengths_is_cramer() -> None:
    rng = random.Random(5)
    worst = 0.0
    with mpmath.workdps(ref.DPS):
        for e, f, k in _cases_two_angles(rng, 300):
            ze, zf, zk = _z(e), _z(f), _z(k)
            det = ze.real * zf.imag - ze.imag * zf.real
            s = -(zk.real * zf.imag - zk.imag * zf.real) / det
            t = -(ze.real * zk.imag - ze.imag * zk.real) / det
            assert abs(s * ze + t * zf + zk) < mpf(10) ** -40
            got = dyads.two_lengths(e, f, k)
            cond = (abs(ze) * abs(zf) / abs(det))  # 1 / sin of the angle between the slides
            worst = max(worst, float(abs(got[0] - s) / (abs(s) + abs(t) + abs(zk)) / cond),
                        float(abs(got[1] - t) / (abs(s) + abs(t) + abs(zk)) / cond))
        assert dyads.two_lengths((1.0, 2.0), (-2.0, -4.0), (1.0, 1.0)) is None  # parallel
    FIGURES["dyad two lengths"] = (worst, "relative, over 1/sin(angle between)")
    assert worst <= 1e-14


ATAN2_ULPS = 4
"""numpy's atan2, sin and cos against math's, each within an ulp or two of the exact value
(tests/ulps.py): measured at most 1 ulp apart with numpy 2.4 on AVX-512 (SVML's atan2),
0 with its SIMD dispatch off."""

TWIN_ULPS = 16
"""A derivation's twins, in ulps of each unknown's size (pi, or the mechanism's size) and of
1 for a margin: each step's atan2 differs by up to ATAN2_ULPS and the later steps carry
that through their own conditioning, measured at most 3.5 (numpy 2.4, AVX-512) at these
fixed random drivers, so 4 x 4."""


def _same(a: Any, b: Any) -> bool:
    """Equal bit for bit, NaN equal to NaN: for what only IEEE arithmetic computes."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a.shape == b.shape and bool(np.all((a == b) | (np.isnan(a) & np.isnan(b))))


def test_twins_agree_with_math_to_a_few_ulps_on_any_cpu() -> None:
    """The twins use norm (sqrt(x^2 + y^2): IEEE operations, the same bits everywhere), cos,
    sin, atan2 and arithmetic. numpy's atan2 (and on some builds sin and cos) is a SIMD
    routine on some CPUs and differs from math's in the last bit, so those to ATAN2_ULPS
    (hypot is avoided for the same reason: numpy's and Python's differ by 1 ulp in about
    0.6% of pairs, hence dyads.norm)."""
    rng = np.random.default_rng(7)
    x, y = rng.uniform(-100, 100, (2, 20000))
    assert _same(dyads.norm_np(x, y), [dyads.norm(a, b) for a, b in zip(x, y)])
    for f in (np.cos, np.sin):
        assert_ulps(f(x), [getattr(math, f.__name__)(a) for a in x], ATAN2_ULPS, what=f.__name__)
    assert_ulps(np.arctan2(x, y), [math.atan2(a, b) for a, b in zip(x, y)], ATAN2_ULPS, what="atan2")


def test_two_angles_with_margin_np_is_its_two_functions_bit_for_bit() -> None:
    """The closed-form sweep's fused two-circle step (one ordering of the three distances,
    the triangle's slack as the margin's numerator) gives two_angles_np's and
    two_angles_margin_np's bits: random circles, K = 0, NaN, exact and near tangency
    (r1 + r2 = d, by a few ulps either way), micrometre and kilometre scales."""
    rng = np.random.default_rng(33)
    n = 4000
    p, q, k = (rng.uniform(-100, 100, (2, n)) for _ in range(3))
    k[:, :5] = 0.0
    p[0, 5:8] = np.nan
    # tangent circles: |K| = |P| + |Q| exactly and a few ulps off
    rp, rq = np.hypot(*p[:, 8:400]), np.hypot(*q[:, 8:400])
    k[0, 8:400], k[1, 8:400] = (rp + rq) * (1.0 + rng.integers(-4, 5, 392) * 2.2e-16), 0.0
    for scale in (1e-6, 1.0, 1e3):
        ps, qs, ks = (tuple(v * scale) for v in (p, q, k))
        for sigma in (1.0, -1.0):
            a, b, ok, margin = dyads.two_angles_with_margin_np(ps, qs, ks, sigma)
            a0, b0, ok0 = dyads.two_angles_np(ps, qs, ks, sigma)
            assert _same(a, a0) and _same(b, b0) and np.array_equal(ok, ok0)
            assert _same(margin, dyads.two_angles_margin_np(ps, qs, ks))


def test_dyad_twins_equal_their_scalar_functions() -> None:
    rng = np.random.default_rng(8)
    n = 3000
    p, q, k = (tuple(rng.uniform(-100, 100, (2, n))) for _ in range(3))
    k[0][:5] = 0.0  # K = 0: concentric circles, an indeterminate angle
    k[1][:5] = 0.0
    at = [((p[0][i], p[1][i]), (q[0][i], q[1][i]), (k[0][i], k[1][i])) for i in range(n)]

    def scalar(fn: Any, *args: Any) -> Any:
        try:
            return fn(*args)
        except ZeroDivisionError:
            return None

    for sigma in (1.0, -1.0):
        for name in ("two_angles", "angle_and_its_length", "angle_and_other_length"):
            a, b, ok = getattr(dyads, name + "_np")(p, q, k, sigma)
            want = [scalar(getattr(dyads, name), *x, sigma) for x in at]
            assert np.array_equal(ok, [w is not None for w in want]), name
            # the angle is atan2's, the last operation: to ATAN2_ULPS of itself; the length
            # (angle_and_*_length) is IEEE arithmetic on the inputs: the same bits
            assert_ulps(np.where(ok, a, np.nan), [w[0] if w else np.nan for w in want], ATAN2_ULPS,
                        what=name)
            b_want = [w[1] if w else np.nan for w in want]
            if name == "two_angles":
                assert_ulps(np.where(ok, b, np.nan), b_want, ATAN2_ULPS, what=name)
            else:
                assert _same(np.where(ok, b, np.nan), b_want), name
        s, ok = dyads.line_circle_np(p, q[0], sigma)
        want = [dyads.line_circle((p[0][i], p[1][i]), q[0][i], sigma) for i in range(n)]
        assert _same(s, [np.nan if w is None else w for w in want])
        assert _same(dyads.line_side_np(p, q[0]),
                     [dyads.line_side((p[0][i], p[1][i]), q[0][i]) for i in range(n)])
    assert _same(dyads.two_angles_margin_np(p, q, k), [dyads.two_angles_margin(*x) for x in at])
    assert _same(dyads.line_circle_margin_np(p, q[0]),
                 [dyads.line_circle_margin((p[0][i], p[1][i]), q[0][i]) for i in range(n)])
    assert _same(dyads.two_angles_side_np(p, k, q[0]), [dyads.two_angles_side(x[0], x[2], q[0][i])
                                                        for i, x in enumerate(at)])
    s, t, ok = dyads.two_lengths_np(p, q, k)
    want = [dyads.two_lengths(*x) for x in at]
    assert _same(s, [w[0] if w else np.nan for w in want]) and _same(t, [w[1] if w else np.nan for w in want])


def _twin_mechanisms() -> list[Any]:
    picks = [m for _, m, _ in MECHANISMS[0:3] + MECHANISMS[120:122] + MECHANISMS[150:152]
             + MECHANISMS[165:167] + MECHANISMS[180:182] + MECHANISMS[195:197]]
    return picks + [load(SAMPLES / f) for f in ("crank_rocker.toml", "watt_sixbar.toml",
                                                "slider_crank.toml", "fourbar_me581_theta4.toml")]


def test_derivation_twins_equal_the_scalar_path() -> None:
    """solve_np, signs_of_np and margins_np against solve, signs_of and margins at 360
    random drivers on every branch (assembled or not): the same positions assemble and the
    same signs, the numbers to TWIN_ULPS."""
    rng = np.random.default_rng(9)
    for m in _twin_mechanisms():
        der = m.derivation
        d = rng.uniform(-math.pi, math.pi, 360)
        if m.driver.kind == "length":
            d = rng.uniform(-2, 2, 360) * m.driver.value
        for signs in der.branches:
            q_np, ok = der.solve_np(d, signs)
            want = [der.solve(float(x), signs) for x in d]
            assert np.array_equal(ok, [w is not None for w in want]), m.name
            rows = np.array([w if w is not None else [np.nan] * der.n for w in want]).T
            for j, u in enumerate(m.unknowns):
                size = math.pi if u.kind == "angle" else m.length_scale
                assert_ulps(q_np[j], rows[j], TWIN_ULPS, size, (m.name, j))
            marg = der.margins_np(d, signs)
            want_m = [der.margins(float(x), signs) for x in d]
            for j in range(len(marg)):
                col = [w[j] for w in want_m]
                # NaN after the first step that does not assemble: the twin goes on with NaN
                # unknowns, so compare where the scalar has a number
                keep = ~np.isnan(col)
                assert_ulps(np.asarray(marg[j])[keep], np.asarray(col)[keep], TWIN_ULPS, 1.0, m.name)
            good = np.nonzero(ok)[0]
            sg = der.signs_of_np([x[good] for x in q_np], d[good])
            for j, col in enumerate(sg):
                assert _same(col, [der.signs_of([x[i] for x in q_np], d[i])[j] for i in good])
                assert np.all(col == signs[j]), m.name


# --- 4. the derivation's structure ----------------------------------------------------------

def _unknowns_in(terms: list[Any], unknowns: set[str]) -> set[str]:
    return {x for t in terms for x in (t.length, t.angle) if isinstance(x, str) and x in unknowns}


def _combined(a: Any, b: Any, c: int) -> list[Any]:
    """Loop a + c * loop b with the vectors that cancel removed (worked out here)."""
    net: dict[Any, float] = {}
    for w, loop in ((1, a), (c, b)):
        for t in loop.vectors:
            key = (t.length, t.angle, t.offset)
            net[key] = net.get(key, 0.0) + w * t.sign
    from linkage.problems.loops import VectorTerm
    return [VectorTerm(s, *key) for key, s in net.items() if s != 0.0]


@pytest.mark.parametrize("name, summary", [
    ("crank_rocker.toml", "closed form: loop 1"),
    ("fourbar_me581.toml", "closed form: loop 1"),
    ("fourbar_me581_theta4.toml", "closed form: loop 1"),
    ("slider_crank.toml", "closed form: loop 1"),
    ("watt_sixbar.toml", "closed form: loops 1, 2 (stepwise)"),
    ("offset_slider.toml", "no closed form: loop 1 has 3 unknowns, loop 2 has 3 unknowns (coupled)"),
    ("rapier_drive.toml", "no closed form: loop 1 has 3 unknowns, loop 2 has 3 unknowns (coupled)"),
])
def test_samples_summary(name: str, summary: str) -> None:
    """Every sample's summary; for the coupled ones, the reason checked here: each loop
    has three unknowns and their sum and difference at least three (the difference
    cancels what the two share, a5 e^(i t15) or the crank and coupler, but three remain),
    so nothing is solvable two at a time."""
    m = load(SAMPLES / name)
    der = m.derivation
    assert der.summary == summary
    unknowns = {u.name for u in m.unknowns}
    if der.complete:
        assert sorted(i for s in der.steps for i in s.unknowns) == list(range(len(unknowns)))
        return
    l1, l2 = m.loops
    assert len(_unknowns_in(list(l1.vectors), unknowns)) == 3
    assert len(_unknowns_in(list(l2.vectors), unknowns)) == 3
    for c in (1, -1):
        assert len(_unknowns_in(_combined(l1, l2, c), unknowns)) >= 3


def test_samples_closed_form_is_newton_polished() -> None:
    """Every sample with a closed form, every branch, at its own driver and 36 more:
    the closed form is Newton polished at 50 digits (1e-12 rad / relative)."""
    worst = 0.0
    with mpmath.workdps(ref.DPS):
        for name in ("crank_rocker.toml", "fourbar_me581.toml", "fourbar_me581_theta4.toml",
                     "slider_crank.toml", "watt_sixbar.toml"):
            m = load(SAMPLES / name)
            scale = _scale(m)
            for d in [m.driver.value] + [math.radians(x) for x in range(-175, 180, 25)]:
                for signs, q in m.derivation.solutions(d):
                    inp = ref.Inputs(m, driver=d)
                    root = ref.polish(inp, ref.as_sol(m, q))
                    dist = float(ref.distance(m, root, q, scale))
                    worst = max(worst, dist)
                    assert dist <= 1e-12, f"{name} at {d}: {signs} {dist:.3g} from Newton"
    _worst("newton_samples", worst, "samples")


def test_two_loops_whose_difference_has_two_unknowns() -> None:
    """No loop has two unknowns but loop 1 - loop 2 has ty, tz only; then loop 1 gives s,
    tx. Every solution is a root at 50 digits, and there are as many as the formulas give."""
    with mpmath.workdps(ref.DPS):
        for case, m, _ in MECHANISMS[195:200]:
            der = m.derivation
            assert der.summary == "closed form: loops 1+2, 1 (stepwise)"
            names = [u.name for u in m.unknowns]
            ty, tz = case.roles["names"][7:9]
            s, tx = case.roles["names"][5:7]
            first, second = der.steps
            assert {names[i] for i in first.unknowns} == {ty, tz} and first.loops == (0, 1)
            assert {names[i] for i in second.unknowns} == {s, tx} and second.loops == (0,)
            refs, _ = ref.reference(case, ref.Inputs(m))
            assert len(der.solutions(m.driver.value)) == len(refs) == 4


# --- 5. change points: Indeterminate or no solution, never NaN --------------------------------

def _fourbar_at(a: float, b: float, c: float, g: float) -> Any:
    case, _ = ref.make_fourbar(random.Random(5), (a, b, c, g))
    return case


def _no_nan(der: Any, d: float) -> str:
    """'indeterminate', 'none' or 'solved' (every number finite), for every branch."""
    out = set()
    for signs in der.branches:
        try:
            q = der.solve(d, signs)
        except derive.Indeterminate:
            out.add("indeterminate")
            continue
        if q is None:
            out.add("none")
        else:
            assert all(math.isfinite(x) for x in q)
            out.add("solved")
    q_np, ok = der.solve_np(np.array([d, d]), der.branches[0])
    assert all(np.all(np.isnan(x[~ok])) and np.all(np.isfinite(x[ok])) for x in q_np)
    assert len(out) == 1
    return out.pop()


def _ground_angle(case: ref.Case, m: Any) -> float:
    """The driver value that puts the crank along the ground (A on O4 when a = g)."""
    inp = ref.Inputs(m)
    t = case.roles["terms"]
    flip = m.loops[0].vectors[t["in"]].sign
    return float(mpmath.arg(-flip * inp.vector(0, t["g"])))


@pytest.mark.parametrize("b, c", [(30.0, 30.0), (30.0, 45.0)])
def test_fourbar_with_the_crank_pin_on_the_rocker_pivot(b: float, c: float) -> None:
    """a = g and the crank along the ground: A is on O4, K = 0. With b = c the circles
    coincide (every rocker angle closes: a change point); with b != c they are
    concentric and never meet. Either way no number is claimed."""
    case = _fourbar_at(40.0, b, c, 40.0)
    case, m = ref.with_driver_value(case, 0.0)
    d = _ground_angle(case, m)
    got = _no_nan(m.derivation, d)
    assert got == ("indeterminate" if b == c else "none") or got == "indeterminate"
    # a hair away it is a position again (or none, when b != c)
    assert _no_nan(m.derivation, d + 1e-6) in ("solved", "none")


@pytest.mark.parametrize("offset", [False, True])
def test_inverted_slider_with_the_pin_on_the_pivot(offset: bool) -> None:
    """a = g, the crank along the ground: the pin is on the slide's pivot (K = 0). Without
    an offset s = 0 and every link angle closes (indeterminate: it must not claim one);
    with an offset e it cannot close (|s + i e| = 0 has no real s)."""
    rng = random.Random(11)
    case, m = ref.make_inverted(rng, offset)
    params = dict(case.params)
    names = list(params)
    la, lg, tg = names[0], names[1], names[2]
    params[lg] = params[la]
    params[tg] = (0.0, "deg")
    case = ref.Case(case.family, params, (case.driver[0], 0.0), case.unknowns, case.loops,
                    case.roles, case.signed)
    m = case.mechanism()
    assert _no_nan(m.derivation, 0.0) == ("none" if offset else "indeterminate")
    assert _no_nan(m.derivation, 1e-3) == "solved" or offset


def test_exactly_at_a_limit_one_finite_solution() -> None:
    """r1 = r4 = 3, r2 = r3 = 0.2 (names p, q, w, v), the crank along the ground: the
    circles about A = (0.2, 0) and O4 = (3, 0) touch at B = (0, 0) exactly. One solution
    (both signs give it), a root at 50 digits: theta3 = theta4 = 180 deg."""
    loop = [{"length": "q", "angle": "ta"}, {"length": "w", "angle": "tb"},
            {"length": "v", "angle": "tc", "sign": -1}, {"length": "p", "angle": 0.0, "sign": -1}]
    case = ref.Case("fourbar", {"p": (3.0, "mm"), "q": (0.2, "mm"), "w": (0.2, "mm"), "v": (3.0, "mm")},
                    ("ta", 0.0), [("tb", "deg"), ("tc", "deg")], [loop],
                    {"terms": {"in": 0, "cp": 1, "out": 2, "g": 3},
                     "angles": {"in": "ta", "cp": "tb", "out": "tc"}, "driven": "in"})
    m = case.mechanism()
    sols = m.derivation.solutions(0.0)
    assert len(sols) == 1
    q = sols[0][1]
    assert all(abs(abs(x) - math.pi) <= 4 * EPS for x in q)
    with mpmath.workdps(ref.DPS):
        inp = ref.Inputs(m)
        assert abs(inp.residual(0, ref.as_sol(m, q))) <= 8 * EPS * inp.size(0, ref.as_sol(m, q))
    assert _no_nan(m.derivation, 0.0) == "solved"


def test_fourbar_view_and_transmission_under_every_driver() -> None:
    """Each random four-bar, however written (ground first or last, negated, any names)
    and whichever angle drives, is seen as input, coupler, output, ground in the roles it
    was built with, and its transmission angle is the law of cosines' at B:
    cos mu = (b^2 + c^2 - |A - O4|^2) / (2 b c), computed here in mpmath."""
    worst = 0.0
    with mpmath.workdps(ref.DPS):
        for case, m, _ in MECHANISMS[:120]:
            der = m.derivation
            t = case.roles["terms"]
            (view,) = der.fourbars
            assert (view.loop, view.input, view.coupler, view.output, view.ground) == (
                0, t["in"], t["cp"], t["out"], t["g"])
            terms = find_steps.loop_terms(m)[0]
            inp = ref.Inputs(m)
            for _, q in der.solutions(m.driver.value):
                sol = {**ref.as_sol(m, q), m.driver.name: mpf(m.driver.value)}
                flip = m.loops[0].vectors[t["in"]].sign
                pa = flip * inp.vector(0, t["in"], sol)
                o4 = -flip * inp.vector(0, t["g"])
                b, c = inp.length(0, t["cp"]), inp.length(0, t["out"])
                mu = mpmath.acos((b * b + c * c - abs(pa - o4) ** 2) / (2 * b * c))
                mu = min(mu, mpmath.pi - mu)  # folded: the acute angle between the lines
                got = steps.fourbar_transmission(view, terms, der.params, m.driver.value, q)
                worst = max(worst, float(abs(mu - got)))
    FIGURES["transmission"] = (worst, "rad, 120 four-bars")
    assert worst <= 1e-12


def _redriven() -> list[tuple[ref.Case, Any, ref.Sol]]:
    """Slider-cranks driven by the slide s, inverted slider-cranks driven by the turning
    link, Watt six-bars driven by their last link, each at a configuration of the
    original mechanism (given as the third item)."""
    out = []
    with mpmath.workdps(ref.DPS):
        for lo, hi, family, new in ((120, 130, "slider_by_s", lambda c: c.roles["s"]),
                                    (150, 180, "inverted_by_t4", lambda c: c.roles["t4"]),
                                    (180, 195, "watt_by_t7", lambda c: c.roles["angles"]["out2"])):
            for case, m, _ in MECHANISMS[lo:hi:3]:
                config = ref.reference(case, ref.Inputs(m))[0][0]
                name = new(case)
                unit = dict(case.unknowns)[name]
                value = float(config[name]) if unit == "mm" else math.degrees(float(config[name]))
                other = ref.redrive(case, name, value, family)
                out.append((other, other.mechanism(), {**config, case.driver[0]: mpf(m.driver.value)}))
    return out


def test_other_drivers_stepwise_closed_form_is_newton_polished() -> None:
    """The same loops driven from elsewhere (the slide, the turning link, the six-bar's
    last link, which makes loop 2 the first step): every solution is Newton polished
    (1e-12), there are as many as the formulas here give, and the original configuration
    is among them."""
    worst, checked = 0.0, 0
    with mpmath.workdps(ref.DPS):
        for case, m, config in _redriven():
            der = m.derivation
            assert der.complete, case.family
            inp = ref.Inputs(m)
            refs, disc = ref.reference_redriven(case, inp)
            if disc < 1e-6:
                continue
            checked += 1
            sols = der.solutions(m.driver.value)
            assert len(sols) == len(refs), case.family
            scale = _scale(m)
            for _, q in sols:
                root = ref.polish(inp, ref.as_sol(m, q))
                dist = float(ref.distance(m, root, q, scale))
                worst = max(worst, dist)
                assert dist <= 1e-12, case.family
                assert min(ref.distance(m, r, root, scale) for r in refs) < mpf(10) ** -40
            assert min(ref.distance(m, config, q, scale) for _, q in sols) < 1e-9, case.family
    _worst("newton_redriven", worst, f"{checked} mechanisms driven from elsewhere")
    assert checked >= 15


def test_two_angles_margin_np_orders_as_the_circle_intersection_and_is_nan_at_a_nan() -> None:
    """two_angles_margin_np orders its three distances by the circle intersection's own rule
    (assembly.descending_np, one home): the same bits as the margin of the sorted distances
    wherever none is NaN (zero lengths mixed in), and NaN wherever one is (a step reading an
    unknown an earlier step did not solve has no margin; before the fold a NaN was ordered
    last, so three NaNs gave a margin of 0); the scalar rule gives the same."""
    rng = np.random.default_rng(33)
    n = 20_000
    a = [rng.normal(size=n) * rng.choice([0.0, 1.0, 1e-8], n) for _ in range(6)]
    for col in a:
        col[rng.random(n) < 0.05] = np.nan
    a[0][:50] = a[1][:50] = a[2][:50] = a[4][:50] = np.nan  # all three distances NaN
    p, q, k = (a[0], a[1]), (a[2], a[3]), (a[4], a[5])
    dist = np.stack((dyads.norm_np(*k), dyads.norm_np(*p), dyads.norm_np(*q)))
    s = -np.sort(-dist, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        want = np.where(s[0] > 0.0, (s[2] - (s[0] - s[1])) / s[0], 0.0)
    nan = np.isnan(dist).any(axis=0)
    want[nan] = np.nan
    got = dyads.two_angles_margin_np(p, q, k)
    assert nan.any() and (want == 0.0).any() and (want[~nan] != 0.0).any()
    assert np.array_equal(got, want, equal_nan=True)
    rows = np.flatnonzero(nan)[:200].tolist() + list(range(n - 200, n))
    scalar = [dyads.two_angles_margin((p[0][i], p[1][i]), (q[0][i], q[1][i]), (k[0][i], k[1][i]))
              for i in rows]
    assert np.array_equal(got[rows], scalar, equal_nan=True)

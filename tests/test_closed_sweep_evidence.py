"""The closed-form sweep's evidence (kinematics/closed.py): each position it reports is
the closed form itself where Phi and J evaluated there imply a Newton step that the
single solve's convergence test accepts (no step taken: 0 iterations), else Newton steps
from it under that loop's stopping rule. References: 40-digit mpmath circle intersections
of random four-bars at micrometre to kilometre scales, up to a limit position (the
closed form's worst conditioning); the scalar single solve from each reported position
(one step, within tol); and the polished path against the certified one."""

from __future__ import annotations

import math
import random

import mpmath as mp
import numpy as np
import pytest

import linkage.kinematics.closed as closed
from linkage.kinematics.closed import closed_sweep
from linkage.kinematics.continuation import Solver
from linkage.kinematics.loading import load
from linkage.kinematics.stepwise import sweep as one_at_a_time
from linkage.problems.derive import sign_text
from linkage.samples import sample_path

TOL = 1e-12


def _four_bar_roots(r1, r2, r3, r4, theta2_deg):
    """Both (theta3, theta4) (rad, mpf) of crank_rocker.toml's loop at 40 digits:
    B at r3 from the crank pin A and r4 from the ground pivot O4 = (r1, 0)."""
    with mp.workdps(40):
        r1, r2, r3, r4 = (mp.mpf(x) for x in (r1, r2, r3, r4))
        t2 = mp.mpf(theta2_deg) * mp.pi / 180
        ax, ay = r2 * mp.cos(t2), r2 * mp.sin(t2)
        dx, dy = r1 - ax, -ay
        d = mp.sqrt(dx * dx + dy * dy)
        a = (r3 * r3 - r4 * r4 + d * d) / (2 * d)
        h = mp.sqrt(max(r3 * r3 - a * a, 0))
        ux, uy = dx / d, dy / d
        out = []
        for s in (1, -1):
            bx, by = ax + a * ux - s * h * uy, ay + a * uy + s * h * ux
            out.append((mp.atan2(by - ay, bx - ax), mp.atan2(by, bx - r1)))
        return out


def _turn_gap(x, y):
    with mp.workdps(40):
        return abs((x - y + mp.pi) % (2 * mp.pi) - mp.pi)


def _arc_to_a_limit(m, signs, rng):
    """Driver values (deg) on one branch from an assembled grid point up to within a
    relative margin of about 1e-7 of a limit (bisection on the scalar margin), or the
    whole turn where there is no limit."""
    d = m.derivation

    def margin(deg):
        return min(d.margins(math.radians(deg), signs))

    grid = [float(k) for k in range(0, 360, 3)]  # (once round: the arc may wrap past 360)
    good = [margin(v) > 1e-6 for v in grid]
    if all(good):
        return [*grid, 360.0]
    if not any(good):
        return None
    start = next(i for i in range(len(grid)) if good[i] and not good[i - 1])
    end = start
    while good[(end + 1) % len(grid)]:
        end += 1
    lo, hi = grid[start] + 3.0 * (end - start), grid[start] + 3.0 * (end - start + 1)
    for _ in range(80):  # the limit lies between lo (assembles) and hi (does not)
        mid = 0.5 * (lo + hi)
        if margin(mid) > 1e-7:
            lo = mid
        else:
            hi = mid
    values = list(np.linspace(grid[start], lo, 40))
    return values if rng.random() < 0.5 else values[:20]  # (some arcs stop short of it)


def _loop_residual(r1, r2, r3, r4, theta2_deg, t3, t4):
    """max |x|, |y| of the loop's closure r2 e^(i theta2) + r3 e^(i theta3) - r4 e^(i theta4) - r1
    at 40 digits (t3, t4 rad, mpf)."""
    with mp.workdps(40):
        t2 = mp.mpf(theta2_deg) * mp.pi / 180
        z = mp.mpf(r2) * mp.expj(t2) + mp.mpf(r3) * mp.expj(t3) - mp.mpf(r4) * mp.expj(t4) - mp.mpf(r1)
        return max(abs(z.real), abs(z.imag))


def test_the_reported_positions_are_roots_to_the_tolerance_at_40_digits():
    """Random four-bars (Grashof or not) at length scales 1e-6 to 1e3 of the file's, on
    either branch, up to a limit position: at every position the engine reports (certified
    closed form or polished), the loop closes within the single solve's residual gate (tol
    x length scale) at 40 digits, and the angles are within tol (rad) of the 40-digit root
    wherever the margin is at least 1e-4. Nearer a limit, the root moves like the square
    root of the loops' rounding (J is nearly singular), so no engine's angles are within tol
    of it; there they are the one-at-a-time engine's, to tol."""
    rng = random.Random(2026)
    base = load(sample_path("crank_rocker.toml"))
    counts = {"certified": 0, "polished": 0, "near": 0}
    for trial in range(60):
        scale = 10.0 ** rng.choice([-6, -3, 0, 3])
        lengths = {k: rng.uniform(20.0, 160.0) * scale for k in ("r1", "r2", "r3", "r4")}
        m = base.with_values(lengths, {})
        signs = (rng.choice([1.0, -1.0]),)
        values = _arc_to_a_limit(m, signs, rng)
        if values is None:
            continue
        got = closed_sweep(m, values, branch=sign_text(signs), tol=TOL)
        assert got is not None, (trial, lengths)
        counts["certified"] += int((got.iterations == 0).sum())
        counts["polished"] += int((got.iterations > 0).sum())
        d = m.derivation
        near = [min(d.margins(math.radians(v), signs)) < 1e-4 for v in values]
        ref = one_at_a_time(m, values, branch=sign_text(signs)) if any(near) else None
        counts["near"] += sum(near)
        for i, v in enumerate(got.values):
            t3, t4 = (mp.mpf(float(x)) * mp.pi / 180 for x in got.solution[i])
            r = [lengths[k] for k in ("r1", "r2", "r3", "r4")]
            assert _loop_residual(*r, float(v), t3, t4) <= TOL * m.length_scale, (trial, float(v))
            if near[i]:
                p = ref.positions[i]
                assert max(abs(math.radians(a - p.solution[n]))
                           for a, n in zip(got.solution[i], ("theta3", "theta4"))) <= TOL, (trial, float(v))
                continue
            err = min(max(_turn_gap(t3, a), _turn_gap(t4, b)) for a, b in _four_bar_roots(*r, float(v)))
            assert err <= TOL, (trial, float(v), float(err))
    assert counts["certified"] > 1000 and counts["near"] >= 10, counts


@pytest.mark.parametrize("name", ["crank_rocker.toml", "slider_crank.toml", "watt_sixbar.toml"])
def test_the_single_solve_takes_one_step_within_tol_from_each_certified_position(name):
    """The evidence is the single solve's test: from each position reported with 0
    iterations, that solve (scalar, compiled) converges in one step that moves it by at
    most tol."""
    m = load(sample_path(name))
    values = [float(k) for k in range(0, 361, 5)]
    got = closed_sweep(m, values, tol=TOL)
    assert got is not None and (got.iterations == 0).all()
    solver = Solver(m, "newton", TOL, 50)
    kinds = [u.kind for u in m.unknowns]
    for i, v in enumerate(values):
        q = [math.radians(x) if k == "angle" else x for x, k in zip(got.solution[i], kinds)]
        _, r = solver.solve(v, q)
        assert r.converged and r.iterations == 1, (v, r.status)
        steps = [abs(a - b) / (1.0 if k == "angle" else m.length_scale) for a, b, k in zip(r.x, q, kinds)]
        assert max(steps) <= TOL, v


@pytest.mark.parametrize("refused", ["every third", "all"])
def test_positions_the_evidence_does_not_certify_are_polished_by_the_rule(monkeypatch, refused):
    """Where the evidence does not certify the closed form, Newton steps from it under the
    single solve's stopping rule: iterations count them there, and the answer is the
    certified one's and the one-at-a-time engine's to the stated tolerance."""
    m = load(sample_path("watt_sixbar.toml"))
    values = [float(k) for k in range(361)]
    certified = closed_sweep(m, values)
    real = closed.system_converged_array

    def refusing(*args):
        ok = real(*args).copy()
        ok[::3 if refused == "every third" else 1] = False
        return ok

    monkeypatch.setattr(closed, "system_converged_array", refusing)
    polished = closed_sweep(m, values)
    assert polished is not None
    want = np.zeros(len(values), dtype=int)
    want[::3 if refused == "every third" else 1] = 1
    assert np.array_equal(polished.iterations, want)
    ref = one_at_a_time(m, values)
    assert polished.branch == certified.branch
    for j, name in enumerate(ref.names):
        col = np.array(ref.column(name))
        big = np.max(np.abs(col))
        assert np.max(np.abs(polished.solution[:, j] - col)) <= 1e-12 * big, name
        assert np.max(np.abs(polished.solution[:, j] - certified.solution[:, j])) <= 1e-12 * big, name
    dets = np.array([p.det for p in ref.positions])
    assert np.max(np.abs(polished.det - dets)) <= 1e-12 * np.max(np.abs(dets))
    assert np.max(np.abs(certified.det - dets)) <= 1e-12 * np.max(np.abs(dets))


def test_a_tolerance_below_rounding_is_the_one_at_a_time_engines():
    """tol 1e-17 rad: neither the closed form nor a Newton step meets it (rounding), so the
    closed-form engine declines and the front door's answer is the one-at-a-time
    engine's, unconverged positions and all."""
    m = load(sample_path("crank_rocker.toml"))
    assert closed_sweep(m, [float(k) for k in range(0, 361, 10)], tol=1e-17) is None


def test_blocks_give_the_answer_of_one_block(monkeypatch):
    """The engine settles BLOCK positions at a time (one block is its own answer, not
    copied): blocks of 50 give what one block gives, position by position."""
    m = load(sample_path("watt_sixbar.toml"))
    values = [0.5 * k for k in range(721)]
    whole = closed_sweep(m, values)
    monkeypatch.setattr(closed, "BLOCK", 50)
    parts = closed_sweep(m, values)
    assert whole is not None and parts is not None
    for f in ("solution", "det", "iterations"):
        assert np.array_equal(getattr(whole, f), getattr(parts, f)), f
    assert whole.branch == parts.branch

"""The block rates (kinematics.rate_blocks: position_rates over numpy arrays, a sweep's
and its loads' path) against the scalar definition (kinematics.rates.position_rates),
position by position: the same status, the same flags and the same numbers to their last
bits (tests/ulps.py), at random positions, speeds and accelerations and up to a toggle,
where the rates must carry their flag or be undefined on both paths. And the block's
pieces against theirs: the LU twin (linalg.lu_np) and Newton direction twin (kinematics.block_linalg), the
Neumann series, polish."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from linkage.kinematics.block_linalg import direction_np
from linkage.kinematics.loading import load
from linkage.kinematics.rate_blocks import block_rates
from linkage.kinematics.rate_bounds import through_inverse, through_inverse_np
from linkage.kinematics.rates import polish, polish_np, position_rates
from linkage.kinematics.sweep import sweep_mechanism
from linkage.linalg import SingularMatrix, back_substitute_np, lu, lu_np, lu_solve
from linkage.methods.newton_system import newton_direction
from linkage.units import radians
from ulps import assert_ulps

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"

ULPS = 4
"""Bound on the block's numbers against the scalar ones', in ulps of each value: the two
run the same operations in the same order (the model's compiled code, Python's complex
products spelt out), so where numpy's cos and sin are the C library's they agree to the
bit; a few ulps leave room for a CPU whose numpy has its own (tests/ulps.py)."""


def _solved(name: str, values: list[float]) -> tuple[object, list[np.ndarray], np.ndarray]:
    """The mechanism, its unknowns (internal units, one array each) and driver (rad) at the
    solved positions among ``values`` (degrees)."""
    m = load(SAMPLES / f"{name}.toml")
    r = sweep_mechanism(m, values)
    sol = [p for p in r.positions if p.solution is not None]
    q = [np.array([radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name] for p in sol])
         for u in m.unknowns]
    return m, q, np.array([radians(p.input) for p in sol])


def _compare(m: object, q: list[np.ndarray], d: np.ndarray, speed: float | None, accel: float) -> list[str]:
    """Block against scalar at every position; the statuses seen."""
    block = block_rates(m.model, q, d, speed, accel).rates()
    size = m.length_scale
    seen = []
    for i, got in enumerate(block):
        want = position_rates(m.model, [float(c[i]) for c in q], float(d[i]), speed, accel)
        where = f"position {i} ({math.degrees(d[i]):.6g} deg)"
        assert got.status == want.status, where
        assert got.ill_conditioned == want.ill_conditioned, where
        seen.append(want.status)
        for field in ("joints", "joint_velocities", "joint_accelerations"):
            a, b = getattr(got, field), getattr(want, field)
            assert a.keys() == b.keys(), (where, field)
            assert_ulps([a[k] for k in a], [b[k] for k in a], ULPS, what=(where, field))
        for field in ("velocities", "accelerations", "velocity_bounds", "acceleration_bounds",
                      "joint_velocity_bounds", "joint_acceleration_bounds"):
            a, b = getattr(got, field), getattr(want, field)
            assert a.keys() == b.keys(), (where, field)
            # a bound sums rounding terms of every size: its last bits scaled by the mechanism
            scale = size * 1e-12 if "bounds" in field else None
            assert_ulps([a[k] for k in a], [b[k] for k in a], ULPS, scale=scale, what=(where, field))
    return seen


@pytest.mark.parametrize("name", ["crank_rocker_joints", "slider_crank_joints", "inverted_slider_joints",
                                  "stephenson_sixbar_joints", "offset_slider"])
def test_block_rates_are_the_scalar_rates_at_random_positions(name: str) -> None:
    rng = np.random.default_rng(33)
    m, q, d = _solved(name, sorted(rng.uniform(0.0, 360.0, 60).tolist()))
    assert len(d) >= 20
    motions = ((None, 0.0), (10.0, 0.0), (float(rng.uniform(-50, 50)), float(rng.uniform(-500, 500))))
    for speed, accel in motions:
        _compare(m, q, d, speed, accel)


def test_block_rates_near_a_toggle_carry_the_scalar_flag_or_are_undefined() -> None:
    """The four-bar driven by its rocker toggles at 104.4775... deg: approaching it the
    rates' bounds grow until they are flagged, and at it they are undefined; the block must
    say so at the same positions (the bounds stay honest, never a bare number)."""
    toggle = 104.47751218592992
    values = [toggle + 10.0 ** -k for k in range(1, 14)] + [toggle, 180.0]
    m, q, d = _solved("fourbar_me581_theta4", values)
    seen = _compare(m, q, d, 10.0, 3.0)
    assert "ill_conditioned" in seen and "ok" in seen


def test_lu_and_newton_direction_twins_give_the_scalar_bits() -> None:
    rng = np.random.default_rng(7)
    for n in (2, 3, 4, 6):
        a = rng.normal(size=(200, n, n)) * rng.choice([1e-3, 1.0, 1e3], size=(200, 1, n))
        a[:5, 0, :] = 0.0  # singular: a zero row
        b = rng.normal(size=(200, n))
        t, y = np.ascontiguousarray(a.transpose(1, 2, 0)), np.ascontiguousarray(b.T)
        ok = lu_np(t, y)
        x = back_substitute_np(t, y)
        dq, usable = direction_np(a, b)
        for k in range(200):
            try:
                want = lu_solve(lu(a[k].tolist()), b[k].tolist())
                assert ok[k] and [float(c[k]) for c in x] == want
            except SingularMatrix:
                assert not ok[k]
            step = newton_direction(a[k].tolist(), b[k].tolist())[0]
            assert bool(usable[k]) == (step is not None)
            if step is not None:
                assert dq[k].tolist() == step


def test_the_force_matrix_condition_and_solution_twins_are_the_scalar_cond1_and_lu_solve() -> None:
    """condition_np (the loads' near-toggle test, one batched inverse) against linalg.cond1
    and lu_solve matrix by matrix: the same 1-norm condition number and solution to the
    rounding the condition allows, inf and NaN where the matrix is singular; solve_np's
    2 x 2 cofactors likewise."""
    from linkage.kinematics.load_matrix import condition_np
    from linkage.kinematics.rate_bounds import solve_np
    from linkage.linalg import cond1

    rng = np.random.default_rng(5)
    for n, count in ((9, 120), (2, 120)):
        a = rng.normal(size=(count, n, n)) * rng.choice([1e-3, 1.0, 1e3], size=(count, 1, n))
        a[:4, 1, :] = 0.0  # singular: a zero row
        a[4:8, :, 0] = a[4:8, :, 1] * (1.0 + 1e-9)  # near singular: two columns a hair apart
        b = rng.normal(size=(count, n))
        cond, x = condition_np(a, b)
        _, x2, usable = solve_np(a, b[..., None])
        for k in range(count):
            want = cond1(a[k].tolist())
            if k < 4:  # a zero row: singular to both
                assert math.isinf(want) and math.isinf(cond[k]) and np.isnan(x[k]).all() and not usable[k]
                continue
            if math.isinf(want) or math.isinf(cond[k]):
                # singular to one LU and 1e16 to the other's rounding (cofactors or pivots):
                # the same verdict, no digits (kinematics.load_matrix.solve_scaled)
                assert min(want, cond[k]) * 2.0 ** -52 > 0.5
                continue
            assert usable[k] and cond[k] == pytest.approx(want, rel=1e3 * want * 2.0 ** -52)
            sol = lu_solve(lu(a[k].tolist()), b[k].tolist())
            scale = want * 2.0 ** -52 * 1e2 * max(map(abs, sol))
            np.testing.assert_allclose(x[k], sol, rtol=0.0, atol=scale)
            np.testing.assert_allclose(x2[k, :, 0], sol, rtol=0.0, atol=scale)
        assert (cond[4:8] > 1e6).all()  # the near-singular ones are judged so


def test_the_neumann_series_twin_stops_where_the_scalar_one_does() -> None:
    rng = np.random.default_rng(11)
    n, count = 3, 300
    inv = [[rng.uniform(0.0, 2.0, count) for _ in range(n)] for _ in range(n)]
    # spreads from tiny (one term) to large (no contraction: None)
    spread = [[rng.uniform(0.0, 1.0, count) * 10.0 ** rng.uniform(-12, 0, count) for _ in range(n)]
              for _ in range(n)]
    g = [rng.uniform(0.0, 1.0, count) for _ in range(n)]
    got, ok = through_inverse_np(inv, spread, g)
    outcomes = set()
    for k in range(count):
        want = through_inverse([[v[k] for v in row] for row in inv], [[v[k] for v in row] for row in spread],
                               [v[k] for v in g])
        assert bool(ok[k]) == (want is not None)
        outcomes.add(want is not None)
        if want is not None:
            assert [float(c[k]) for c in got] == want
    assert outcomes == {True, False}


def test_polish_twin_takes_the_scalar_steps() -> None:
    m, q, d = _solved("stephenson_sixbar_joints", list(np.linspace(0.0, 359.0, 40)))
    rng = np.random.default_rng(5)
    rough = [c + rng.normal(size=c.shape) * 1e-7 for c in q]  # a solve stopped at its tolerance
    got = polish_np(m.model, rough, d)
    for i in range(len(d)):
        want = polish(m.model, [float(c[i]) for c in rough], float(d[i]))
        assert [float(c[i]) for c in got] == want

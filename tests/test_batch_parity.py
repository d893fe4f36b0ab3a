"""Batch engines give what the one-at-a-time engine gives (issue 18): the same columns
(rates, joints, points), the same scaled tolerances and the same statuses; the stopping
and continuity rules are defined once (linkage.rules), each numpy twin equal to its
scalar. References: the slider-crank's closed form and its time derivatives, derived
here (worked example P7, docs/worked_examples.md's loop, differentiated by hand), not the code under test."""

from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
import tomllib

import linkage
from linkage import rules
from linkage.kinematics.batch import batch_sweep
from linkage.kinematics.limits import LOCATE_TOL, solved_ranges_array
from linkage.kinematics.loading import load, parse_mechanism
from linkage.kinematics.sweep import driver_values, sweep

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"
SAMPLE_NAMES = sorted(p.stem for p in SAMPLES.glob("*.toml"))


# --- references -------------------------------------------------------------------------------

def slider_crank(scale: float = 1.0) -> linkage.problems.loops.Mechanism:
    """sample_inputs/slider_crank.toml with every length times ``scale``."""
    doc = tomllib.loads((SAMPLES / "slider_crank.toml").read_text())
    for k in ("r2", "r3", "e"):
        doc["parameters"][k]["value"] *= scale
    doc["unknowns"]["s"]["guess"] *= scale
    return parse_mechanism(doc)


def slider_crank_exact(theta2_deg: float, w2: float = 0.0, a2: float = 0.0, scale: float = 1.0
                       ) -> tuple[float, float, float, float, float, float]:
    """(theta3 rad, s, theta3', s', theta3'', s'') of the open branch from the closed form
    sin theta3 = (e - r2 sin theta2) / r3, s = r2 cos theta2 + r3 cos theta3, and its
    first and second time derivatives."""
    r2, r3, e = 40.0 * scale, 120.0 * scale, 10.0 * scale
    t2 = math.radians(theta2_deg)
    t3 = math.asin((e - r2 * math.sin(t2)) / r3)
    s = r2 * math.cos(t2) + r3 * math.cos(t3)
    # r2 cos t2 w2 + r3 cos t3 w3 = 0 (the y row of the loop, differentiated)
    w3 = -r2 * math.cos(t2) * w2 / (r3 * math.cos(t3))
    v = -r2 * math.sin(t2) * w2 - r3 * math.sin(t3) * w3
    a3 = ((r2 * math.sin(t2) * w2 ** 2 - r2 * math.cos(t2) * a2 + r3 * math.sin(t3) * w3 ** 2)
          / (r3 * math.cos(t3)))
    acc = (-r2 * math.cos(t2) * w2 ** 2 - r2 * math.sin(t2) * a2 - r3 * math.cos(t3) * w3 ** 2
           - r3 * math.sin(t3) * a3)
    return t3, s, w3, v, a3, acc


# --- finding: batch tolerances ------------------------------------------------------------------

@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e6])
def test_batch_newton_takes_a_single_solves_iterations_from_the_same_start(scale, monkeypatch):
    """Batch tolerances, position by position: from the batch's own warm start, a single
    solve (textbook Newton, the stopping rule every solve uses) takes exactly the batch's
    iterations, at every scale. Before, the batch stopped early at 1e-6 and late at 1e6."""
    import linkage.kinematics.batch as batch
    from linkage.solve import solve_system

    starts: list[list[np.ndarray]] = []
    evaluate = batch.VectorLoops.evaluate

    def spy(self, q, rows):
        if rows is None:  # the first evaluation of a block (the only one of every position): the warm starts
            starts.append([c.copy() for c in q])
        return evaluate(self, q, rows)

    monkeypatch.setattr(batch.VectorLoops, "evaluate", spy)
    m = slider_crank(scale)
    values = driver_values(0.0, 360.0, None, 1501)
    result = batch.batch_sweep(m, values)
    (t3, s), = starts  # one block
    for i in range(0, len(values), 3):
        r = solve_system(m.model.problem_at(math.radians(values[i])), (t3[i], s[i]), tol=1e-12,
                         record=False, damped=False)
        assert r.converged and r.iterations == result.iterations[i], (scale, values[i])


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e6])
def test_batch_tolerances_scale_with_the_mechanism_as_one_at_a_time(scale):
    """Batch tolerances: the batch's Newton compared step and residual with tol, not tol x
    the length scale: the slider-crank scaled by 1e-6 or 1e6 took 1.86 and 2.73 iterations
    (165 positions handed to the slow path) where the one-at-a-time sweep takes 2.00 at
    every scale. Now both engines take the same iterations, position by position, at every
    scale, and the batch hands nothing to the slow path."""
    values = driver_values(0.0, 360.0, None, 1501)
    m = slider_crank(scale)
    batch, batch_1 = batch_sweep(m, values), batch_sweep(slider_crank(1.0), values)
    one, one_1 = sweep(m, values), sweep(slider_crank(1.0), values)
    assert batch.fallback == 0
    assert list(batch.iterations) == list(batch_1.iterations)
    assert [p.iterations for p in one.positions] == [p.iterations for p in one_1.positions]
    # the mean the issue measured: the batch's equals its own at scale 1 and does not
    # exceed the one-at-a-time's (its Hermite warm start is at least as good as the
    # tangent predictor, so it may stop a step sooner; never later)
    assert batch.iterations.mean() == batch_1.iterations.mean()
    assert batch.iterations.mean() <= np.mean([p.iterations for p in one.positions])
    assert (batch.status == 0).all()
    # and the answers are right to the tolerance, at the mechanism's own size
    for i in range(0, len(values), 50):
        t3, s, *_ = slider_crank_exact(values[i], scale=scale)
        assert abs(math.radians(batch.solution[i, 0]) - t3) <= 1e-12
        assert abs(batch.solution[i, 1] - s) <= 1e-12 * 120.0 * scale


def test_design_newton_uses_the_scaled_stopping_rule():
    """design_loops.newton_block (scans) has the batch's stopping rule, from linkage.rules: a design
    scaled by 1e6 takes the same iterations as the original."""
    from linkage.kinematics.design_loops import newton_block
    from linkage.kinematics.vector_loops import VectorLoops

    counts = []
    for scale in (1e-6, 1.0, 1e6):
        m = slider_crank(scale)
        vals = np.radians(np.linspace(0.0, 360.0, 97))
        loops = VectorLoops(m.model, vals)
        t3 = np.array([slider_crank_exact(math.degrees(v), scale=scale)[0] for v in vals])
        q = [t3 + 1e-4, np.array([slider_crank_exact(math.degrees(v), scale=scale)[1] for v in vals])
             * (1.0 + 1e-4)]
        done, _, iters = newton_block(loops, q, np.arange(len(vals)), 1e-12,
                                      np.full(len(vals), 120.0 * scale), [False, True], 50, count=True)
        assert done.all()
        counts.append(list(iters))
    assert counts[0] == counts[1] == counts[2]


@pytest.mark.parametrize("name", SAMPLE_NAMES)
def test_loops_from_a_plan_are_the_loops_from_their_terms(name):
    """VectorLoops from a LoopPlan (fixed terms reduced to numbers once per model) give Phi
    and J bit for bit as from the model's own terms, each fixed term's cosine and sine taken
    where it is summed (VectorLoops.of_terms, the design engines' way)."""
    from linkage.kinematics.vector_loops import DRIVER, LoopPlan, VectorLoops

    m = load(SAMPLES / f"{name}.toml")
    rng = np.random.default_rng(7)
    drv = rng.uniform(-7.0, 7.0, 53)
    terms = [[(sign, drv if li == DRIVER else lc, li if li >= 0 else -1, drv if ai == DRIVER else ac,
               ai if ai >= 0 else -1, off) for sign, lc, li, ac, ai, off in loop] for loop in m.model.terms]
    q = [rng.uniform(-3.0, 3.0, 53) * (1.0 if u.kind == "angle" else m.length_scale) for u in m.unknowns]
    want = VectorLoops.of_terms(terms, m.model.n, 53).evaluate(q, None)
    for loops in (VectorLoops(m.model, drv), VectorLoops(LoopPlan.of(m.model), drv)):
        got = loops.evaluate(q, None)
        assert all(np.array_equal(a, b) for a, b in zip(got[0], want[0]))
        assert all(np.array_equal(np.broadcast_to(a, (53,)), np.broadcast_to(b, (53,)))
                   for ra, rb in zip(got[1], want[1]) for a, b in zip(ra, rb))


# --- finding: batch sweeps drop rates -------------------------------------------------------------

def _csv(text: str) -> tuple[list[str], list[list[str]]]:
    rows = list(csv.reader(io.StringIO(text)))
    return rows[0], rows[1:]


def test_batch_sweeps_keep_rate_and_joint_columns(cli):
    """Batch sweeps drop rates: `--batch --speed` printed no velocity, acceleration or joint
    column (and exited 0). Now the batch's CSV has the one-at-a-time sweep's columns and
    numbers, and its rates equal the closed form's derivatives."""
    args = ("sweep", str(SAMPLES / "slider_crank.toml"), "--points", "37", "--speed", "10", "--accel", "2",
            "--format", "csv")
    one, many = cli(*args, "--no-batch"), cli(*args, "--batch")
    assert one.code == 0 and many.code == 0, many.err
    head_1, rows_1 = _csv(one.out)
    head_b, rows_b = _csv(many.out)
    assert head_b == head_1
    assert any("dtheta3/dt" in h for h in head_b) and any("B.ax" in h for h in head_b)
    skip = {head_b.index("iterations")}  # how many steps each engine took, not a result
    for r1, rb in zip(rows_1, rows_b, strict=True):
        for j, (a, b) in enumerate(zip(r1, rb, strict=True)):
            if j in skip:
                continue
            try:
                x, y = float(a), float(b)
            except ValueError:
                assert a == b
                continue
            if " bound" in head_b[j]:
                # a bound is an estimate from each engine's own position (equal to ~tol),
                # not a result: the same size, not the same digits
                assert 0.5 * x <= y <= 2.0 * x, (head_b[j], a, b)
                continue
            assert abs(x - y) <= 1e-12 * max(1.0, abs(x)), (head_b[j], a, b)
    col = {h: j for j, h in enumerate(head_b)}
    for row in rows_b:
        t2 = float(row[0])
        _, _, w3, v, a3, acc = slider_crank_exact(t2, 10.0, 2.0)
        assert float(row[col["dtheta3/dt (rad/s)"]]) == pytest.approx(w3, rel=1e-10, abs=1e-12)
        assert float(row[col["ds/dt (mm/s)"]]) == pytest.approx(v, rel=1e-10, abs=1e-10)
        assert float(row[col["d2theta3/dt2 (rad/s^2)"]]) == pytest.approx(a3, rel=1e-10, abs=1e-10)
        assert float(row[col["d2s/dt2 (mm/s^2)"]]) == pytest.approx(acc, rel=1e-10, abs=1e-8)


def test_batch_sweeps_keep_rates_in_json(cli):
    """The same finding in JSON: each position's velocities, accelerations and joints."""
    args = ("sweep", str(SAMPLES / "crank_rocker.toml"), "--points", "13", "--speed", "5", "--format", "json")
    one, many = json.loads(cli(*args, "--no-batch").out), json.loads(cli(*args, "--batch").out)
    assert many["driver_motion"] == one["driver_motion"] == {"speed": 5.0, "accel": 0.0}
    for p1, pb in zip(one["positions"], many["positions"], strict=True):
        assert set(pb) == set(p1)
        assert pb["velocities"].keys() == p1["velocities"].keys() and pb["velocities"]


def test_sweeps_above_the_batch_threshold_keep_rates():
    """A sweep over 20,000 positions (the batch engine by default) has rates too."""
    m = load(SAMPLES / "slider_crank.toml")
    values = np.linspace(0.0, 360.0, 20_001)
    result = linkage.sweep(m, values, speed=10.0)
    assert result.method == "newton (batch)" and result.motion == (10.0, 0.0)
    for i in (0, 7_777, 20_000):
        p = result.positions[i]
        w3 = slider_crank_exact(p.input, 10.0)[2]
        assert p.rates.velocities["theta3"] == pytest.approx(w3, rel=1e-10)
        assert set(p.rates.joints) == {"O2", "A", "B"}


def test_batch_path_plot_draws_the_curve(cli, monkeypatch, tmp_path):
    """`--batch --path P --plot` drew an empty curve (no position had joints). Now the
    curve has a finite point at every position, equal to the one-at-a-time sweep's."""
    import linkage.render.plots as plots

    drawn: dict[str, list[tuple[list[float], list[float]]]] = {}

    def fake_pyplot():
        fig, ax = mock.MagicMock(), mock.MagicMock()

        def plot(xs, ys, *args, label=None, **kw):
            drawn.setdefault(label, []).append((list(xs), list(ys)))

        ax.plot.side_effect = plot
        return mock.MagicMock(subplots=mock.MagicMock(return_value=(fig, ax)))

    monkeypatch.setattr(plots, "pyplot", fake_pyplot)
    monkeypatch.setattr(plots, "save_figure", lambda fig, path: None)
    curves = {}
    for engine in ("--batch", "--no-batch"):
        drawn.clear()
        run = cli("sweep", str(SAMPLES / "crank_rocker.toml"), "--points", "37", engine, "--path", "P",
                  "--plot", str(tmp_path / "p.png"))
        assert run.code == 0, run.err
        (xs, ys), = drawn["P"]
        curves[engine] = (xs, ys)
        assert len(xs) == 37 and all(map(math.isfinite, xs + ys))
    np.testing.assert_allclose(curves["--batch"], curves["--no-batch"], rtol=1e-12, atol=1e-12)


# --- batch and one-at-a-time give the same on every sample --------------------------------------

def _flat(p) -> dict[tuple[str, ...], float]:
    out: dict[tuple[str, ...], float] = {}
    if p.solution:
        out.update({("q", k): v for k, v in p.solution.items()})
    r = p.rates
    if r is not None:
        for attr in ("velocities", "accelerations"):
            out.update({(attr, k): v for k, v in getattr(r, attr).items()})
        for attr in ("joints", "joint_velocities", "joint_accelerations"):
            for k, (x, y) in getattr(r, attr).items():
                out[(attr, k, "x")], out[(attr, k, "y")] = x, y
    return out


def _bounds(p) -> dict[tuple[str, ...], float]:
    """Each rate's stated error bound, keyed as :func:`_flat` keys its value."""
    r = p.rates
    out: dict[tuple[str, ...], float] = {}
    if r is None:
        return out
    for attr, bounds in (("velocities", r.velocity_bounds), ("accelerations", r.acceleration_bounds)):
        out.update({(attr, k): b for k, b in bounds.items()})
    for attr, bounds in (("joint_velocities", r.joint_velocity_bounds),
                         ("joint_accelerations", r.joint_acceleration_bounds)):
        for k, b in bounds.items():
            out[(attr, k, "x")] = out[(attr, k, "y")] = b
    return out


@pytest.mark.parametrize("name", SAMPLE_NAMES)
def test_batch_and_one_at_a_time_sweeps_agree_on_every_sample(name):
    """Same statuses, branch, toggles, columns and numbers (positions, rates, joints and
    points) to 1e-12 of each column's largest value. A rate may differ by more only within
    the two engines' stated bounds added up (each is within its bound of the truth): near
    a limit the conditioning of J amplifies the positions' last-digit differences."""
    m = load(SAMPLES / f"{name}.toml")
    # offset_slider's gaps are classified one position at a time (Newton, damped Newton and
    # least squares from several guesses): fewer positions keep the test fast
    values = driver_values(0.0, 360.0, None, 181 if name == "offset_slider" else 721)
    one = linkage.sweep(m, values, batch=False, speed=10.0, accel=3.0)
    many = linkage.sweep(m, values, batch=True, speed=10.0, accel=3.0)
    assert many.method == "newton (batch)"
    assert (many.names, many.units, many.branch) == (one.names, one.units, one.branch)
    assert many.motion == one.motion == (10.0, 3.0)
    # limits and toggles are located by bisection to LOCATE_TOL (1e-9 deg), each engine from
    # its own bracket
    assert many.toggles == pytest.approx(one.toggles, rel=0.0, abs=LOCATE_TOL)
    assert many.feasible_ranges == one.feasible_ranges
    assert [p.status for p in many.positions] == [p.status for p in one.positions]
    flat_1 = [_flat(p) for p in one.positions]
    flat_b = [_flat(p) for p in many.positions]
    size: dict[tuple[str, ...], float] = {}
    for f in flat_1:
        for k, v in f.items():
            size[k] = max(size.get(k, 0.0), abs(v))
    wider = 0
    for p1, pb, f1, fb in zip(one.positions, many.positions, flat_1, flat_b, strict=True):
        assert (pb.rates is None) == (p1.rates is None)
        if p1.rates is not None:
            assert pb.rates.status == p1.rates.status
        assert fb.keys() == f1.keys(), p1.input
        b1, bb = _bounds(p1), _bounds(pb)
        for k, v in f1.items():
            close = abs(fb[k] - v) <= 1e-12 * max(size[k], 1e-300)
            if not close:
                wider += 1
                assert abs(fb[k] - v) <= b1[k] + bb[k], (name, p1.input, k, v, fb[k], b1.get(k))
    assert wider <= 0.01 * sum(len(f) for f in flat_1)  # the rule, not the exception


# --- the rules: each numpy twin equals its scalar ---------------------------------------------------

def _awkward(rng: np.random.Generator, n: int) -> np.ndarray:
    """Random magnitudes over 40 decades, both signs, with zeros, NaN and infinities, and
    exact ties (every value repeated somewhere)."""
    x = rng.choice([-1.0, 1.0], n) * 10.0 ** rng.uniform(-20, 20, n)
    x[rng.random(n) < 0.05] = 0.0
    x[rng.random(n) < 0.03] = np.nan
    x[rng.random(n) < 0.03] = np.inf
    x[rng.random(n) < 0.03] = -np.inf
    ties = rng.random(n) < 0.1
    x[ties] = rng.permutation(x)[ties]
    return x


@pytest.mark.parametrize("seed", range(5))
def test_system_convergence_twin_equals_the_scalar(seed):
    rng = np.random.default_rng(seed)
    n = 4000
    err, resid, gate = np.abs(_awkward(rng, n)), np.abs(_awkward(rng, n)), np.abs(_awkward(rng, n))
    limit = np.where(rng.random(n) < 0.3, err, np.abs(_awkward(rng, n)))  # ties at the boundary
    with np.errstate(invalid="ignore"):
        got = rules.system_converged_array(err, resid, limit, gate)
    want = [rules.system_converged(*map(float, t)) for t in zip(err, resid, limit, gate)]
    assert got.dtype == bool and list(got) == want
    # the limit and the gate: arrays of scales give each scalar's value
    tol, rtol = 1e-9, 1e-13
    size_q = np.abs(_awkward(rng, n))
    np.testing.assert_array_equal(rules.step_limit(tol, rtol, size_q),
                                  [rules.step_limit(tol, rtol, float(s)) for s in size_q])
    np.testing.assert_array_equal(rules.residual_gate(tol, size_q),
                                  [rules.residual_gate(tol, float(s)) for s in size_q])


@pytest.mark.parametrize("seed", range(5))
def test_step_size_twin_equals_the_scalar(seed):
    rng = np.random.default_rng(100 + seed)
    n = 2000
    for k in (1, 2, 3, 5):
        step = [_awkward(rng, n) for _ in range(k)]
        kinds = list(rng.choice(["angle", "length"], k))
        size = float(10.0 ** rng.uniform(-8, 8))
        scales = rules.step_scales(kinds, size)
        with np.errstate(invalid="ignore"):
            got = rules.step_size_array(step, scales)
        want = [rules.step_size([float(c[i]) for c in step], scales) for i in range(n)]
        np.testing.assert_array_equal(got, want)
        # per-position scales (one per design) as arrays
        sizes = 10.0 ** rng.uniform(-8, 8, n)
        arr_scales = [sizes if kd == "length" else 1.0 for kd in kinds]
        got = rules.step_size_array(step, arr_scales)
        want = [rules.step_size([float(c[i]) for c in step],
                                [float(sizes[i]) if kd == "length" else 1.0 for kd in kinds])
                for i in range(n)]
        np.testing.assert_array_equal(got, want)


def test_step_size_is_the_solvers_step_measure():
    """The lean loops measure their step with methods.newton_system.step_measure: the same."""
    from linkage.methods.newton_system import step_measure

    rng = np.random.default_rng(7)
    for _ in range(2000):
        k = int(rng.integers(1, 5))
        step = list(rng.normal(size=k) * 10.0 ** rng.uniform(-15, 3, k))
        scales = None if rng.random() < 0.3 else tuple(10.0 ** rng.uniform(-6, 6, k))
        assert rules.step_size(step, scales) == step_measure(step, scales)


@pytest.mark.parametrize("seed", range(5))
def test_continuity_twin_equals_the_scalar(seed):
    rng = np.random.default_rng(200 + seed)
    n = 4000
    correction, moved = np.abs(_awkward(rng, n)), np.abs(_awkward(rng, n))
    dv, size = _awkward(rng, n) * 1e-15, 1.0 + np.abs(_awkward(rng, n))
    # a share exactly at the boundary
    edge = rng.random(n) < 0.2
    correction[edge] = (0.5 * moved + (rules.CONTINUITY_ROUNDING + rules.CONTINUITY_CURVATURE * dv * dv)
                        * size)[edge]
    with np.errstate(invalid="ignore", over="ignore"):
        got = rules.continues_array(correction, moved, dv, size)
    want = [rules.continues(*map(float, t)) for t in zip(correction, moved, dv, size)]
    assert list(got) == want
    # the measures, from three points of k unknowns
    for k in (1, 2, 4):
        q_last, pred, q = ([rng.normal(size=n) * 10.0 ** rng.uniform(-3, 3) for _ in range(k)]
                           for _ in range(3))
        arrays = rules.continuity_measures_array(q_last, pred, q)
        for i in range(0, n, 37):
            one = rules.continuity_measures([float(c[i]) for c in q_last], [float(c[i]) for c in pred],
                                            [float(c[i]) for c in q])
            assert one == tuple(float(a[i]) for a in arrays)


def test_continuity_rule_is_the_sweeps():
    """The scalar rule is the continuation's documented one: the correction at most half the
    predicted change plus (1e-7 + 10 dv^2)(1 + max|q|), NaN refused."""
    assert rules.continues(0.5, 1.0, 0.0, 1.0)                     # 0.5 <= 0.5 + 1e-7
    assert not rules.continues(0.5 + 2e-7, 1.0, 0.0, 1.0)
    assert rules.continues(0.5 + 10.0 * 0.01 * 3.0, 1.0, 0.1, 3.0)  # curvature term, size 3
    assert not rules.continues(math.nan, 1.0, 0.1, 3.0)


@pytest.mark.parametrize("seed", range(3))
def test_solved_ranges_twin_equals_the_sweeps(seed):
    """The batch's feasible ranges (without a closed form) were the coarse pass's, as coarse
    as its grid (offset_slider: [16, 132] where the sweep says [15.5, 132]). Now they are
    the positions' own, by the array twin of the sweep's rule."""
    from linkage.kinematics.limits import solved_ranges
    from linkage.kinematics.positions import Position

    rng = np.random.default_rng(300 + seed)
    for n in (0, 1, 2, 3, 10, 200):
        values = np.sort(rng.uniform(-400, 400, n))
        for p_on in (0.1, 0.5, 0.9):
            ok = rng.random(n) < p_on
            positions = [Position(float(v), "converged" if c else "no_solution", None, None, 0, None)
                         for v, c in zip(values, ok)]
            assert solved_ranges_array(values, ok) == solved_ranges(positions)


@pytest.mark.parametrize("max_iter", [1, 2])
def test_batch_sweep_honours_the_iteration_cap(max_iter):
    """The iteration cap is a stopping rule too: the batch ran up to 30 vectorised and 50
    one-at-a-time iterations whatever ``max_iter`` the caller gave (with max_iter=1 it
    reported positions that took 2). Now no position takes more, and the statuses are the
    one-at-a-time sweep's."""
    m = load(SAMPLES / "crank_rocker.toml")
    values = driver_values(0.0, 360.0, None, 361)
    one = linkage.sweep(m, values, batch=False, max_iter=max_iter)
    many = linkage.sweep(m, values, batch=True, max_iter=max_iter)
    assert max(p.iterations for p in many.positions) <= max_iter
    assert [p.status for p in many.positions] == [p.status for p in one.positions]

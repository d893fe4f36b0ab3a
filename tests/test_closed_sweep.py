"""The closed-form sweep engine (kinematics/closed.py): the same answers as the
one-at-a-time engine wherever it applies, positions that are roots to the stated
tolerance (checked here at 50 digits from the sample files' own text), the fallbacks, and
the numpy twins of the rules it reads. No timings: `linkage bench` (and
benchmarks/closed_sweep.py) measure those."""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import tomllib

from linkage.errors import InputError
from linkage.kinematics.loading import load
from linkage.kinematics.stepwise import sweep as one_at_a_time
from linkage.kinematics.sweep import sweep_mechanism
from linkage.samples import sample_path

CLOSED = "newton (closed form)"
FULL = [float(k) for k in range(361)]

CASES = [
    ("crank_rocker.toml", None, FULL),
    ("crank_rocker.toml", "open", FULL),
    ("crank_rocker.toml", "crossed", FULL),
    ("slider_crank.toml", None, FULL),
    ("slider_crank.toml", "open", FULL),
    ("slider_crank.toml", "crossed", FULL),
    ("watt_sixbar.toml", None, FULL),
    # a non-Grashof triple rocker: its limits are at 112.02 and 247.98 deg, so 0..360 is
    # the one-at-a-time engine's (test_a_limit_inside_falls_back); each feasible arc alone
    # is the closed-form engine's
    ("fourbar_me581.toml", None, [float(k) for k in range(0, 113)]),
    ("fourbar_me581.toml", "open", [float(k) for k in range(248, 361)]),
    ("fourbar_me581.toml", "crossed", [float(k) for k in range(0, 113)]),
    ("fourbar_me581.toml", "crossed", [float(k) for k in range(248, 361)]),
    # driven by its rocker (feasible from 104.48 to 255.52 deg): the configuration's name
    # is the same as under the crank; each name on an arc where it stays on one sign
    ("fourbar_me581_theta4.toml", None, [float(k) for k in range(106, 130)]),
    ("fourbar_me581_theta4.toml", "open", [float(k) for k in range(106, 130)]),
    ("fourbar_me581_theta4.toml", "crossed", [float(k) for k in range(210, 250)]),
]


def _close(a, b, what):
    """Equal within 1e-12 relative to the column's largest value (None/NaN alike)."""
    a = np.array([np.nan if x is None else x for x in a], dtype=float)
    b = np.array([np.nan if x is None else x for x in b], dtype=float)
    assert np.array_equal(np.isnan(a), np.isnan(b)), what
    if np.isnan(b).all():
        return
    big = np.nanmax(np.abs(b))
    assert np.nanmax(np.abs(a - b)) <= 1e-12 * big, (what, np.nanmax(np.abs(a - b)), big)


@pytest.mark.parametrize("name,branch,values", CASES,
                         ids=[f"{c[0].removesuffix('.toml')}-{c[1]}-{c[2][0]:g}" for c in CASES])
def test_the_closed_form_engine_equals_the_one_at_a_time_engine(name, branch, values):
    _assert_same(load(sample_path(name)), values, branch)


SLIDER_DRIVEN = """
name = "Slider-driven crank"
length_unit = "mm"

[parameters]
r2 = { value = 40, unit = "mm" }
r3 = { value = 120, unit = "mm" }
e = { value = 10, unit = "mm", signed = true }

[driver]
name = "s"
value = 140
unit = "mm"

[unknowns]
theta2 = { guess = 40, unit = "deg" }
theta3 = { guess = -10, unit = "deg" }

[[loops]]
name = "O2-A-B"
vectors = [
  { length = "r2", angle = "theta2" },
  { length = "r3", angle = "theta3" },
  { length = "s", angle = 0, sign = -1 },
  { length = "e", angle = 90, sign = -1 },
]
"""


def test_a_length_driver_equals_the_one_at_a_time_engine(tmp_path):
    """The offset slider-crank driven by its slider (a length), 100..150 mm: the crank
    and coupler from two circles, stepwise."""
    path = tmp_path / "slider_driven.toml"
    path.write_text(SLIDER_DRIVEN)
    _assert_same(load(path), [100.0 + 0.5 * k for k in range(101)], None)


def _assert_same(m, values, branch):
    fast = sweep_mechanism(m, values, branch=branch)
    ref = one_at_a_time(m, values, branch=branch)
    assert fast.method == CLOSED and ref.method == "newton"
    assert [p.status for p in fast.positions] == [p.status for p in ref.positions]
    assert fast.summary == ref.summary == {"converged": len(values)}
    for col in ref.names:
        _close(fast.column(col), ref.column(col), col)
    _close([p.det for p in fast.positions], [p.det for p in ref.positions], "det")
    _close([p.transmission for p in fast.positions], [p.transmission for p in ref.positions],
           "transmission")
    assert [p.input for p in fast.positions] == [p.input for p in ref.positions]
    assert (fast.names, fast.units, fast.driver, fast.driver_unit) == \
        (ref.names, ref.units, ref.driver, ref.driver_unit)
    assert fast.feasible_ranges == ref.feasible_ranges
    assert fast.toggles == ref.toggles == ()
    assert fast.classification == ref.classification
    # the labels: where the one-at-a-time engine names the branch (the old closed-form key),
    # the same name; where it can only give the sign of det J (the Watt six-bar), the name
    # of its own configurations (the derivation's word rule), the same at every position;
    # where the names cut across the signs (driven by the rocker), the followed signs, the
    # same as the one-at-a-time engine's, and each position its own configuration's name
    labels = {p.branch for p in fast.positions}
    if m.driver.name == "theta4":
        d = m.derivation
        signs = {d.signs_of([math.radians(p.solution[n]) for n in ref.names], math.radians(p.input))
                 for p in fast.positions}
        assert len(signs) == 1 and fast.branch == ref.branch == "+-"[signs.pop()[0] < 0]
        assert [p.branch for p in fast.positions] == [p.branch for p in ref.positions]
        for p in fast.positions:
            t3 = math.radians(p.solution["theta3"])
            assert p.branch == ("open" if math.sin(math.radians(p.input) - t3) > 0 else "crossed")
        assert branch is None or branch in labels
    elif ref.branch.startswith("det"):
        assert labels == {fast.branch}
        d = m.derivation
        first = ref.positions[0]
        q = [math.radians(first.solution[n]) if u.kind == "angle" else first.solution[n]
             for n, u in zip(ref.names, m.unknowns)]
        drv = math.radians(first.input) if m.driver.kind == "angle" else first.input
        assert fast.branch == d.name_of(q, drv)
    else:
        assert labels == {fast.branch}
        assert [p.branch for p in fast.positions] == [p.branch for p in ref.positions]
        assert fast.branch == ref.branch == (branch or ref.branch)
    # no Newton step: at every position the closed form itself meets the single solve's
    # convergence test (Phi and J evaluated there, the step they imply within tol)
    assert {p.iterations for p in fast.positions} == {0}


def _file_residual(path, driver_deg, solution, dps=50):
    """max |loop closure| at 50 digits, from the sample file's text alone."""
    doc = tomllib.loads(path.read_text())
    with mp.workdps(dps):
        known = {}
        for k, q in doc["parameters"].items():
            v = mp.mpf(q["value"])
            known[k] = v * mp.pi / 180 if q.get("unit") == "deg" else v
        known[doc["driver"]["name"]] = mp.mpf(driver_deg) * mp.pi / 180
        for k, v in solution.items():
            unit = doc["unknowns"][k].get("unit")
            known[k] = mp.mpf(v) * mp.pi / 180 if unit == "deg" else mp.mpf(v)

        def value(x, angle):
            if isinstance(x, str):
                return known[x]
            return mp.mpf(x) * mp.pi / 180 if angle else mp.mpf(x)

        worst = mp.mpf(0)
        for loop in doc["loops"]:
            x = y = mp.mpf(0)
            for vec in loop["vectors"]:
                r = vec.get("sign", 1) * value(vec["length"], False)
                t = value(vec["angle"], True) + mp.mpf(vec.get("offset", 0)) * mp.pi / 180
                x += r * mp.cos(t)
                y += r * mp.sin(t)
            worst = max(worst, abs(x), abs(y))
        return float(worst)


@pytest.mark.parametrize("name", ["crank_rocker.toml", "slider_crank.toml", "watt_sixbar.toml"])
def test_the_positions_are_roots_to_the_tolerance(name):
    """Each reported position closes the file's loops to tol x its length scale (the
    single solve's residual gate), at 50 digits."""
    path = sample_path(name)
    m = load(path)
    tol = 1e-12
    fast = sweep_mechanism(m, FULL, tol=tol)
    assert fast.method == CLOSED
    gate = tol * m.length_scale
    for p in list(fast.positions)[::7]:
        assert _file_residual(path, p.input, p.solution) <= gate, p.input


def test_a_limit_inside_falls_back_to_the_one_at_a_time_engine():
    m = load(sample_path("fourbar_me581.toml"))
    fast = sweep_mechanism(m, FULL)
    ref = one_at_a_time(m, FULL)
    assert fast.method == "newton"
    assert fast.toggles == ref.toggles and len(fast.toggles) == 2
    assert fast.summary == ref.summary


def test_a_branch_name_with_no_assembly_is_refused_by_both_engines():
    """Driven by its rocker, both assemblies of the four-bar at 106..129 deg are named open
    (open and open (mirror)): there is no crossed one to follow anywhere in the range, and
    both engines say so (InputError naming branch and what assembles there)."""
    m = load(sample_path("fourbar_me581_theta4.toml"))
    values = [float(k) for k in range(106, 130)]
    for run in (lambda: sweep_mechanism(m, values, branch="crossed"),
                lambda: one_at_a_time(m, values, branch="crossed")):
        with pytest.raises(InputError, match=r"branch: no 'crossed' assembly anywhere in theta4 = "
                                             r"106\.\.129 deg; at 106: open, open \(mirror\)"):
            run()


@pytest.mark.parametrize("kw", [{"method": "lm"}, {"method": "newton-fd"}, {"batch": False}])
def test_other_methods_and_the_switch_take_the_one_at_a_time_engine(kw):
    m = load(sample_path("crank_rocker.toml"))
    got = sweep_mechanism(m, FULL[:20], **kw)
    assert got.method == kw.get("method", "newton")


def test_a_coupled_mechanism_is_not_the_closed_form_engines():
    m = load(sample_path("offset_slider.toml"))
    assert not m.derivation.complete
    got = sweep_mechanism(m, [float(k) for k in range(0, 30)])
    assert got.method == "newton"


def test_unsorted_or_single_values_take_the_one_at_a_time_engine():
    m = load(sample_path("crank_rocker.toml"))
    assert sweep_mechanism(m, [10.0, 5.0, 20.0]).method == "newton"
    assert sweep_mechanism(m, [10.0]).method == "newton"
    assert sweep_mechanism(m, [10.0, 11.0]).method == CLOSED


def test_the_fast_path_still_refuses_bad_input():
    from linkage.errors import InputError

    m = load(sample_path("crank_rocker.toml"))
    with pytest.raises(InputError, match="driver theta2"):
        sweep_mechanism(m, [0.0, 1e300])


def test_the_positions_stay_columns_until_read():
    from linkage.kinematics.batch import BatchPositions

    m = load(sample_path("watt_sixbar.toml"))
    fast = sweep_mechanism(m, FULL)
    assert isinstance(fast.positions, BatchPositions)
    assert fast.positions[-1].input == 360.0 and fast.positions[-1].status == "converged"


def test_rates_equal_the_one_at_a_time_engines():
    m = load(sample_path("crank_rocker.toml"))
    values = [float(k) for k in range(0, 361, 15)]
    fast = sweep_mechanism(m, values, speed=10.0)
    ref = sweep_mechanism(m, values, speed=10.0, batch=False)
    assert fast.method == CLOSED and ref.method == "newton" and fast.motion == ref.motion
    for a, b in zip(fast.positions, ref.positions):
        for n in m.unknowns:
            va, vb = a.rates.velocities[n.name], b.rates.velocities[n.name]
            assert abs(va - vb) <= 1e-9 * (1.0 + abs(vb)), (a.input, n.name)


def test_the_crank_rockers_angles_read_as_solve_file_gives_them():
    """The anchoring rule: at the file's driver value (30 deg) the sweep reads as
    ``solve FILE`` reports it (Newton from the file's guess), whatever turn the closed
    form's atan2 gave."""
    from linkage.solve import solve_system

    m = load(sample_path("crank_rocker.toml"))
    fast = sweep_mechanism(m, FULL)
    r = solve_system(m.problem(), tuple(u.value for u in m.unknowns), tol=1e-12)
    at30 = fast.positions[30].solution
    for n, x in zip(fast.names, r.x):
        assert abs(at30[n] - math.degrees(x)) < 1e-9


# --- the numpy twins it reads ----------------------------------------------------------------

@pytest.mark.parametrize("name", ["crank_rocker.toml", "slider_crank.toml", "watt_sixbar.toml",
                                  "fourbar_me581.toml", "fourbar_me581_theta4.toml"])
def test_the_driver_trig_given_changes_no_bit(name):
    """The closed-form and batch engines take the driver's cosine and sine once and give them
    to solve_margins_np, on_branch_np and VectorLoops (driver_trig): the same bits as each
    taking its own,
    -0.0 among the drivers included (sin(-0.0) keeps the sign; the sums begin at 0.0)."""
    from linkage.kinematics.vector_loops import VectorLoops, loop_plan

    m = load(sample_path(name))
    d = m.derivation
    drv = np.radians(np.arange(-180.0, 180.0, 0.7))
    drv[0] = -0.0
    trig = (np.cos(drv), np.sin(drv))
    q_pos = [np.full(len(drv), u.value) for u in m.unknowns]
    for signs in d.branches:
        own, given = d.solve_margins_np(drv, signs), d.solve_margins_np(drv, signs, driver_trig=trig)
        for a, b in zip([*own[0], own[1], *own[2]], [*given[0], given[1], *given[2]]):
            assert np.array_equal(a, b, equal_nan=True)
            assert np.array_equal(np.signbit(a), np.signbit(b))
    from linkage.problems.derive import read_branch

    for signs in d.branches:  # the batch engine's branch rule, read with signs: the same verdicts
        q, ok, _ = d.solve_margins_np(drv, signs)
        q = [np.where(ok, c, 0.3) for c in q]
        want = read_branch(d, "".join("+" if x > 0 else "-" for x in signs))
        assert np.array_equal(d.on_branch_np(q, drv, want), d.on_branch_np(q, drv, want, driver_trig=trig))
        coefs = zip(d.two_way_coefficients_np(q, drv), d.two_way_coefficients_np(q, drv, None, trig))
        for own, given in coefs:
            for x, y in zip([v for pair in own for v in pair], [v for pair in given for v in pair]):
                x, y = np.broadcast_to(x, drv.shape), np.broadcast_to(y, drv.shape)
                assert np.array_equal(x, y, equal_nan=True) and np.array_equal(np.signbit(x), np.signbit(y))
    assert loop_plan(m).driver_angle
    (phi, jac), (phi2, jac2) = (VectorLoops(loop_plan(m), drv, t).evaluate(q_pos, None) for t in (None, trig))
    for x, y in zip([*phi, *(v for row in jac for v in row)], [*phi2, *(v for row in jac2 for v in row)]):
        x, y = np.broadcast_to(x, drv.shape), np.broadcast_to(y, drv.shape)
        assert np.array_equal(x, y) and np.array_equal(np.signbit(x), np.signbit(y))


@pytest.mark.parametrize("name", ["crank_rocker.toml", "slider_crank.toml", "watt_sixbar.toml",
                                  "fourbar_me581.toml"])
def test_solve_margins_np_equals_the_scalar_path(name):
    m = load(sample_path(name))
    d = m.derivation
    drv = np.radians(np.arange(0.0, 360.0, 7.0))
    for signs in d.branches:
        q, ok, margins = d.solve_margins_np(drv, signs)
        q2, ok2 = d.solve_np(drv, signs)
        assert np.array_equal(ok, ok2)
        for a, b in zip(q, q2):
            assert np.array_equal(a, b, equal_nan=True)
        for i, v in enumerate(drv):
            want = d.margins(float(v), signs)
            got = [float(mg[i]) for mg in margins]
            assert got == pytest.approx(want, rel=1e-12, abs=1e-15, nan_ok=True)
            s = d.solve(float(v), signs)
            assert ok[i] == (s is not None)
            if s is not None:
                assert [float(c[i]) for c in q] == pytest.approx(s, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("grid", [
    FULL, FULL[:-1], [float(k) for k in range(0, 359, 2)], [0.0, 90.0, 180.0, 270.0], [0.0, 1.0],
    [float(k) for k in range(360, -1, -1)], [0.0, 1.0, 1.0, 2.0], [5.0], [],
    [0.1 * k for k in range(3601)], [0.0, 100.0, 200.0, 300.0, 380.0], [0.0, float("nan")],
])
def test_closes_circle_array_is_its_scalar(grid):
    from linkage.kinematics.angles import closes_circle, closes_circle_array

    assert closes_circle_array(np.array(grid)) == closes_circle(grid)
    assert closes_circle_array(np.array(grid), 2 * math.pi) == closes_circle(grid, 2 * math.pi)
    # with the grid's np.diff given (the closed-form engine takes it once): the same verdict
    diff = np.diff(np.array(grid, dtype=float))
    assert closes_circle_array(np.array(grid), 360.0, diff) == closes_circle(grid)


def test_anchor_index_array_every_position_solved_is_the_masked_rule():
    """anchor_index_array with solved=True (the closed-form engine: no masked copy) gives
    what the masked path gives with every position solved, ties to the first, and the
    scalar rule's index."""
    from linkage.kinematics.angles import anchor_index, anchor_index_array

    grid = np.arange(0.0, 360.0, 0.5)
    for v0, closes in ((30.0, True), (359.9, True), (359.9, False), (-45.25, True), (90.25, False)):
        got = anchor_index_array(grid, True, v0, closes)
        masked = anchor_index_array(grid, np.ones((1, len(grid)), bool), v0, closes)
        assert got.shape == (1,) and got[0] == masked[0]
        assert got[0] == anchor_index(list(grid), [True] * len(grid), v0, closes)


def test_unwrap_turns_array_every_position_solved_is_the_scalar_rule():
    from linkage.kinematics.angles import unwrap_turns, unwrap_turns_array

    rng = np.random.default_rng(19)
    rows = np.cumsum(rng.uniform(-170.0, 170.0, size=(6, 50)), axis=1)
    rows = (rows + 180.0) % 360.0 - 180.0  # wrapped, as atan2 gives them
    for closes in (True, False):
        got = unwrap_turns_array(rows, closes)
        for row, turns in zip(rows, got):
            assert list(turns) == unwrap_turns(list(row), closes)
        # and the general path (a row with a gap) still gives the scalar's
        gappy = rows.copy()
        gappy[:, 10:13] = np.nan
        got = unwrap_turns_array(gappy, closes)
        for row, turns in zip(gappy, got):
            want = unwrap_turns([None if math.isnan(x) else x for x in row], closes)
            assert [None if math.isnan(t) else t for t in turns] == want


# --- the bench rows --------------------------------------------------------------------------

def test_the_sweep_targets_are_judged_from_one_runs_medians():
    from linkage.measure.sweeps import WATT_CLOSED, WATT_ONE, sweep_targets, targets

    rows = sweep_targets({"linkage.sweep 361 positions": 0.001, "pylinkage step_fast 361 positions": 0.0035,
                          WATT_CLOSED: 0.004, WATT_ONE: 0.1})
    assert rows[0][0].startswith("3.") and rows[0][2] == pytest.approx(3.5) and rows[0][3] is True
    assert rows[1][0].startswith("6.") and rows[1][2] == pytest.approx(25.0) and rows[1][3] is True
    slow = sweep_targets({"linkage.sweep 361 positions": 0.002, "pylinkage step_fast 361 positions": 0.0035,
                          WATT_CLOSED: 0.03, WATT_ONE: 0.1})
    assert slow[0][3] is False and slow[1][3] is False
    # without pylinkage (or a run that did not time it) the row is there, not judged
    alone = sweep_targets({"linkage.sweep 361 positions": 0.001})
    assert alone[0][2] is None and alone[0][3] is None and alone[1][3] is None
    labels = [r[0][:2] for r in targets({})]
    assert "3." in labels and "6." in labels

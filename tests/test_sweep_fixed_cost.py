"""The closed-form sweep's fixed cost per call, cut without changing a result: the
results built without the frozen dataclasses' ``__init__`` equal the constructors', what
is cached on a mechanism can serve no other, and a sweep equals, field for field and bit
for bit, the one the uncached path (a fresh mechanism, nothing implied yet) gives, on
random four-bars over ranges that cross their limits, on both branches, at length scales
from 1e-6 to 1e3. No timings: benchmarks/sweep_floor.py measures them."""

from __future__ import annotations

import random
import re
from dataclasses import fields

import numpy as np
import pytest

import linkage
from linkage.kinematics.loading import parse_mechanism
from linkage.kinematics.positions import SweepResult, sweep_result


def test_a_sweep_result_built_fast_equals_the_constructor():
    assert [f.name for f in fields(SweepResult)] == [
        "mechanism", "driver", "driver_unit", "names", "units", "positions", "feasible_ranges", "toggles",
        "branch", "classification", "method", "motion", "length_unit", "meetings", "branch_note", "forces"]
    args = ("m", "theta2", "deg", ("theta3",), ("deg",), (), ((0.0, 1.0),), (2.0,), "open",
            {"grashof": "crank-rocker"}, "newton (closed form)", (1.0, 0.0), "mm", (0.5,))
    fast = sweep_result(*args)
    slow = SweepResult(*args[:11], motion=args[11], length_unit=args[12], meetings=args[13])
    assert fast == slow and repr(fast) == repr(slow) and vars(fast) == vars(slow)


def _bits(x):
    """A value as text that tells every float's bits apart (-0.0, NaN), containers element by element."""
    if isinstance(x, float):
        return x.hex()
    if isinstance(x, (list, tuple)):
        return "(" + ",".join(_bits(v) for v in x) + ")"
    if isinstance(x, dict):
        return "{" + ",".join(f"{k}:{_bits(v)}" for k, v in x.items()) + "}"
    return repr(x)


def _every_field(s: SweepResult) -> list[str]:
    """Every field of a sweep and of each of its positions, and its columns, as :func:`_bits`."""
    kept = [getattr(s, f.name) for f in fields(SweepResult) if f.name not in ("positions", "meetings")]
    out = [_bits(kept),
           _bits(tuple(s.meetings)), _bits(s.summary), _bits(s.inputs)]
    out += [_bits([getattr(p, f.name) for f in fields(p)]) for p in s.positions]
    out += [_bits([None if v is None else float(v) for v in s.column(name)]) for name in s.names]
    return out


def _fourbar(r, scale, guesses, drawn):
    """A four-bar (ground r1 on x, crank r2 driving, coupler r3, rocker r4), lengths times ``scale``."""
    return parse_mechanism({
        "name": "random four-bar", "length_unit": "mm",
        "parameters": {**{f"r{i + 1}": {"value": r[i] * scale, "unit": "mm"} for i in range(4)},
                       "theta1": {"value": 0, "unit": "deg"}},
        "driver": {"name": "theta2", "value": drawn, "unit": "deg"},
        "unknowns": {"theta3": {"guess": guesses[0], "unit": "deg"},
                     "theta4": {"guess": guesses[1], "unit": "deg"}},
        "loops": [{"name": "O2-A-B-O4", "vectors": [
            {"length": "r2", "angle": "theta2"}, {"length": "r3", "angle": "theta3"},
            {"length": "r4", "angle": "theta4", "sign": -1},
            {"length": "r1", "angle": "theta1", "sign": -1}]}]})


def _random_cases(seed: int, count: int):
    """(links, scale, guesses, drawn driver value, [(values, branch, tol)]): Grashof crank-rockers
    (crank shortest) and any four-bars (limits inside many ranges), at scales 1e-6 to 1e3."""
    rng = random.Random(seed)
    for _ in range(count):
        r = [rng.uniform(0.3, 3.0) for _ in range(4)]
        if rng.random() < 0.6:
            s, *others = sorted(r)
            rng.shuffle(others)
            r = [others[0], s, others[1], others[2]]
        sweeps = []
        for _ in range(3):
            lo = rng.choice([0.0, rng.uniform(-200.0, 200.0)])
            span = rng.choice([360.0, rng.uniform(1.0, 400.0)])
            values = [float(v) for v in np.linspace(lo, lo + span, rng.choice([2, 3, 7, 73, 361]))]
            branch = rng.choice([None, None, "open", "crossed"])
            sweeps.append((values, branch, rng.choice([1e-12, 1e-10, 1e-14])))
        yield (r, 10.0 ** rng.uniform(-6.0, 3.0), (rng.uniform(-180, 180), rng.uniform(-180, 180)),
               rng.uniform(0.0, 360.0), sweeps)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_a_mechanism_swept_again_gives_what_a_fresh_one_gives(seed):
    """What a sweep keeps on a mechanism (its plan, branch, anchor, loop plan, the first
    value's signs) changes no field of a later sweep: each sweep of a mechanism that has
    been swept before, over other values, branches and tolerances, equals bit for bit the
    same sweep of a fresh copy of it (nothing kept yet), on whichever engine it takes."""
    engines = set()
    for links, scale, guesses, drawn, sweeps in _random_cases(seed, 14):
        warm = _fourbar(links, scale, guesses, drawn)
        for values, branch, tol in sweeps:
            for again in range(2):
                try:
                    got = linkage.sweep(warm, values, branch=branch, tol=tol)
                except linkage.InputError as exc:
                    with pytest.raises(linkage.InputError, match=re.escape(str(exc))):
                        linkage.sweep(_fourbar(links, scale, guesses, drawn), values, branch=branch,
                                      tol=tol)
                    continue
                fresh = linkage.sweep(_fourbar(links, scale, guesses, drawn), values, branch=branch, tol=tol)
                assert _every_field(got) == _every_field(fresh), (links, scale, values[0], branch, again)
                engines.add(got.method)
    assert engines == {"newton", "newton (closed form)"}  # both engines were compared


SAMPLES_WITH_A_CLOSED_FORM = ["crank_rocker.toml", "crank_rocker_joints.toml", "fourbar_me581_theta4.toml",
                              "slider_crank.toml", "watt_sixbar.toml", "stephenson_sixbar_joints.toml",
                              "inverted_slider_crank.toml", "rapier_drive.toml"]


@pytest.mark.parametrize("name", SAMPLES_WITH_A_CLOSED_FORM)
def test_far_from_touch_is_the_product_of_the_column_lengths_at_every_position(name):
    """The closed engine's bound (far_from_touch) stands for the ratio |det J| / (product of
    J's columns' lengths) only where that product is the same at every position: at random
    unknowns and driver values it is that product (to rounding) times TOUCH_CANDIDATE, and
    |det J| above it means the ratio is above TOUCH_CANDIDATE; where a column's length
    varies (the inverted slider's slide on a turning line) there is no bound."""
    from linkage.kinematics.closed import TOUCH_SLACK, closed_plan
    from linkage.kinematics.limits import TOUCH_CANDIDATE
    from linkage.kinematics.vector_loops import VectorLoops, solve_linear
    from linkage.samples import sample_path

    m = linkage.load_mechanism(sample_path(name))
    plan = closed_plan(m)
    rng = np.random.default_rng(7)
    k = 2000
    drv = rng.uniform(-7.0, 7.0, k) if m.driver.kind == "angle" else rng.uniform(0.5, 2.0, k) * m.length_scale
    q = [rng.uniform(-7.0, 7.0, k) if u.kind == "angle" else rng.uniform(-2.0, 2.0, k) * m.length_scale
         for u in m.unknowns]
    phi, jac = VectorLoops(plan.loops, drv).evaluate(q, None)
    _, det = solve_linear(jac, phi, k)
    product = np.ones(k)
    for j in range(len(q)):
        product *= np.sqrt(sum(np.square(np.broadcast_to(row[j], (k,))) for row in jac))
    if name == "inverted_slider_crank.toml":
        assert plan.far_from_touch is None
        assert np.ptp(product) > 1e-3 * product.max()  # (its slide's column does vary)
        return
    assert plan.far_from_touch is not None
    exact = plan.far_from_touch / (TOUCH_CANDIDATE * (1.0 + TOUCH_SLACK))
    assert np.max(np.abs(product / exact - 1.0)) < 1e-13
    ratio = np.abs(det) / product
    assert ((np.abs(det) <= plan.far_from_touch) | (ratio > TOUCH_CANDIDATE)).all()


def test_the_closed_engines_columns_are_shown_when_first_read():
    """The closed engine's display columns (each angle unwrapped and anchored) are worked
    out at the first read of ``solution``, and are what the constructor would have held:
    the same array whether read first through the result, a position, a column, a pickle
    or a deep copy, and the work is not kept once done."""
    import copy
    import pickle

    from linkage.kinematics.batch import BatchResult
    from linkage.kinematics.closed import closed_sweep
    from linkage.samples import sample_path

    m = linkage.load_mechanism(sample_path("crank_rocker.toml"))
    values = [float(v) for v in range(0, 361, 5)]
    reference = closed_sweep(m, values)
    assert "solution" not in vars(reference)
    shown = reference.solution
    assert "solution_work" not in vars(reference) and reference.solution is shown
    built = BatchResult(**{f.name: getattr(reference, f.name) for f in fields(BatchResult)})
    for f in fields(BatchResult):
        a, b = getattr(built, f.name), getattr(reference, f.name)
        assert np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b, f.name
    reads = [lambda b: b.solution, lambda b: pickle.loads(pickle.dumps(b)).solution,
             lambda b: copy.deepcopy(b).solution,
             lambda b: np.column_stack([b.to_sweep().column(u.name) for u in m.unknowns])]
    for read in reads:
        got = read(closed_sweep(m, values))
        assert got.dtype == shown.dtype and got.shape == shown.shape
        assert got.tobytes() == shown.tobytes()
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        reference.nothing  # noqa: B018

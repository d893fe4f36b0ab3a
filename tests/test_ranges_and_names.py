"""Issue 18, one slice: the range rule across the grid's end (one definition, scalar and
numpy twins, read by the sweep, the scan and the design engines), clashing names refused
at load, and the equation sweep.

References are independent of the code under test: the law of cosines in plain Python for
four-bar angles, hand-worked angle sequences for the rule, and the scalar solver for the
equation sweep."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import linkage
from linkage.kinematics import angles
from linkage.kinematics.loading import load
from linkage.render.sweep import ranges_of

ROOT = Path(__file__).resolve().parent.parent
CRANK = ROOT / "sample_inputs" / "crank_rocker.toml"
LINKS = ("r1", "r2", "r3", "r4")
DEGREES = [float(k) for k in range(360)]


# --- an independent reference: the law of cosines and the rule, in plain Python ----------------

def fourbar_angles(r1: float, r2: float, r3: float, r4: float, branch: str,
                   values: list[float]) -> dict[str, list[float | None]]:
    """theta3 and theta4 (deg, in (-180, 180]) at each theta2, None where it cannot be
    assembled; ground O2 -> O4 along +x, open: sin(theta4 - theta3) > 0."""
    sign = -1.0 if branch == "open" else 1.0
    t3: list[float | None] = []
    t4: list[float | None] = []
    for v in values:
        t2 = math.radians(v)
        ax, ay = r2 * math.cos(t2), r2 * math.sin(t2)
        d2 = (ax - r1) ** 2 + ay * ay
        if not (r3 - r4) ** 2 <= d2 <= (r3 + r4) ** 2:
            t3.append(None)
            t4.append(None)
            continue
        d = math.sqrt(d2)
        psi = math.acos(max(-1.0, min(1.0, (r4 * r4 + d2 - r3 * r3) / (2 * r4 * d))))
        th4 = math.atan2(ay, ax - r1) + sign * psi
        bx, by = r1 + r4 * math.cos(th4), r4 * math.sin(th4)
        t3.append(math.degrees(math.atan2(by - ay, bx - ax)))
        t4.append(math.degrees(th4))
    return {"theta3": t3, "theta4": t4}


def reference_range(angle: list[float | None]) -> float:
    """The swing of an angle over a full-turn grid (0..359): read around the circle from
    the start of a feasible arc, each value nearest the previous; a full turn at most,
    and a full turn for one that comes back round a turn away."""
    n = len(angle)
    begin = next((k for k in range(n) if angle[k] is not None and angle[k - 1] is None), 0)
    smooth: list[float] = []
    for k in range(n):
        v = angle[(begin + k) % n]
        if v is None:
            continue
        if smooth:
            v = smooth[-1] + (v - smooth[-1] + 180.0) % 360.0 - 180.0
        smooth.append(v)
    if len(smooth) == n and abs(smooth[-1] - smooth[0]) > 180.0:
        return 360.0
    return min(max(smooth) - min(smooth), 360.0)


def crosses_the_seam(r1: float, r2: float, r3: float, r4: float) -> bool:
    """Assembles at 359 and at 0 deg but not everywhere: the feasible arc crosses the end."""
    feasible = [fourbar_angles(r1, r2, r3, r4, "open", [v])["theta4"][0] is not None for v in DEGREES]
    return feasible[0] and feasible[-1] and not all(feasible)


def seam_designs(count: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    found: list[np.ndarray] = []
    while len(found) < count:
        d = rng.uniform(10.0, 100.0, 4)
        if crosses_the_seam(*d):
            found.append(d)
    return np.array(found)


def run_scan(designs: np.ndarray, branch: str, values: list[float] = DEGREES) -> dict[str, np.ndarray]:
    """The scan's records for exactly these designs (one chunk, as `linkage scan` runs it)."""
    from linkage.files import read_input
    from linkage.scan import ScanJob, run_chunk

    job = ScanJob(read_input(CRANK), str(CRANK), (), LINKS, tuple(values), branch, 1e-12)
    return run_chunk(job, 0, designs)


def one_sweep(design: np.ndarray, branch: str, values: list[float] = DEGREES) -> linkage.SweepResult:
    m = load(CRANK).with_values(dict(zip(LINKS, map(float, design))), {})
    return linkage.sweep(m, values, branch=branch)


# A triple rocker whose open-branch arc runs from 272.47 deg through 0 to 87.53 deg: its
# rocker swings 199.59 deg and its coupler 221.01 deg (law of cosines above), and before
# this fix the scan reported 358.71 and 358.70 for them (the arc joined at the wrong turn).
SEAM = np.array([22.063752752244827, 99.25175764130182, 19.693458611499807, 81.04826827136806])


# --- the finding: scan ranges across the seam ------------------------------------------------------

@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_scan_ranges_across_the_seam_are_continuous_across_the_grids_end(branch):
    want = fourbar_angles(*SEAM, branch, DEGREES)
    rec = run_scan(SEAM[None, :], branch)
    for name in ("theta3", "theta4"):
        expected = reference_range(want[name])
        assert 190.0 < expected < 230.0  # the swing, far from a full turn
        assert abs(rec[f"{name}_range"][0] - expected) < 1e-9, name
        assert abs(rec[f"{name}_max"][0] - rec[f"{name}_min"][0] - expected) < 1e-9
    # the same design scanned from -180 deg: the same ranges, and the same turn
    shifted = run_scan(SEAM[None, :], branch, [float(k) for k in range(-180, 180)])
    for key in ("theta3_range", "theta4_range", "theta3_min", "theta4_max"):
        assert abs(shifted[key][0] - rec[key][0]) < 1e-9, key


def test_a_full_turn_sweep_of_a_triple_rocker_reports_its_swing_not_360():
    want = fourbar_angles(*SEAM, "open", DEGREES)
    for values in (DEGREES, [float(k) for k in range(361)], [float(k) for k in range(-180, 180)]):
        got = ranges_of(one_sweep(SEAM, "open", values))
        for name in ("theta3", "theta4"):
            assert abs(got[name]["stroke"] - reference_range(want[name])) < 1e-9, (values[0], values[-1])
            assert abs(got[name]["max"] - got[name]["min"] - got[name]["stroke"]) < 1e-9


def test_a_coupler_that_turns_fully_has_range_360_and_a_rocker_its_swing():
    """A double crank (ground shortest): coupler and follower turn fully, range 360 in the
    scan and in the sweep. A crank-rocker's rocker: its swing, from the law of cosines."""
    double_crank = np.array([40.0, 100.0, 120.0, 80.0])
    crank_rocker = np.array([100.0, 40.0, 120.0, 80.0])
    rec = run_scan(np.vstack([double_crank, crank_rocker]), "open")
    sweeps = [ranges_of(one_sweep(d, "open")) for d in (double_crank, crank_rocker)]
    for name in ("theta3", "theta4"):
        assert rec[f"{name}_range"][0] == 360.0 and sweeps[0][name]["stroke"] == 360.0
    swing = reference_range(fourbar_angles(*crank_rocker, "open", DEGREES)["theta4"])
    assert 30.0 < swing < 90.0
    assert abs(rec["theta4_range"][1] - swing) < 1e-9
    assert abs(sweeps[1]["theta4"]["stroke"] - swing) < 1e-9


@pytest.mark.parametrize("branch", ["open", "crossed"])
def test_scan_ranges_equal_the_sweeps_on_random_designs_across_the_seam(branch):
    """Done-when 2: 40 seeded random four-bars whose feasible arcs cross the grid's end; the
    scan's min, max and range of theta3 and theta4 are the one-at-a-time sweep's (min and
    max up to the whole turns each engine anchors to: the scan the file's guess, the sweep
    `solve FILE`), and the ranges are the law of cosines'."""
    designs = seam_designs(40, seed=18)
    rec = run_scan(designs, branch)
    wide = 0
    for i, d in enumerate(designs):
        got = ranges_of(one_sweep(d, branch))
        want = fourbar_angles(*d, branch, DEGREES)
        for name in ("theta3", "theta4"):
            scan_range = rec[f"{name}_range"][i]
            assert abs(scan_range - got[name]["stroke"]) < 1e-9, (i, name)
            assert abs(scan_range - reference_range(want[name])) < 1e-9, (i, name)
            turns = (rec[f"{name}_min"][i] - got[name]["min"]) / 360.0
            assert abs(turns - round(turns)) < 1e-11, (i, name)
            assert abs(rec[f"{name}_max"][i] - got[name]["max"] - 360.0 * round(turns)) < 1e-9
            wide += scan_range > 180.0
    assert wide >= 10  # many arcs whose swing exceeds half a turn (where the old rule slipped)


# --- the one definition: scalar and numpy twins ------------------------------------------------------

def test_the_rule_on_hand_worked_sequences():
    # an arc across the end of a 0..330 grid (step 30): read from 270 round to 60
    values = [10.0, 100.0, None, None, None, None, None, None, None, -170.0, -100.0, -30.0]
    closes = angles.closes_circle([30.0 * k for k in range(12)])
    assert closes
    turns = angles.unwrap_turns(values, closes)
    shown = [None if v is None else angles.continuous(v, t) for v, t in zip(values, turns)]
    # from -170 (the arc's start): -100, -30, then 10 and 100 continue upwards
    assert shown == [10.0, 100.0, None, None, None, None, None, None, None, -170.0, -100.0, -30.0]
    assert angles.angle_extent(shown, closes) == (-170.0, 100.0, 270.0)
    # in grid order (a grid that does not close) 100 -> -170 is read as +90: 190, 260, 330
    grid_order = angles.unwrap_turns(values, False)
    assert [None if v is None else angles.continuous(v, t) for v, t in zip(values, grid_order)][9:] == \
        [190.0, 260.0, 330.0]
    # a full cycle that turns once: 360; one that swings: its swing
    turning = [float(v) for v in range(0, 360, 30)]
    assert angles.angle_extent(turning, True)[2] == 360.0
    assert angles.angle_extent(turning, False)[2] == 330.0
    assert angles.angle_extent([10.0, 50.0, 20.0, -30.0], True) == (-30.0, 50.0, 80.0)
    # grids that close the circle, and ones that do not
    assert angles.closes_circle(DEGREES) and angles.closes_circle([float(k) for k in range(361)])
    assert angles.closes_circle([float(k) for k in range(-180, 180)])
    assert angles.closes_circle(DEGREES[::-1])
    assert angles.closes_circle([0.1 * k for k in range(3600)])
    assert not angles.closes_circle(DEGREES[:-2]) and not angles.closes_circle([0.0, 10.0, 5.0])
    assert angles.closes_circle([2 * math.pi * k / 100 for k in range(100)], 2 * math.pi)


angle_rows = st.lists(
    st.lists(st.one_of(st.none(), st.floats(-1e4, 1e4, allow_nan=False)), min_size=1, max_size=12),
    min_size=1, max_size=6,
).filter(lambda rows: len({len(r) for r in rows}) == 1)


@settings(max_examples=300, deadline=None)
@given(rows=angle_rows, closes=st.booleans(), v0=st.floats(-720, 720), ref=st.floats(-1e3, 1e3))
def test_the_numpy_twins_are_the_scalar_rule_bit_for_bit(rows, closes, v0, ref):
    a = np.array([[np.nan if v is None else v for v in r] for r in rows])
    grid = [30.0 * k for k in range(a.shape[1])]
    turns = angles.unwrap_turns_array(a, closes)
    near = angles.anchor_index_array(grid, np.isfinite(a), v0, closes)
    lo, hi, span = angles.angle_extent_array(np.where(np.isfinite(a), angles.continuous(a, turns), np.nan),
                                             closes)
    starts = angles.circular_start_array(np.isfinite(a), closes)
    for i, r in enumerate(rows):
        solved = [v is not None for v in r]
        assert starts[i] == angles.circular_start(solved, closes)
        t = angles.unwrap_turns(r, closes)
        assert [None if math.isnan(x) else int(x) for x in turns[i]] == t
        shown = [None if v is None else angles.continuous(v, k) for v, k in zip(r, t)]
        for j, v in enumerate(shown):
            if v is not None:
                # continuous: each solved value within half a turn of the previous one read
                assert v == angles.continuous(a[i, j], turns[i, j])
        got = angles.angle_extent(shown, closes)
        assert (np.array(got) == np.array([lo[i], hi[i], span[i]])).all() or \
            (all(math.isnan(x) for x in got) and math.isnan(lo[i]))
        k = angles.anchor_index(grid, solved, v0, closes)
        if k is not None:
            assert near[i] == k
            at = shown[k]
            assert angles.turn_shift(ref, at) == angles.turn_shift_array(ref, at)


@settings(max_examples=300, deadline=None)
@given(ref=st.floats(-1e4, 1e4), values=st.lists(st.floats(-1e4, 1e4), min_size=1, max_size=8))
def test_the_nearest_turn_twin_is_the_scalar_and_within_half_a_turn(ref, values):
    got = angles.nearest_turn_array(ref, np.array(values))
    for v, g in zip(values, got):
        x = angles.nearest_turn(ref, v)
        assert x == g
        assert -180.0 - 1e-9 <= x - ref <= 180.0 + 1e-9
        turns = (x - v) / 360.0
        assert abs(turns - round(turns)) < 1e-9


@settings(max_examples=200, deadline=None)
@given(values=st.lists(st.one_of(st.none(), st.floats(-1e3, 1e3)), min_size=2, max_size=20),
       closes=st.booleans())
def test_unwrapped_values_are_continuous_and_whole_turns_from_the_solved(values, closes):
    """Rule 2 itself: each reported value is the solved one plus whole turns, within half a
    turn of the previous one read (around the circle on a closing grid)."""
    t = angles.unwrap_turns(values, closes)
    shown = [None if v is None else angles.continuous(v, k) for v, k in zip(values, t)]
    start = angles.circular_start([v is not None for v in values], closes)
    read = [shown[(start + k) % len(values)] for k in range(len(values))]
    read = [v for v in read if v is not None]
    for a, b in itertools.pairwise(read):
        assert -180.0 - 1e-9 <= b - a <= 180.0 + 1e-9
    if read:
        assert -180.0 - 1e-9 <= read[0] <= 180.0 + 1e-9


# --- the finding: name clashes corrupt scan records ---------------------------------------------------

def with_parameter(name: str, unit: str = "mm") -> str:
    """The crank-rocker file with one more parameter, called ``name``."""
    text = CRANK.read_text()
    extra = f'{name} = {{ value = 5, unit = "{unit}" }}\n'
    return text.replace("r2 = { value = 40", extra + "r2 = { value = 40", 1)


def unknown_beside_point() -> str:
    """The crank-rocker file without its closed form, its coupler angle renamed P_x: the
    unknown's columns P_x_min/P_x_max (deg) and point P's P_x_min/P_x_max (mm)."""
    text = CRANK.read_text().replace('closed_form = "fourbar"\n', "")
    return text.replace("theta3 = { guess", "P_x = { guess").replace('angle = "theta3"', 'angle = "P_x"')


@pytest.mark.parametrize("text,clash", [
    (with_parameter("design"), "'design'"),
    (with_parameter("full_cycle"), "'full_cycle'"),
    (with_parameter("feasible_fraction"), "'feasible_fraction'"),
    (with_parameter("theta4_range", "deg"), "'theta4_range'"),
    (with_parameter("P_y_max"), "'P_y_max'"),
    (with_parameter("min_transmission_deg", "deg"), "'min_transmission_deg'"),
    (unknown_beside_point(), "'P_x_min'"),
], ids=["design", "full_cycle", "feasible_fraction", "unknown-column", "point-column", "fourbar-column",
        "unknown-P_x-beside-point-P"])
def test_name_clashes_corrupt_scan_records_so_they_are_refused_at_load(cli, tmp_path, text, clash):
    path = tmp_path / "clash.toml"
    path.write_text(text)
    for args in (("solve", str(path)), ("scan", str(path), "--vary", "r2=20:30:2")):
        r = cli(*args)
        assert r.code == 2 and r.out == ""
        lines = r.err.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: ") and clash in lines[0], r.err
    with pytest.raises(linkage.ParseError, match=clash):
        load(path)


def test_every_column_a_scan_writes_is_a_reserved_name(tmp_path):
    """The reserved names are the scan's own columns (not a second list): every key of a
    real scan's records, named as a parameter, is refused; the file as it is loads."""
    rec = run_scan(np.array([[100.0, 40.0, 120.0, 80.0]]), "open")
    from linkage.problems.columns import columns_of

    m = load(CRANK)
    assert list(rec) == [c[0] for c in columns_of(m, LINKS)]
    for key in rec:
        if key in LINKS:
            continue
        path = tmp_path / f"{key}.toml"
        path.write_text(with_parameter(key))
        with pytest.raises(linkage.ParseError, match=f"'{key}'"):
            load(path)
    path = tmp_path / "fine.toml"
    path.write_text(with_parameter("r9"))
    assert "r9" in load(path).parameters


# --- the finding: the equation sweep ------------------------------------------------------------------

def true_roots(alpha: float, r1: float, r2: float, r3: float) -> list[float]:
    """Both roots phi (deg) of R1 cos a - R2 cos phi + R3 - cos(a - phi) = 0 to 50 digits:
    (R2 + cos a) cos phi + sin a sin phi = R1 cos a + R3 is A cos(phi - delta) = k."""
    mp = pytest.importorskip("mpmath")
    with mp.workdps(50):
        a = mp.radians(mp.mpf(alpha))
        p, q = mp.mpf(r2) + mp.cos(a), mp.sin(a)
        k, size = mp.mpf(r1) * mp.cos(a) + mp.mpf(r3), mp.hypot(p, q)
        if abs(k) > size:
            return []
        base, spread = mp.atan2(q, p), mp.acos(k / size)
        return [float(mp.degrees(base + s * spread)) for s in (1, -1)]


def off_root(phi: float, roots: list[float]) -> float:
    return min(abs((phi - r + 180.0) % 360.0 - 180.0) for r in roots)


def test_the_equation_sweep_continues_where_solve_converges(cli):
    """`linkage sweep --from 0 --to 3 --step 1` stopped at alpha = 2 with max_iter (Newton
    from the tangent prediction started within rounding of the root and stepped between
    its neighbouring floats); `solve --alpha 2` converges. Every alpha now converges, on
    a true root, and the bare `linkage sweep` exits 0."""
    from linkage.problems.freudenstein import SEED_R

    run = cli("sweep", "--from", "0", "--to", "3", "--step", "1", "--format", "json")
    assert run.code == 0, run.out
    rows = json.loads(run.out)["positions"]
    assert [r["alpha"] for r in rows] == [0, 1, 2, 3]
    for r in rows:
        assert r["status"].startswith("converged"), r
        # alpha = 0 is a double root (phi = 0 exactly), determined only to sqrt(eps)
        assert off_root(r["phi"], true_roots(r["alpha"], *SEED_R)) < (1e-7 if r["alpha"] == 0 else 1e-10)
    full = cli("sweep", "--format", "json")
    assert full.code == 0
    rows = json.loads(full.out)["positions"]
    assert len(rows) == 361 and all(r["status"].startswith("converged") for r in rows)
    assert max(off_root(r["phi"], true_roots(r["alpha"], *SEED_R)) for r in rows if r["alpha"] % 360) < 1e-9


def test_the_equation_sweep_honours_digits(cli):
    run = cli("sweep", "--from", "0", "--to", "2", "--step", "1", "--digits", "5", "--format", "plain")
    assert run.code == 0
    cells = run.out.split()
    assert "-0.23593" in cells and "-0.47189" in cells
    assert not any(c.startswith("-0.235930") for c in cells)


@pytest.mark.parametrize("seed", [5, 6])
def test_the_equation_sweep_solves_every_assemblable_alpha_of_random_linkages(cli, seed):
    """The class: for random link lengths over a full turn, every alpha with a real root
    (50-digit closed form) converges onto one, and every alpha without is no_solution."""
    rng = np.random.default_rng(seed)
    for _ in range(6):
        links = rng.uniform(0.3, 3.0, 4)
        run = cli("sweep", "--links", *(repr(float(v)) for v in links), "--to", "359", "--format", "json")
        out = json.loads(run.out)
        from linkage.problems.freudenstein import coefficients_from_links

        c = coefficients_from_links(*links)
        for r in out["positions"]:
            roots = true_roots(r["alpha"], c.r1, c.r2, c.r3)
            if not roots:
                assert r["status"] == "no_solution", r
                continue
            assert r["status"].startswith("converged"), (list(links), r)
            # f' vanishes only at a limit position (a double root): there sqrt(eps) of a turn
            assert off_root(r["phi"], roots) < (1e-6 if abs(roots[0] - roots[1]) < 1e-3 else 1e-9)
        assert run.code == 0  # no_solution is an answer (as in a mechanism sweep), not a failure

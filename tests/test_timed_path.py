"""Path generation with prescribed timing (linkage.synthesis.timed_path, synthesize --path
--point X,Y,DEG) against an independent reference: random four-bars whose coupler points
are computed by plane geometry (circle intersection at each crank angle, not from the
dyads' standard form or Burmester's equations), and the engine's own assemblies and sweep
of every listed four-bar. The four-bar of test_the_written_design_... (ground 0 and 2.5+0.3i,
crank 1, coupler 2.6, rocker 2.2) is the one docs/path_synthesis.md works through."""

from __future__ import annotations

import cmath
import csv
import io
import math

import numpy as np
import pytest

ANGLES = (10.0, 40.0, 75.0, 110.0, 150.0)


def _place(A: complex, B: complex, r2: float, r3: float, r4: float, k: complex, phi: float,
           sign: int) -> tuple[complex, complex, complex] | None:
    """The crank pin M, rocker pin N and coupler point P = M + (N - M) k at crank angle phi
    (rad), on the assembly ``sign`` (N left (+1) or right (-1) of M -> B); None where the
    four-bar does not close."""
    M = A + r2 * cmath.exp(1j * phi)
    d = abs(B - M)
    if not abs(r3 - r4) < d < r3 + r4:
        return None
    along = (r3 * r3 - r4 * r4 + d * d) / (2 * d)
    h = math.sqrt(max(0.0, r3 * r3 - along * along))
    u = (B - M) / d
    N = M + along * u + sign * h * u * 1j
    return M, N, M + (N - M) * k


def _grashof(*lengths: float) -> bool:
    shortest, p, q, longest = sorted(lengths)
    return shortest + longest < p + q


def _random_four_bar(rng: np.random.Generator, grashof: bool, signs=(1,) * 5):  # type: ignore[no-untyped-def]
    """A random four-bar of the Grashof kind asked and five of its coupler points at crank
    angles in increasing order within one stretch its crank can turn through (one circuit
    for one sign). Returns the pivots (A, B, M_1, N_1), the points and the angles (deg)."""
    while True:
        A, B = complex(*rng.uniform(-1, 1, 2)), complex(rng.uniform(2, 3), rng.uniform(-1, 1))
        r2, r3, r4 = rng.uniform(0.5, 3, 3)
        if _grashof(abs(B - A), r2, r3, r4) != grashof:
            continue
        k = complex(rng.uniform(-0.5, 1.5), rng.uniform(-1, 1))
        grid = np.radians(np.arange(0.0, 360.0, 1.0))
        ok = [_place(A, B, r2, r3, r4, k, g, 1) is not None for g in grid]
        if not any(ok):
            continue
        if all(ok):
            start, length = int(rng.integers(360)), 360
        else:  # the longest stretch the crank turns through (around 0 too)
            runs, k0 = [], ok.index(False)
            for s in range(360):
                i = (k0 + s) % 360
                if ok[i] and (not runs or not ok[(i - 1) % 360]):
                    runs.append([i, 0])
                if ok[i]:
                    runs[-1][1] += 1
            start, length = max(runs, key=lambda r: r[1])
            if length < 60:
                continue
        picks = np.sort(rng.choice(np.arange(2, length - 2, 6), 5, replace=False))
        angles = [float((start + p) % 360) + rng.uniform(-0.5, 0.5) for p in picks]
        placed = [_place(A, B, r2, r3, r4, k, math.radians(a), s) for a, s in zip(angles, signs)]
        if any(p is None for p in placed):
            continue
        M1, N1, _ = placed[0]  # type: ignore[misc]
        return (A, B, M1, N1), [p[2] for p in placed], angles  # type: ignore[index]


def _matches(pivots, candidate, tol: float = 1e-9) -> bool:  # type: ignore[no-untyped-def]
    size = max(abs(p - pivots[2]) for p in pivots)
    return max(abs(a - b) for a, b in zip(pivots, candidate)) <= tol * size


def _timed(points, angles):  # type: ignore[no-untyped-def]
    return [(p.real, p.imag, a) for p, a in zip(points, angles)]


@pytest.mark.parametrize(("grashof", "seed"), [(True, 1), (True, 2), (True, 3), (False, 4), (False, 5)])
def test_a_known_four_bar_sampled_at_five_crank_angles_is_among_the_solutions(grashof, seed):
    from linkage.synthesis.timed_path import timed_four_bars

    pivots, points, angles = _random_four_bar(np.random.default_rng(seed), grashof)
    found = timed_four_bars(_timed(points, angles))
    assert 1 <= len(found.cranks.cranks) <= 4 and len(found.four_bars) <= 12
    assert sum(_matches(pivots, fb.pivots) for fb in found.four_bars) == 1
    assert found.incomplete() == 0


def _engine_places_p(design, points, angles) -> float:  # type: ignore[no-untyped-def]
    """The largest distance from each point to the nearest P the engine assembles at the
    prescribed crank angle (the design's crank angle at the first point plus the prescribed
    turn), over its real assemblies: linkage.assemblies, not the synthesis' configurations."""
    import linkage
    from linkage.kinematics.loading import from_text
    from linkage.synthesis.path import mechanism_text

    m = from_text(mechanism_text(design), "<test>")
    worst = 0.0
    for p, a in zip(points, angles):
        found = linkage.assemblies(m, design.crank_deg[0] + a - angles[0])
        worst = max(worst, min(abs(complex(*s.joints["P"]) - p) for s in found.real))
    return worst / m.length_scale


def test_every_listed_four_bar_passes_through_the_points_at_the_prescribed_crank_angles():
    import linkage

    pivots, points, angles = _random_four_bar(np.random.default_rng(7), True)
    result = linkage.synthesize_path(_timed(points, angles))
    assert result.designs and sum(_matches(pivots, (d.ground_a, d.ground_b, d.pin_m, d.pin_n))
                                  for d in result.designs) == 1
    for d in result.designs:
        assert _engine_places_p(d, points, angles) <= 1e-9
        assert d.timing_error_deg <= 1e-9 and "timing" not in d.defects and "positions" not in d.defects
        late = [math.remainder(c - d.crank_deg[0] - (a - angles[0]), 360.0)
                for c, a in zip(d.crank_deg, angles)]
        assert max(map(abs, late)) <= 1e-9
    # Roberts: the cognate whose crank at C (triangle ABC similar to MNP) stays parallel to
    # the crank AM has the same timing, and is grouped with it
    A, B, M, N = pivots
    C = A + (B - A) * (points[0] - M) / (N - M)
    size = max(abs(p - points[0]) for p in pivots)
    mine = next(i for i, d in enumerate(result.designs)
                if _matches(pivots, (d.ground_a, d.ground_b, d.pin_m, d.pin_n)))
    cognate = [i for i, d in enumerate(result.designs)
               if abs(d.ground_a - C) <= 1e-9 * size and abs(d.ground_b - B) <= 1e-9 * size]
    group = next(g for g in result.groups if mine in g)
    assert len(cognate) == 1 and sorted(group) == sorted([mine, *cognate])
    assert sorted(i for g in result.groups for i in g) == list(range(len(result.designs)))


def test_points_on_two_assemblies_are_a_branch_defect():
    """Three points on one assembly, two on the other: the dyads do not see assemblies, so
    the four-bar is found, and moving it says the points are on two circuits."""
    import linkage

    rng = np.random.default_rng(8)
    while True:
        pivots, points, angles = _random_four_bar(rng, True, signs=(1, 1, 1, -1, -1))
        A, B, M1, _ = pivots
        if abs(M1 - A) < min(abs(B - A), 0.9 * abs(pivots[3] - M1)):  # a crank-rocker: two circuits
            break
    result = linkage.synthesize_path(_timed(points, angles))
    mine = [d for d in result.designs if _matches(pivots, (d.ground_a, d.ground_b, d.pin_m, d.pin_n))]
    assert len(mine) == 1 and "branch" in mine[0].defects and mine[0].grashof == "crank-rocker"


def test_points_given_out_of_order_are_an_order_defect():
    import linkage

    pivots, points, angles = _random_four_bar(np.random.default_rng(9), True)
    swap = [0, 1, 3, 2, 4]
    result = linkage.synthesize_path(_timed([points[i] for i in swap], [angles[i] for i in swap]))
    mine = [d for d in result.designs if _matches(pivots, (d.ground_a, d.ground_b, d.pin_m, d.pin_n))]
    assert len(mine) == 1 and "order" in mine[0].defects and "branch" not in mine[0].defects


def test_points_past_a_limit_position_of_the_crank_are_a_grashof_defect():
    """A non-Grashof four-bar: three points on one assembly as the crank turns up to its
    limit, two on the other as it turns back. One circuit, in order, but the crank (the
    input, with timing) cannot drive it there: motion generation's ``grashof`` defect."""
    import linkage

    pivots, points, angles = _random_four_bar(np.random.default_rng(12), False, signs=(1, 1, 1, -1, -1))
    back = [0, 1, 2, 4, 3]
    result = linkage.synthesize_path(_timed([points[i] for i in back], [angles[i] for i in back]))
    mine = [d for d in result.designs if _matches(pivots, (d.ground_a, d.ground_b, d.pin_m, d.pin_n))]
    assert len(mine) == 1 and "grashof" in mine[0].defects
    assert not {"branch", "order", "timing"} & set(mine[0].defects)
    # the same four-bar with every point on the first assembly: the crank turns one way
    same, points, angles = _random_four_bar(np.random.default_rng(12), False)
    assert same == pivots
    result = linkage.synthesize_path(_timed(points, angles))
    mine = [d for d in result.designs if _matches(pivots, (d.ground_a, d.ground_b, d.pin_m, d.pin_n))]
    assert len(mine) == 1 and not {"grashof", "branch", "order"} & set(mine[0].defects)


def test_a_crank_that_turns_otherwise_than_prescribed_is_a_timing_defect():
    """The reference four-bar judged at its own configurations: on time with its angles, a
    ``timing`` defect (and no other new one) with one angle moved by a degree."""
    from linkage.synthesis.path import judge_four_bar

    rng = np.random.default_rng(10)
    pivots, points, angles = _random_four_bar(rng, True)
    A, B, M1, N1 = pivots
    r2, r3, r4 = abs(M1 - A), abs(N1 - M1), abs(N1 - B)
    k = (points[0] - M1) / (N1 - M1)
    poses: list[tuple[float, float, float]] = []
    for a in angles:
        for sign in (1, -1):
            M, N, P = _place(A, B, r2, r3, r4, k, math.radians(a), sign)  # type: ignore[misc]
            if abs(P - points[len(poses)]) < 1e-12:
                break
        poses.append((math.radians(a), cmath.phase(N - M), cmath.phase(N - B)))
    on_time = judge_four_bar(pivots, poses, points, 0.0, tuple(angles))
    late = judge_four_bar(pivots, poses, points, 0.0, (*angles[:3], angles[3] + 1.0, angles[4]))
    assert on_time.timing_error_deg <= 1e-9 and "timing" not in on_time.defects
    assert abs(late.timing_error_deg - 1.0) <= 1e-9
    assert set(late.defects) - set(on_time.defects) == {"timing"}


FIVE = [(0.0, 0.0, 0.0), (1.0, 0.2, 20.0), (1.5, 1.0, 45.0), (1.0, 2.0, 80.0), (0.0, 2.2, 120.0)]


@pytest.mark.parametrize(("bad", "says"), [
    ([*FIVE, (2.0, 2.0, 150.0)], "at most 5 points"),
    (FIVE[:4], "1 free number for each dyad"),
    (FIVE[:3], "2 free numbers for each dyad"),
    ([*FIVE[:4], (2.0, 2.0)], "or none"),
    ([*FIVE[:4], (2.0, 2.0, math.nan)], "points[4]"),
    ([*FIVE[:4], (2.0, 2.0, 1e300)], "points[4]"),
    ([*FIVE[:4], (1.0, 0.2, 150.0)], "coincide"),
    ([(x, y, 30.0) for x, y, _ in FIVE], "does not turn"),
    ([*FIVE[:4], (2.0, 2.0, 360.0)], "points 1 and 5 have the same crank angle"),
])
def test_bad_timed_points_are_refused_with_one_line(bad, says):
    import linkage
    from linkage.errors import InputError

    with pytest.raises(InputError) as err:
        linkage.synthesize_path(bad)
    assert "\n" not in str(err.value) and says in str(err.value)


def _point_args(points, angles) -> list[str]:  # type: ignore[no-untyped-def]
    return [f"--point={p.real!r},{p.imag!r},{a!r}" for p, a in zip(points, angles)]


@pytest.mark.parametrize(("args", "says"), [
    ([f"--point={x},{y},{a}" for x, y, a in [*FIVE, (2, 2, 150)]], "at most 5 points"),
    ([f"--point={x},{y},{a}" for x, y, a in FIVE[:4]], "a family"),
    ([*[f"--point={x},{y},{a}" for x, y, a in FIVE[:4]], "--point=2,2"], "or none"),
    ([*[f"--point={x},{y},{a}" for x, y, a in FIVE[:4]], "--point=2,2,nan"], "--point 5"),
    ([*[f"--point={x},{y},{a}" for x, y, a in FIVE[:4]], "--point=1,0.2,150"], "coincide"),
    ([*[f"--point={x},{y},{a}" for x, y, a in FIVE], "--workers", "2"], "--workers is for untimed points"),
])
def test_synthesize_timed_path_refuses_bad_points_in_one_line(cli, args, says):
    out = cli("synthesize", "--path", *args)
    assert out.code == 2 and says in out.err and len(out.err.strip().splitlines()) == 1


def test_the_written_design_sweeps_through_the_points_at_the_prescribed_crank_angles(cli, tmp_path):
    """synthesize --path -o FILE.toml, then linkage sweep FILE.toml over the file's range
    (the design's crank angle at the first point through the prescribed turn), in steps that
    land on every prescribed angle: P is on each point there."""
    A, B, r2, r3, r4, k = 0j, complex(2.5, 0.3), 1.0, 2.6, 2.2, complex(0.5, 0.7)
    points = [_place(A, B, r2, r3, r4, k, math.radians(a), 1)[2] for a in ANGLES]  # type: ignore[index]
    design = tmp_path / "timed.toml"
    out = cli("synthesize", "--path", *_point_args(points, ANGLES), "-o", str(design), "-f", "csv",
              "--table", "designs")
    assert out.code == 0 and design.exists()
    table = list(csv.DictReader(io.StringIO(out.out)))
    assert len(table) == 6 and all(float(r["timing_error (deg)"]) <= 1e-9 for r in table)  # 12 four-bars
    first = float(next(r for r in design.read_text().splitlines() if r.startswith("value =")).split()[-1])
    swept = cli("sweep", str(design), "--step", "5", "-f", "csv")
    assert swept.code == 0
    rows = list(csv.DictReader(io.StringIO(swept.out)))
    reached = {round(float(r["theta2 (deg)"]) - first): complex(float(r["P.x (m)"]), float(r["P.y (m)"]))
               for r in rows if r["status"] == "converged"}
    for p, a in zip(points, ANGLES):
        assert abs(reached[round(a - ANGLES[0])] - p) <= 1e-9 * 3


def test_a_failed_path_counts_as_a_missing_root_only_when_roots_are_short_of_four():
    """Burmester's problem has four roots in the complex; the total-degree homotopy's other
    12 paths end at infinity, and one of those failing loses nothing."""
    from types import SimpleNamespace

    from linkage.synthesis.timed_path import missing_roots

    def problem(real: int, complex_count: int, failed: int, unresolved: int = 0):  # type: ignore[no-untyped-def]
        return SimpleNamespace(cranks=(None,) * real, complex_count=complex_count, failed=failed,
                               unresolved=unresolved)

    assert missing_roots(problem(4, 0, 7)) == 0 and missing_roots(problem(2, 2, 1)) == 0
    assert missing_roots(problem(3, 0, 2)) == 1 and missing_roots(problem(1, 2, 1)) == 1
    assert missing_roots(problem(2, 0, 0, 1)) == 1 and missing_roots(problem(2, 0, 0)) == 0


def test_a_burmester_root_one_gamma_misses_is_found_with_the_next():
    """A non-Grashof four-bar (seed 137 of the sampler) whose third Burmester problem lost a
    real root to a failed path with the first gamma: solved again, every problem has its
    four roots, and the four-bar is among the solutions."""
    from linkage.synthesis.timed_path import timed_four_bars

    pivots, points, angles = _random_four_bar(np.random.default_rng(137), False)
    found = timed_four_bars(_timed(points, angles))
    assert found.incomplete() == 0
    assert sum(_matches(pivots, fb.pivots) for fb in found.four_bars) == 1


def test_collinear_timed_points_say_their_roots_went_to_infinity_not_that_all_were_found(cli):
    """Five collinear points: Burmester's problems have fewer than four finite roots (one
    goes to infinity); the summary says so, and does not claim all four were found."""
    out = cli("synthesize", "--path", *[f"--point={k},0,{10 * k}" for k in range(5)])
    assert "fewer than 4 finite roots" in out.out and "every problem's 4 roots found" not in out.out
    assert out.code == 1  # no design without defects

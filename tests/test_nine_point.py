"""Nine-point path synthesis (linkage.homotopy.ninepoint) against independent references:
finite differences for the derivatives, a four-bar's coupler points computed by circle
intersection (not from the isotropic equations), and the published counts of Wampler,
Morgan and Sommese (1992), Problem 3: 1,442 four-bars up to cognates, 64 real."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest

from linkage.homotopy import ninepoint as npt
from linkage.homotopy import ninepoint_track as nt
from linkage.synthesis.path import PROBLEM_3


def _coupler_points(rng: np.random.Generator) -> tuple[list[complex], np.ndarray]:
    """A random real four-bar and nine of its coupler points, by plane geometry: the crank
    turns to each angle, the coupler's second pivot is where the circles about the crank
    pin (coupler length) and about the second ground pivot (rocker length) meet, on one
    side throughout. Returns the points and the four-bar as unknowns (P_0 at the origin)."""
    while True:
        A, B = 0j, complex(rng.uniform(2, 4), rng.uniform(-1, 1))
        r1, r2, L = rng.uniform(0.8, 1.5), rng.uniform(1.5, 3), rng.uniform(2, 3.5)
        k = complex(rng.uniform(0.2, 0.8), rng.uniform(0.3, 1.0))  # P = M + (N - M) k
        phis = np.sort(rng.uniform(0, 2 * math.pi, 9))
        pts, pose = [], None
        for phi in phis:
            M = A + r1 * cmath.exp(1j * phi)
            d = abs(B - M)
            if not abs(L - r2) < d < L + r2:
                break
            along = (L * L - r2 * r2 + d * d) / (2 * d)
            h = math.sqrt(max(0.0, L * L - along * along))
            u = (B - M) / d
            N = M + along * u + h * u * 1j
            pts.append(M + (N - M) * k)
            if pose is None:
                pose = (M, N)
        else:
            P0 = pts[0]
            M, N = pose
            z = np.array([A - P0, M - P0, B - P0, N - P0])
            return pts, np.concatenate([z, np.conj(z)])


def _instance(pts: list[complex]) -> tuple[np.ndarray, np.ndarray]:
    p = np.array(pts)
    return p[1:] - p[0], np.conj(p[1:] - p[0])


def test_a_four_bar_and_its_cognates_solve_the_equations_of_its_coupler_points():
    rng = np.random.default_rng(11)
    for _ in range(20):
        pts, z = _coupler_points(rng)
        d, db = _instance(pts)
        for member in npt.orbit(z):
            E = npt.equations(member[None, :], d, db)[0]
            # relative to the size of the terms (degree 8 in lengths of about 3)
            assert np.abs(E).max() <= 1e-11 * max(1.0, float(np.abs(member).max())) ** 8


def test_derivatives_match_finite_differences_affine_and_projective():
    rng = np.random.default_rng(5)
    z, d, db = npt.seed_instance(rng)
    w = np.array([0.7 - 0.2j])
    for homogeneous in (None, w):
        E, J, Ed, Edb = npt.equations(z[None, :], d, db, homogeneous)
        h = 1e-7
        for k in range(8 if homogeneous is None else 9):
            zp = z.copy()
            wp = None if homogeneous is None else w.copy()
            if k < 8:
                zp[k] += h
            else:
                wp[0] += h
            Ep = npt.equations(zp[None, :], d, db, wp)[0]
            assert np.abs((Ep - E)[0] / h - J[0, :, k]).max() <= 1e-5 * np.abs(J[0, :, k]).max()
        for j in range(8):
            dp, dbp = d.copy(), db.copy()
            dp[j] += h
            dbp[j] += h
            assert abs((npt.equations(z[None, :], dp, db, homogeneous)[0][0, j] - E[0, j]) / h - Ed[0, j]) \
                <= 1e-5 * abs(Ed[0, j])
            assert abs((npt.equations(z[None, :], d, dbp, homogeneous)[0][0, j] - E[0, j]) / h - Edb[0, j]) \
                <= 1e-5 * abs(Edb[0, j])


def test_the_stored_start_instance_has_1442_distinct_nonsingular_orbits():
    start = npt.load_start()
    assert start.solutions.shape == (1442, 8)
    Z, last, cond = npt.polish(start.solutions, start.delta, start.deltabar)
    # Newton's last step against the size: at rounding for all but the largest solutions
    # (pivots a thousand times the points' spread), whose affine condition reaches 1e12
    assert np.median(last) <= 1e-13
    assert np.percentile(last, 99) <= 1e-11
    assert np.all(last <= 1e-13 * cond)
    assert len(npt.distinct(npt.canonical(Z))) == 1442
    # no two stored solutions are of one orbit
    members = np.concatenate([npt.orbit(z) for z in Z])
    assert len(npt.distinct(members)) == 6 * 1442


def test_the_generic_monodromy_loops_the_nine_point_problem_one_root_per_orbit():
    """parameter.monodromy with NinePointLoops (how benchmarks/nine_point_start.py made the
    stored instance): two seeds of one orbit are one root; every root a loop adds is a
    solution of the seed instance (60-digit Newton from it moves it by rounding only), and
    no two roots are of one orbit."""
    from linkage.homotopy.parameter import monodromy

    rng = np.random.default_rng(7)
    z, d, db = npt.seed_instance(rng)
    p = np.concatenate([d, db])
    cognate = npt.orbit(z)[3]
    assert np.linalg.norm(cognate - z) > 1e-3
    seeded = monodromy(nt.NinePointLoops(), p, np.stack([z, cognate]), max_loops=0)
    assert len(seeded.roots) == 1 and seeded.counts == ()
    seen = []
    found = monodromy(nt.NinePointLoops(), p, z[None, :], max_loops=3, seed=rng, on_loop=seen.append)
    assert [loop.count for loop in seen] == list(found.counts) and len(found.roots) == found.counts[-1] > 2
    assert sum(loop.new for loop in seen) == len(found.roots) - 1
    for root in found.roots:
        exact = npt.polish_precisely(root, d, db)
        assert exact is not None
        assert np.linalg.norm(exact - root) <= 1e-12 * max(1.0, float(np.linalg.norm(root)))
    members = np.concatenate([npt.orbit(r) for r in found.roots])
    assert len(npt.distinct(members)) == 6 * len(found.roots)


def test_a_known_four_bar_is_found_among_the_solutions_through_its_points(crank_rocker_search):
    """The complete solve through a Grashof crank-rocker's nine coupler points (plane
    geometry), shared with tests/test_path_search.py (tests/conftest.py)."""
    pts, z = _grashof_crank_rocker_points(set())
    res = crank_rocker_search.samples[0].solutions
    assert crank_rocker_search.samples[0].points == tuple(pts)
    assert res.paths == 1442
    want = npt.canonical(z[None, :])[0]
    gaps = np.linalg.norm(res.solutions - want, axis=1)
    assert gaps.min() <= 1e-8 * max(1.0, float(np.linalg.norm(want)))
    assert res.real[int(np.argmin(gaps))]


@pytest.fixture(scope="module")
def problem_3():
    return nt.solve_points([complex(x, y) for x, y in PROBLEM_3])


def test_problem_3_has_the_published_64_real_four_bars(problem_3):
    res = problem_3
    assert int(res.real.sum()) == 64
    # every one found is a solution, once: distinct orbits, nonsingular
    assert len(npt.distinct(npt.canonical(res.solutions))) == len(res.solutions)
    # the published 1,442 orbits (8,652 solutions): endpoints that will not settle in double
    # precision are polished at 60 digits, and a path that fails leaves its endpoint to the
    # next route
    assert len(res.solutions) == 1442 and res.missing == 0
    # each real one is a root to rounding: its residual against each equation's own terms,
    # evaluated exactly (60 digits) at the double-precision root, is at rounding level
    import mpmath

    p = np.array([complex(x, y) for x, y in PROBLEM_3])
    with mpmath.workdps(60):
        def exact(a):
            return np.array([[mpmath.mpc(complex(v)) for v in row] for row in np.atleast_2d(a)], dtype=object)

        d = p[1:] - p[0]
        residual = npt.relative_residual(exact(res.solutions[res.real]), exact(d)[0], exact(np.conj(d))[0])
    assert residual.max() <= 1e-13


def _grashof_crank_rocker_points(other_side: set[int], order: list[int] | None = None):
    """Nine coupler points of a Grashof crank-rocker (ground 3, crank 1, coupler 3, rocker
    2.5: 1 + 3 < 3 + 2.5), those in ``other_side`` taken in the other assembly, in
    ``order``. Returns the points and the four-bar (P_0 at the origin) by plane geometry."""
    A, B, r1, L, r2, k = 0j, 3 + 0j, 1.0, 3.0, 2.5, 0.4 + 0.6j
    pts, pose = [], None
    for i, phi in enumerate(np.linspace(0.2, 5.8, 9)):
        M = A + r1 * cmath.exp(1j * phi)
        d = abs(B - M)
        along = (L * L - r2 * r2 + d * d) / (2 * d)
        h = math.sqrt(L * L - along * along) * (-1 if i in other_side else 1)
        u = (B - M) / d
        N = M + along * u + h * u * 1j
        pts.append(M + (N - M) * k)
        if pose is None:
            pose = (M, N)
    if order is not None:
        pts = [pts[i] for i in order]
    M, N = pose
    P0 = pts[0]
    z = np.array([A - P0, M - P0, B - P0, N - P0])
    return pts, np.concatenate([z, np.conj(z)])


def test_a_design_through_its_points_in_order_on_one_circuit_has_no_defect():
    from linkage.synthesis.path import judge

    pts, z = _grashof_crank_rocker_points(set())
    fb = judge(z, pts)
    assert fb.defects == () and fb.grashof == "crank-rocker"
    assert fb.max_point_error <= 1e-12 * 3
    d = np.array(pts[1:]) - pts[0]
    assert np.abs(npt.equations(z[None, :], d, np.conj(d))[0]).max() <= 1e-10


def test_points_on_the_other_assembly_are_a_branch_defect():
    from linkage.synthesis.path import judge

    pts, z = _grashof_crank_rocker_points({4, 5})
    d = np.array(pts[1:]) - pts[0]
    assert np.abs(npt.equations(z[None, :], d, np.conj(d))[0]).max() <= 1e-10  # still through them
    assert judge(z, pts).defects == ("branch",)


def test_points_met_out_of_order_are_an_order_defect():
    from linkage.synthesis.path import judge

    pts, z = _grashof_crank_rocker_points(set(), [0, 1, 2, 5, 4, 3, 6, 7, 8])
    assert judge(z, pts).defects == ("order",)
    # the same points in reverse are met in order, turning the crank the other way
    pts, z = _grashof_crank_rocker_points(set(), [0, 8, 7, 6, 5, 4, 3, 2, 1])
    assert judge(z, pts).defects == ()


@pytest.mark.parametrize("bad", [
    [(0, 0)] * 9,
    [(i, i * i) for i in range(4)],
    [(i, i * i) for i in range(10)],
    [(float("nan"), 0), *[(i, i * i) for i in range(1, 9)]],
    [(0, 0), (0, 0), *[(i, i * i) for i in range(2, 9)]],
    [(1e200, 0), *[(i, i * i) for i in range(1, 9)]],
    "nine points",
])
def test_bad_points_are_refused_with_one_line(bad):
    from linkage.errors import InputError
    from linkage.synthesis.path import synthesize_path

    with pytest.raises(InputError) as err:
        synthesize_path(bad)
    assert "\n" not in str(err.value)


def _same_sets(a: np.ndarray, b: np.ndarray) -> bool:
    if len(a) != len(b):
        return False
    return all(np.min(np.linalg.norm(b - z, axis=1)) <= 1e-8 * max(1.0, float(np.linalg.norm(z))) for z in a)


def test_paths_tracked_as_dask_tasks_on_threads_and_a_loopback_cluster_end_where_they_end_here():
    """Issue 34, done-when 4: the tracking runs as tasks (chunks of paths) on the scan's
    runner: dask's local threads and a dask.distributed cluster of two worker processes on
    127.0.0.1; the endpoints are those tracked here (to 1e-8: a chunk's corrector steps
    are shared by its paths, so the last bits may differ)."""
    distributed = pytest.importorskip("distributed")
    from linkage.synthesis.path import chunk_runner

    pts = [complex(x, y) for x, y in PROBLEM_3]
    # 100 paths in chunks of 40: three tasks, the last one short, as 300 in the default 256 were two
    options = {"max_routes": 1, "orbits": 100, "chunk": 40}
    here = nt.solve_points(pts, **options)
    threads = nt.solve_points(pts, **options, run=chunk_runner("threads", 2))
    assert len(here.solutions) >= 95 and _same_sets(here.solutions, threads.solutions)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        remote = nt.solve_points(pts, **options, run=chunk_runner(cluster.scheduler_address, None))
    assert _same_sets(here.solutions, remote.solutions)
    assert remote.failed == here.failed


@pytest.mark.parametrize(("args", "says"), [
    (["--point", "0,0", "--point", "1,1"], "5 to 9 points"),
    (["--point", "0;0", *["--point", "1,1"] * 8], "write X,Y"),
    ([*[f"--point={k},{k * k}" for k in range(9)], "--plot", "x.png"], "--path takes 5 to 9 --point"),
    ([*[f"--point={k},{k * k}" for k in range(8)], "--point=0,0"], "coincide"),
])
def test_synthesize_path_refuses_bad_points_in_one_line(cli, args, says):
    out = cli("synthesize", "--path", *args)
    assert out.code == 2 and says in out.err and len(out.err.strip().splitlines()) == 1


def test_point_is_an_option_of_path(cli):
    out = cli("synthesize", "--function", "x", "--x", "1:2", "--alpha", "0:90", "--phi", "0:90",
              "--point", "0,0")
    assert out.code == 2 and "--point of --path" in out.err


def test_a_low_transmission_angle_over_the_motion_is_a_transmission_defect():
    from linkage.synthesis.path import judge

    pts, z = _grashof_crank_rocker_points(set())
    fb = judge(z, pts, min_transmission=0.0)
    assert fb.defects == () and 0.0 < fb.transmission_min_deg < 90.0
    assert judge(z, pts, min_transmission=fb.transmission_min_deg + 1e-6).defects == ("transmission",)


@pytest.fixture(scope="module")
def problem_3_first_orbits():
    """Problem 3's first 60 orbits, at the published size: the unit the scaled solves are
    compared with (computed once for every scale)."""
    return nt.solve_points([complex(x, y) for x, y in PROBLEM_3], max_routes=1, orbits=60)


@pytest.mark.parametrize("scale", [1e-6, 1e3])
def test_four_bars_through_points_scale_with_the_points(scale, problem_3_first_orbits):
    """Micrometres to kilometres: the same problem at another size gives the same four-bars
    at that size (the pivots scale with the points; the engine solves at unit size)."""
    pts = [complex(x, y) for x, y in PROBLEM_3]
    unit = problem_3_first_orbits
    moved = nt.solve_points([p * scale + (5.0 - 2.0j) * scale for p in pts], max_routes=1, orbits=60)
    assert len(moved.solutions) == len(unit.solutions) >= 57
    assert _same_sets(unit.solutions, moved.solutions / scale)


def test_problem_3s_64_real_four_bars_are_alpha_certified_real_and_distinct(problem_3):
    """Hauenstein and Sottile certified Problem 3's 64 real four-bars with alphaCertified;
    Smale's alpha test here (linkage.homotopy.ninepoint_alpha) certifies each double-precision
    solution real, and no two of them one root."""
    from types import SimpleNamespace

    from linkage.homotopy import alpha
    from linkage.homotopy import ninepoint_alpha as na
    from linkage.render.path_synthesis import certified_line

    res = problem_3
    rows = res.solutions[res.real]
    certs = na.certify_rows(rows, res.points)
    assert len(certs) == 64 and all(c.certified and c.real for c in certs)
    assert alpha.undistinguished(list(rows), certs) == []
    from linkage.synthesis.path import real_certificates

    assert certified_line(SimpleNamespace(certificates=real_certificates(res))) == (
        "alpha test (Smale; 50 digits): 64 of the 64 real four-bars certified real, all distinct")


def test_the_residual_against_the_terms_multiplied_out_is_at_rounding_for_every_solution(problem_3):
    """About 1% of Problem 3's complex solutions (pivots tens to thousands of times the
    points' size) had residuals up to 1e-9 against |N1 N2| + |D|^2: N1, N2 and D are there
    near cancellations, so that sum understates E_j's terms. Against the terms multiplied
    out (solve.relative_residual, as every other polynomial system's residual is measured),
    each of the 1,442 is at rounding, and the target's 1e-12 holds for all of them."""
    import mpmath

    from linkage.homotopy import ninepoint_alpha as na
    from linkage.homotopy.solve import relative_residuals

    res = problem_3
    p = np.array(res.points)
    d = p[1:] - p[0]
    system = na.polynomial_system(d, np.conj(d))
    everyone = relative_residuals(system, res.solutions)
    assert everyone.max() <= 1e-14
    flagged = np.flatnonzero(npt.relative_residual(res.solutions, d, np.conj(d)) > 1e-12)
    assert len(flagged) >= 5 and not res.real[flagged].any()
    # evaluated at 50 digits, so that neither figure is the rounding of its evaluation: the
    # factored measure stays above 1e-12 at those solutions, the terms' is at rounding
    Z = res.solutions[flagged]
    assert na.residuals(system, Z, d, np.conj(d)).max() <= 1e-14
    with mpmath.workdps(50):
        def exact(a):
            return np.array([[mpmath.mpc(complex(v)) for v in row] for row in np.atleast_2d(a)], dtype=object)

        factored = npt.relative_residual(exact(Z), exact(d)[0], exact(np.conj(d))[0])
    assert (factored > 1e-12).sum() >= 5

"""Path synthesis through five to nine points (linkage.synthesis.path_points, path_search):
the extra points that make nine, and the search that ranks defect-free four-bars, against
independent references: a known four-bar's coupler points (plane geometry), each listed
design moved through the points by circle intersection (not the engine's loops), a circle
for the curve through the points, and the same search on a dask loopback cluster."""

from __future__ import annotations

import cmath
import dataclasses
import math

import numpy as np
import pytest

from linkage.errors import InputError
from linkage.homotopy import ninepoint as npt
from linkage.homotopy import ninepoint_track as nt
from linkage.synthesis.path import CIRCUIT_DEFECTS, judge
from linkage.synthesis.path_points import curve_point, gap_counts, inserted, nine_points, sampled
from linkage.synthesis.path_search import search_path
from linkage.units import radians
from test_nine_point import _grashof_crank_rocker_points

GIVEN, VIA = (0, 1, 3, 4, 6, 8), (2, 5, 7)
"""Of a Grashof crank-rocker's nine coupler points (test_nine_point), six given and three
taken as the extra points."""


def _pairs(pts: list[complex]) -> list[tuple[float, float]]:
    return [(p.real, p.imag) for p in pts]


@pytest.fixture(scope="module")
def curve() -> tuple[list[complex], np.ndarray]:
    return _grashof_crank_rocker_points(set())


def search_the_crank_rocker():
    """The search through the six given points with the three via points: a complete
    nine-point solve, run once a session (tests/conftest.py's ``crank_rocker_search``)."""
    pts, _ = _grashof_crank_rocker_points(set())
    return search_path(_pairs([pts[i] for i in GIVEN]), via=_pairs([pts[i] for i in VIA]))


@pytest.fixture(scope="module")
def known(crank_rocker_search):
    return crank_rocker_search


def _through(fb, point: complex, crank_deg: float) -> float:
    """How far the design's coupler point is from ``point`` with the crank at ``crank_deg``,
    by plane geometry: the pin M on the crank circle, the pin N where the circles about M
    (coupler) and B (rocker) meet (the nearer of the two assemblies), P rigid with MN."""
    a, b, m0, n0 = fb.ground_a, fb.ground_b, fb.pin_m, fb.pin_n
    k = (fb.coupler_point - m0) / (n0 - m0)
    m = a + abs(m0 - a) * cmath.exp(1j * radians(crank_deg))
    coupler, rocker = abs(n0 - m0), abs(n0 - b)
    d = abs(b - m)
    along = (coupler * coupler - rocker * rocker + d * d) / (2 * d)
    h = math.sqrt(max(0.0, coupler * coupler - along * along))
    u = (b - m) / d
    return min(abs(m + (n - m) * k - point) for n in (m + along * u + h * u * 1j, m + along * u - h * u * 1j))


def test_the_via_points_go_into_their_gaps_and_make_the_curves_nine_points(curve, known):
    pts, _ = curve
    assert known.samples[0].points == tuple(pts) and known.samples[0].extra == VIA
    # eight of them and one more: the same nine-point problem, so the same four-bars
    for left_out in range(1, 8):
        given = [p for i, p in enumerate(pts) if i != left_out]
        assert nine_points(given, [pts[left_out]], 0, 0).points == tuple(pts)


def test_a_known_four_bar_through_six_of_its_coupler_points_is_among_the_ranked_designs(curve, known):
    pts, z = curve
    sample = known.samples[0]
    assert sample.found == nt.PATHS and sample.missing == 0
    members = npt.orbit(z)[:, :4] + pts[0]  # the four-bar and its cognates: a, x, b, y in the plane
    scale = float(np.abs(members).max())
    found = [d for d in known.designs
             if np.min(np.linalg.norm(members - [d.four_bar.ground_a, d.four_bar.pin_m, d.four_bar.ground_b,
                                                 d.four_bar.pin_n], axis=1)) <= 1e-8 * scale]
    assert found and {d.four_bar.lengths == pytest.approx((3.0, 1.0, 3.0, 2.5)) for d in found} >= {True}


def test_every_ranked_design_passes_through_the_points_in_rank_order(curve, known):
    pts, _ = curve
    assert known.designs
    size = max(abs(p - pts[0]) for p in pts)
    keys = [d.four_bar.transmission_min_deg for d in known.designs]
    assert keys == sorted(keys, reverse=True) and min(keys) >= 30.0
    for d in known.designs:
        fb = d.four_bar
        assert fb.defects == () and fb.max_point_error <= 1e-9  # the engine's own judgement
        # and by circle intersection, at the crank angles the engine found
        assert max(_through(fb, p, c) for p, c in zip(pts, fb.crank_deg)) <= 1e-9 * size


def test_cognates_share_the_defects_of_the_circuit(curve, known):
    """A search judges a design with a branch or order defect once: its cognates' motions
    correspond, so they have the same ones (checked here by judging them)."""
    pts, _ = curve
    sols = known.samples[0].solutions
    reals = np.flatnonzero(sols.real)
    once = [k for k, g in enumerate(known.samples[0].designs) if len(g) == 1]
    assert once
    for k in once[:4]:
        members = npt.orbit(sols.solutions[reals[k]] / 1.0)[:3]
        judged = [judge(m, list(pts)) for m in members]
        assert {tuple(d for d in fb.defects if d in CIRCUIT_DEFECTS) for fb in judged} == \
            {tuple(d for d in known.samples[0].designs[k][0].defects if d in CIRCUIT_DEFECTS)}


def test_the_curve_through_the_points_is_near_their_circle_and_passes_through_them():
    """The closed centripetal Catmull-Rom curve through six points of a circle stays within
    3% of its radius (a polygon's chords, within 13%)."""
    pts = [2.0 * cmath.exp(2j * math.pi * k / 6) + (1 - 1j) for k in range(6)]
    for k in range(6):
        assert abs(curve_point(pts, k, 0.0) - pts[k]) <= 1e-12
        assert abs(curve_point(pts, k, 1.0) - pts[(k + 1) % 6]) <= 1e-12
        assert all(abs(abs(curve_point(pts, k, s) - (1 - 1j)) - 2.0) <= 0.06 for s in np.linspace(0, 1, 11))


def test_extra_points_are_in_the_widest_gaps_between_the_given_ones_and_reproducible():
    pts = [0j, 1 + 0j, 2 + 0.2j, 6 + 0.5j, 7 + 1j]  # one wide gap, 4 units
    assert gap_counts(pts, 4) == [0, 0, 3, 1] or gap_counts(pts, 4) == [1, 0, 3, 0]
    for sample in range(4):
        nine = sampled(pts, 7, sample)
        assert len(nine.points) == 9 and nine.given == tuple(pts)
        assert 0 not in nine.extra and 8 not in nine.extra  # never before the first or after the last
        assert nine == sampled(pts, 7, sample)
    assert sampled(pts, 7, 1) != sampled(pts, 7, 2) != sampled(pts, 8, 2)
    even = sampled(pts, 0, 0)  # sample 0: evenly spaced along the curve
    assert even.points[even.extra[0]] == curve_point(pts, 2, 1 / 4)
    assert inserted(pts, [3.5 + 0.3j]).points == (pts[0], pts[1], pts[2], 3.5 + 0.3j, pts[3], pts[4])


@pytest.fixture(scope="module")
def sampled_here(curve):
    pts, _ = curve
    return search_path(_pairs([pts[i] for i in GIVEN]), samples=2, orbits=120, seed=3)


def _pivots(fb) -> np.ndarray:
    return np.array([fb.ground_a, fb.ground_b, fb.pin_m, fb.pin_n])


def _same_designs(a, b) -> bool:
    """Each sample's real designs (first cognates) are the same, judged the same: pivots to
    1e-8 (a chunk's corrector steps are shared by its paths, so the last bits may differ
    where chunks are cut differently), defects, least transmission angle; and so the ranks."""
    for x, y in zip(a.samples, b.samples):
        if len(x.designs) != len(y.designs):
            return False
        for group in x.designs:
            p = _pivots(group[0])
            twin = min(y.designs, key=lambda g: float(np.abs(_pivots(g[0]) - p).max()))[0]
            if np.abs(_pivots(twin) - p).max() > 1e-8 * np.abs(p).max() or twin.defects != group[0].defects \
                    or abs(twin.transmission_min_deg - group[0].transmission_min_deg) > 1e-6:
                return False
    return [(d.sample, d.cognate) for d in a.designs] == [(d.sample, d.cognate) for d in b.designs]


def test_each_sample_passes_through_the_given_points_with_its_own_extra_points(curve, sampled_here):
    pts, _ = curve
    given = tuple(pts[i] for i in GIVEN)
    first, second = sampled_here.samples
    assert first.points != second.points
    for s in sampled_here.samples:
        assert tuple(p for k, p in enumerate(s.points) if k not in s.extra) == given
        moved = [fb for group in s.designs for fb in group if "positions" not in fb.defects]
        assert moved
        for fb in moved:  # by circle intersection, at the crank angles the engine found
            size = max(*fb.lengths, max(abs(p - s.points[0]) for p in s.points))
            assert max(_through(fb, p, c) for p, c in zip(s.points, fb.crank_deg)) <= 1e-9 * size


def test_a_search_tracked_as_tasks_on_a_loopback_cluster_ranks_the_same_designs(curve, sampled_here):
    """Issue 34, done-when 4: each sample's paths run as tasks on a dask.distributed
    cluster of two worker processes on 127.0.0.1."""
    distributed = pytest.importorskip("distributed")
    pts, _ = curve
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        remote = search_path(_pairs([pts[i] for i in GIVEN]), samples=2, orbits=120, seed=3,
                             scheduler=cluster.scheduler_address)
    assert [s.points for s in remote.samples] == [s.points for s in sampled_here.samples]
    assert sum(len(s.designs) for s in remote.samples) >= 3
    assert _same_designs(remote, sampled_here)


NINE = [(0.25, 0), (0.52, 0.1), (0.8, 0.7), (1.2, 1), (1.4, 1.3), (1.1, 1.48), (0.7, 1.4), (0.2, 1),
        (0.02, 0.4)]


@pytest.mark.parametrize(("points", "options", "says"), [
    (NINE[:4], {}, "5 to 9 points"),
    ([*NINE, (3, 3)], {}, "5 to 9 points"),
    (NINE[:6], {"via": NINE[6:8]}, "need 3 extra points"),
    (NINE[:6], {"via": [NINE[0], *NINE[6:8]]}, "coincide"),
    (NINE[:6], {"via": [(math.nan, 0), *NINE[6:8]]}, "finite"),
    (NINE[:6], {"via": [(1e200, 0), *NINE[6:8]]}, "1e150"),
    (NINE, {"via": [(3, 3)]}, "need 0 extra points"),
    (NINE, {"samples": 2}, "nine points leave no extra points"),
    (NINE[:6], {"via": NINE[6:9], "samples": 2}, "via points leave no extra points"),
    (NINE[:6], {"samples": 0}, "samples"),
    (NINE[:6], {"orbits": 0}, "orbits"),
])
def test_bad_points_and_options_of_a_search_are_input_errors(points, options, says):
    with pytest.raises(InputError) as err:
        search_path(points, **options)
    assert says in str(err.value) and "\n" not in str(err.value)


def _args(points, option="--point"):
    return [a for x, y in points for a in (option, f"{x!r},{y!r}")]


@pytest.mark.parametrize(("args", "says"), [
    (_args(NINE[:6]) + _args(NINE[6:7], "--via"), "--via: 6 points need 3 extra points"),
    ([*_args(NINE[:6]), "--samples", "2"], "--samples is an option of --search"),
    ([*_args(NINE), "--search", "--samples", "2"], "--samples: nine points"),
    ([*_args(NINE[:6]), "--search", "--samples", "0"], "--samples must be"),
    ([*_args(NINE[:6]), "--via", "1;2"], "write X,Y"),
    (_args(NINE[:6]) + _args([NINE[0], *NINE[6:8]], "--via"), "coincide"),
])
def test_synthesize_path_search_refuses_bad_input_in_one_line(cli, args, says):
    out = cli("synthesize", "--path", *args)
    assert out.code == 2 and says in out.err and len(out.err.strip().splitlines()) == 1


@pytest.fixture()
def solved_known(monkeypatch, curve, known):
    """``linkage.homotopy.ninepoint_track.solve_points`` answering the known curve's nine points
    with the fixture's solutions (the known four-bar's group and three others), so that
    the command's plumbing is tested without tracking the paths again."""
    pts, _ = curve
    sols = known.samples[0].solutions
    reals = np.flatnonzero(sols.real)
    best = known.designs[0].group
    keep = [reals[best], *[reals[k] for k in range(len(reals)) if k != best][:3]]
    kept = {int(k): n for n, k in enumerate(keep)}  # the paths' four-bars, renumbered
    record = dataclasses.replace(sols.record, four_bar=np.array([kept.get(int(f), -1)
                                                                 for f in sols.record.four_bar]))
    small = dataclasses.replace(sols, solutions=sols.solutions[keep], real=sols.real[keep],
                                condition=sols.condition[keep], record=record)

    def solve(points, **_):
        assert list(points) == list(pts)
        return small

    monkeypatch.setattr(nt, "solve_points", solve)
    return known.designs[0]


def test_the_command_ranks_writes_the_best_and_says_none_with_exit_1(cli, curve, solved_known, tmp_path):
    pts, _ = curve
    args = ["synthesize", "--path", "--search", *_args(_pairs([pts[i] for i in GIVEN])),
            *_args(_pairs([pts[i] for i in VIA]), "--via")]
    out = cli(*args, "-f", "csv", "--table", "designs")
    assert out.code == 0, out.err
    head, first = out.out.splitlines()[:2]
    row = dict(zip(head.split(","), first.split(",")))
    assert int(row["design"]) == 1 and int(row["sample"]) == 1 and row["defects"] == "none"
    want = solved_known.four_bar.transmission_min_deg
    assert float(row["transmission_min (deg)"]) == pytest.approx(want, abs=1e-9)
    best = tmp_path / "best.toml"
    assert cli(*args, "-o", str(best)).code == 0
    import linkage

    m = linkage.load_mechanism(best)
    assert m.model is not None and abs(m.parameters["r1"].value - solved_known.four_bar.lengths[0]) <= 1e-12
    nothing = tmp_path / "none.toml"
    out = cli(*args, "--min-transmission", "89", "-o", str(nothing))
    assert out.code == 1 and not nothing.exists() and "no four-bar without defects" in out.out


def test_nine_points_searched_rank_the_finite_set_as_six_and_three_via_do(cli, curve, solved_known):
    pts, _ = curve
    nine = cli("synthesize", "--path", "--search", *_args(_pairs(pts)), "-f", "csv", "--table", "designs")
    six = cli("synthesize", "--path", "--search", *_args(_pairs([pts[i] for i in GIVEN])),
              *_args(_pairs([pts[i] for i in VIA]), "--via"), "-f", "csv", "--table", "designs")
    assert nine.code == six.code == 0 and nine.out == six.out and len(nine.out.splitlines()) >= 3


def test_without_search_six_points_and_three_via_get_the_nine_point_report_naming_the_extra_ones(
        cli, curve, solved_known):
    pts, _ = curve
    out = cli("synthesize", "--path", *_args(_pairs([pts[i] for i in GIVEN])),
              *_args(_pairs([pts[i] for i in VIA]), "--via"), "-f", "plain")
    # the stand-in solve has 4 of the 1,442 orbits: the report says so, and exits 1
    assert out.code == 1 and "(1438 not reached)" in out.out, out.err
    assert "through 6 given points and 3 extra points between them, points 3 (" in out.out
    assert "the nine: each design passes through all nine in order" in out.out

"""Which point sets path synthesis (synthesize --path, linkage.synthesize_path,
linkage.search_path) refuses before tracking a path: collinear and coincident points, with
tolerances relative to the points' spread (the same verdict at any unit of length). A
four-bar's coupler curve is a tricircular sextic and contains no line, so a line meets it
in at most 6 points (linkage.synthesis.path_points.MOST_ON_A_LINE): nine points with seven
on a line lie on no coupler curve. The tracking is replaced by a sentinel, so a refused set
fails fast when it is not refused (it would track for minutes)."""

from __future__ import annotations

import numpy as np
import pytest

from linkage.errors import InputError

LINE = (0.3 + 0.4j, 0.6 - 0.8j)
"""A point of the line and its unit direction: a slanted line, so no coordinate is exact."""


class Tracked(Exception):
    """Raised in place of the tracking: the points were accepted."""


@pytest.fixture
def no_tracking(monkeypatch):
    from linkage.homotopy import ninepoint_track

    def tracked(*args, **kwargs):  # type: ignore[no-untyped-def]
        raise Tracked

    monkeypatch.setattr(ninepoint_track, "solve_points", tracked)


def _on_line(n: int, scale: float, off: float = 0.0) -> list[tuple[float, float]]:
    """n points along LINE (spread n - 1 times ``scale``), bowed across it by at most ``off``
    of the spread (on a parabola: no three of them on a line unless ``off`` is 0)."""
    base, u = LINE
    bow = [4 * off * k * (n - 1 - k) / (n - 1) for k in range(n)]
    pts = [(base + (k + 1j * b) * u) * scale for k, b in enumerate(bow)]
    return [(p.real, p.imag) for p in pts]


@pytest.mark.parametrize("scale", [1e-9, 1.0, 1e3])
@pytest.mark.parametrize("n", [5, 6, 7, 8, 9])
def test_collinear_points_are_refused_before_any_tracking(n, scale, no_tracking):
    """Found: five collinear points tracked for more than 400 s (the curve through them, on
    which the extra points go, is their line: every path degenerate). Five to nine points
    on a line, at any unit of length, and 1e-12 of their spread off it: one line, no path."""
    from linkage.synthesis.path import synthesize_path
    from linkage.synthesis.path_search import search_path

    for off in (0.0, 1e-12):
        for solve in (synthesize_path, search_path):
            with pytest.raises(InputError, match="the points lie on one line") as err:
                solve(_on_line(n, scale, off))
            assert "\n" not in str(err.value)


@pytest.mark.parametrize("scale", [1e-9, 1.0, 1e3])
def test_points_a_thousandth_of_their_spread_off_a_line_are_tracked(scale, no_tracking):
    """Nearly straight is a real problem (approximate straight-line four-bars): accepted."""
    from linkage.synthesis.path import synthesize_path

    for n in range(5, 10):
        with pytest.raises(Tracked):
            synthesize_path(_on_line(n, scale, 1e-3))


def test_seven_of_nine_points_on_a_line_are_refused_and_six_are_not(no_tracking):
    from linkage.synthesis.path import synthesize_path

    off = [(3.0, 1.0), (1.0, 2.0), (5.0, 3.0)]
    with pytest.raises(InputError, match="7 of the nine points lie on one line"):
        synthesize_path([(k, 0.0) for k in range(7)] + off[:2])
    with pytest.raises(Tracked):
        synthesize_path([(k, 0.0) for k in range(6)] + off)


def test_collinear_points_with_via_points_off_the_line_are_tracked_and_on_it_refused(no_tracking):
    from linkage.synthesis.path import synthesize_path

    pts = _on_line(5, 1.0)
    with pytest.raises(Tracked):
        synthesize_path(pts, via=[(1.0, 1.0), (2.0, 3.0), (3.0, -1.0), (0.5, 2.0)])
    on = _on_line(9, 1.0)[5:]
    with pytest.raises(InputError, match=r"the points lie on one line .*, and so do the via points"):
        synthesize_path(pts, via=on)


def test_collinear_points_exit_2_with_one_line_before_any_tracking(cli, no_tracking):
    args = [a for k in range(5) for a in ("--point", f"{k},0")]
    for extra in ([], ["--search", "--samples", "2"]):
        out = cli("synthesize", "--path", *args, *extra)
        assert out.code == 2 and len(out.err.strip().splitlines()) == 1
        assert "the points lie on one line" in out.err and "--via: give 4 off the line" in out.err


@pytest.mark.parametrize("scale", [1e-9, 1.0, 1e3])
@pytest.mark.parametrize("n", [5, 7, 9])
def test_coincident_points_are_refused_at_any_scale(n, scale, no_tracking):
    """Two points 1e-12 of the spread apart coincide; 1e-3 apart they are two."""
    from linkage.synthesis.path import synthesize_path

    rng = np.random.default_rng(n)
    pts = [complex(*p) * scale for p in rng.uniform(-1, 1, (n, 2))]
    spread = max(abs(p - pts[0]) for p in pts)
    for apart, refused in ((0.0, True), (1e-12, True), (1e-3, False)):
        moved = [*pts[:-1], pts[1] + apart * spread]
        pairs = [(p.real, p.imag) for p in moved]
        if refused:
            with pytest.raises(InputError, match="coincide"):
                synthesize_path(pairs)
        else:
            with pytest.raises(Tracked):
                synthesize_path(pairs)


def test_a_route_whose_chunk_has_no_rows_polishes_to_nothing():
    """Found with collinear points (before they were refused): every path of a chunk given
    up, the polish of its empty block raised ValueError (reshape of 0 rows)."""
    from linkage.homotopy import ninepoint

    d = np.arange(1, 9) * (1 + 0.5j)
    Z, last, cond = ninepoint.polish(np.empty((0, 8), dtype=complex), d, np.conj(d))
    assert Z.shape == (0, 8) and last.shape == (0,) and cond.shape == (0,)

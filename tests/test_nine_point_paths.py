"""Every path of nine-point path synthesis on show (issue 34: per path and in total, every
step, corrector iteration and failure with its reason; a summary table of counts by class):
linkage.homotopy.ninepoint_track.PathRecord and the report's outcomes and paths tables.
The first 60 of the stored instance's orbits tracked to Problem 3's points (a few seconds)."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from linkage.homotopy import ninepoint_track as nt
from linkage.homotopy import tracker
from linkage.synthesis.path import PROBLEM_3, synthesize_path

ORBITS = 60
SETTLED = (nt.REACHED, nt.AGAIN, nt.DUPLICATE)
GIVEN_UP = (nt.UNDERFLOW, nt.TOO_MANY_STEPS, nt.INFINITE)


@pytest.fixture(scope="module")
def result():
    return synthesize_path(PROBLEM_3, orbits=ORBITS)


@pytest.fixture(scope="module")
def report(result):
    from linkage.render.path_synthesis import path_report

    return path_report(result, 6)


def test_each_paths_steps_sum_to_its_routes_total(result):
    s = result.solutions
    rec = s.record
    assert s.routes >= 1 and len(rec.route) == ORBITS * s.routes
    for r in range(s.routes):
        mine = rec.route == r + 1
        assert sorted(rec.path[mine]) == list(range(ORBITS))
        assert int(rec.steps[mine].sum()) == s.steps[r]


def test_a_carried_path_took_at_least_the_steps_its_legs_need_and_a_newton_step_each(result):
    """Independent bounds on the counts: a leg from t = 0 to 1 in steps of at most MAX_STEP
    takes at least 1 / MAX_STEP accepted steps; an accepted step had at least one corrector
    iteration and no step more than the tracker's CORRECTOR_STEPS; the smallest step size of
    a path that got through is not below the tracker's MIN_STEP."""
    rec = result.solutions.record
    legs = np.where(rec.route == 1, 1, 2)
    through = np.isin(rec.outcome, [*SETTLED, nt.UNSETTLED])
    accepted = rec.steps - rec.rejected
    assert np.all(accepted[through] >= legs[through] * math.ceil(1 / nt.MAX_STEP))
    assert np.all(rec.newton >= accepted) and np.all(rec.newton <= tracker.CORRECTOR_STEPS * rec.steps)
    smallest = rec.smallest_step[through]
    assert np.all((smallest >= tracker.MIN_STEP) & (smallest <= nt.MAX_STEP))


def test_every_failed_path_has_a_reason_and_every_settled_path_a_four_bar(result):
    s = result.solutions
    rec = s.record
    settled = np.isin(rec.outcome, SETTLED)
    assert np.all((rec.four_bar >= 0) == settled)
    assert np.all((rec.leg > 0) == np.isin(rec.outcome, GIVEN_UP))
    assert np.isin(rec.outcome, GIVEN_UP).any(), "Problem 3's first 60 orbits have a path given up"
    # each four-bar found is reached first by exactly one path; the others are again or duplicates
    reached = rec.four_bar[rec.outcome == nt.REACHED]
    assert sorted(reached) == list(range(len(s.solutions)))
    assert set(rec.four_bar[settled]) == set(range(len(s.solutions)))


def test_the_record_says_why_the_tracker_gave_a_path_up_as_the_trackers_own_words_do():
    """track_route's outcome codes against the tracker's failure messages, the same start
    solutions tracked on the same segment (solve_points' first route with seed 0)."""
    start = nt.load_start()
    p = np.array([complex(x, y) for x, y in PROBLEM_3])
    d1 = (p[1:] - p[0]) / float(np.max(np.abs(p[1:] - p[0])))
    patch = nt.random_patch(np.random.default_rng(0))
    legs = ((start.delta, start.deltabar, d1, np.conj(d1)),)
    chunk = nt.track_route(nt.Route(legs, (patch,), (d1, np.conj(d1))), 0, start.solutions[:ORBITS])
    with np.errstate(all="ignore"):
        _, ok, log = nt.track_segment(nt.ParameterSegment(*legs[0], patch), start.solutions[:ORBITS])
    words = np.array([f.split(" ")[0] for f in log.failure])
    assert list(chunk["path_steps"]) == list(log.steps)
    assert np.array_equal(chunk["outcome"] == nt.UNDERFLOW, words == "step")
    assert np.array_equal(chunk["outcome"] == nt.TOO_MANY_STEPS, words == "more")
    assert np.array_equal(chunk["outcome"] == nt.INFINITE, (words == "") & ~ok)
    assert (~ok).sum() == chunk["failed"][0] >= 1


def test_outcome_counts_equal_the_routes_summary_and_the_paths_table(result, report):
    s = result.solutions
    counts = s.record.counts(s.routes)
    tables = {t.name: t for t in report.tables}
    outcomes = {c.name: c.values for c in tables["outcomes"].columns}
    paths = {c.name: c.values for c in tables["paths"].columns}
    for r in range(s.routes):
        assert counts[r].sum() == s.paths == outcomes["paths"][r]
        assert counts[r, [nt.UNDERFLOW, nt.TOO_MANY_STEPS, nt.INFINITE]].sum() == s.failed[r]
        assert counts[r, nt.UNSETTLED] == s.unrefined[r]
        for k, name in enumerate(nt.OUTCOMES):
            assert outcomes[name][r] == counts[r, k] == sum(
                1 for route, o in zip(paths["route"], paths["outcome"]) if route == r + 1 and o == name)
    # the real four-bars are the designs: each design is some path's four-bar
    designs = {d for d in paths["design"] if d is not None}
    assert designs == set(range(1, len(result.designs) + 1))


def test_the_paths_table_is_the_same_when_the_chunks_run_on_dask_threads_as_here():
    pytest.importorskip("dask")
    from linkage.synthesis.path import chunk_runner

    pts = [complex(x, y) for x, y in PROBLEM_3]
    options = {"orbits": ORBITS, "max_routes": 1, "chunk": ORBITS // 2}
    here = nt.solve_points(pts, **options)
    threads = nt.solve_points(pts, **options, run=chunk_runner("threads", 2))
    for name in nt.PathRecord.__dataclass_fields__:
        assert np.array_equal(getattr(here.record, name), getattr(threads.record, name)), name
    assert sorted(here.record.path) == list(range(ORBITS))


def test_the_csv_and_json_have_one_row_per_path_per_route_and_the_terminal_only_the_summary(report, result,
                                                                                            tmp_path):
    from linkage.render import writers
    from linkage.render.display import display_text

    routes = result.solutions.routes
    writers.write(report, "csv", tmp_path / "paths.csv", table="paths")
    with open(tmp_path / "paths.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == ORBITS * routes
    assert {(r["route"], r["orbit"]) for r in rows} == {(str(r + 1), str(k + 1)) for r in range(routes)
                                                         for k in range(ORBITS)}
    assert {r["outcome"] for r in rows} <= set(nt.OUTCOMES)
    writers.write(report, "json", tmp_path / "all.json")
    document = json.loads((tmp_path / "all.json").read_text())
    text = json.dumps(document)
    assert '"paths"' in text and '"outcomes"' in text
    shown = display_text(report, "plain")
    assert "Paths by outcome" in shown and "step_underflow" in shown
    assert len(shown.splitlines()) < ORBITS  # the per-path rows are not on the terminal

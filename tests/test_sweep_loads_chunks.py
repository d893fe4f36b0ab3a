"""A loaded sweep's loads a chunk of positions at a time (kinematics.force_sweeps.load_chunks,
sweep_load_columns; docs/performance_loads.md): the chunks are produced one at a time and
each holds at most a chunk of positions; the columns and peaks are the same whatever the
chunk size, equal to the one-position-at-a-time answer (linkage.Forces per position) and
to the one peak rule over the whole sweep at once (forces.force_peaks); the memory added per
position is a few numbers, not a position's objects."""

from __future__ import annotations

import math
import random
import sys
import tracemalloc
from pathlib import Path

import numpy as np
import pytest

from linkage.cli import run_cli
from linkage.kinematics import force_sweeps
from linkage.kinematics.columns import sweep_columns
from linkage.kinematics.force_sweeps import FORCE_KEYS, load_chunks, sweep_load_columns
from linkage.kinematics.forces import FORCE_STATUSES, PeakTracker, force_peaks
from linkage.kinematics.loading import load
from linkage.kinematics.sweep import sweep_mechanism
from linkage.problems.loads import Loads

ROOT = Path(__file__).resolve().parents[1]
LOADED = ROOT / "docs" / "crank_rocker_loads.toml"
ME581 = ROOT / "sample_inputs" / "fourbar_me581_joints.toml"  # unsolved, near_toggle positions
EPS = sys.float_info.epsilon


def _swept(path: Path, values, speed: float | None, loads: Loads | None = None, batch: bool | None = None):
    m = load(path)
    loads = loads or m.extra["loads"]
    r = sweep_mechanism(m, values, speed=speed, batch=batch, loads=loads)
    return m, r, loads


def _same(a, b) -> bool:
    """Equal arrays, NaN where the other has NaN (bit for bit otherwise)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return a.shape == b.shape and bool(np.array_equal(a, b, equal_nan=True))


def _as_array(values) -> np.ndarray:
    return np.array([math.nan if v is None else v for v in values], dtype=float)


def test_loaded_sweep_cost_15_kb_a_position_its_loads_come_a_chunk_at_a_time(monkeypatch) -> None:
    """Finding: loaded sweeps cost 15 KB a position (every position's Forces, then lists and
    rows of them, all at once). Now a generator: the first chunk is given before the next
    is solved, and no chunk holds more than ``chunk`` positions."""
    m = load(LOADED)
    r = sweep_mechanism(m, [i * 0.5 for i in range(101)], speed=10.0)
    cols = sweep_columns(r)
    calls = []
    solve = force_sweeps.chunk_forces

    def counted(*args, **kw):
        calls.append(len(args[2]))
        return solve(*args, **kw)

    monkeypatch.setattr(force_sweeps, "chunk_forces", counted)
    chunks = load_chunks(m, cols, m.extra["loads"], 10.0, 0.0, chunk=16)
    assert iter(chunks) is chunks and not calls  # a generator: nothing solved until asked
    first = next(chunks)
    assert calls == [16] and first.start == 0 and len(first.status) == 16
    assert all(len(v) == 16 for v in first.columns.values())
    rest = list(chunks)
    assert len(calls) == 1 + len(rest) == math.ceil(101 / 16)
    assert max(calls) <= 16 and [c.start for c in rest] == list(range(16, 101, 16))


@pytest.mark.parametrize("path, speed, values", [
    (LOADED, 10.0, [i * 0.5 for i in range(721)]),
    (LOADED, None, [i * 2.0 for i in range(181)]),
    (ME581, 4.0, [i * 0.25 for i in range(1441)]),  # unsolved and near_toggle positions
], ids=["crank-rocker-speed", "crank-rocker-static", "me581-toggles"])
def test_loaded_sweep_cost_15_kb_a_position_chunks_equal_the_whole_sweep(path: Path, speed, values) -> None:
    """Every column, every status and both peaks of the chunked loads equal the whole sweep
    at once (one chunk) and the one-position-at-a-time Forces (SweepResult.force_columns),
    with the peaks on a chunk boundary (the chunk ending just before, at, and just after
    each peak) and at chunk sizes that divide nothing evenly."""
    m, r, loads = _swept(path, values, speed)
    cols = sweep_columns(r)
    n = len(values)
    whole = sweep_load_columns(m, cols, loads, speed or 0.0, 0.0, chunk=n)
    # the independent answer: each position's linkage.Forces, the one peak rule at once
    ref = r.force_columns()
    codes = np.array([FORCE_STATUSES.index(s) if s in FORCE_STATUSES else -1 for s in ref["status"]])
    assert np.array_equal(whole.status, codes)
    assert list(whole.columns) == [k for k in ref if k != "status"]
    for k in whole.columns:
        assert _same(whole.columns[k], _as_array(ref[k])), k
    (at_in, at_pin), flagged = force_peaks(codes[None, :], _as_array(ref["input"])[None, :],
                                           _as_array(ref["max_pin_force"])[None, :])
    assert (whole.peak_input, whole.peak_pin, whole.flagged) == (at_in[0], at_pin[0], flagged[0])
    assert whole.peak_input >= 0
    if path == ME581:
        assert whole.flagged > 0 and (whole.status == -1).any()
    sizes = {7, 100, 4096}
    for peak in (whole.peak_input, whole.peak_pin):
        sizes |= {k for k in (peak - 1, peak, peak + 1) if k >= 1}
    for size in sorted(sizes):
        got = sweep_load_columns(m, cols, loads, speed or 0.0, 0.0, chunk=size)
        assert np.array_equal(got.status, whole.status), size
        assert list(got.columns) == list(whole.columns), size
        for k in whole.columns:
            assert _same(got.columns[k], whole.columns[k]), (size, k)
        assert (got.peak_input, got.peak_pin, got.flagged) == \
            (whole.peak_input, whole.peak_pin, whole.flagged), size


def _peak_column(rng: random.Random, status: np.ndarray, top: float) -> np.ndarray:
    """Values within a few ulps of ``top``, others well below, some negative (a peak is of
    |value|); no number where the forces are undefined (every ok position has one) and at
    some unsolved positions."""
    n = len(status)
    col = np.array([rng.choice([1, -1]) * (top * (1.0 + rng.randint(-12, 3) * EPS) if rng.random() < 0.4
                                           else rng.uniform(0.0, 0.9) * top) for _ in range(n)])
    col[status == 3] = math.nan
    col[(status == -1) & (np.arange(n) % 2 == 0)] = math.nan
    return col


def test_loaded_sweep_cost_15_kb_a_position_peaks_across_chunks_follow_the_one_rule() -> None:
    """PeakTracker fed chunk by chunk gives force_peaks' answer over the whole row: the first
    of the values equal to the largest within rounding, flagged positions counted and never
    taken. Ties within a few ulps straddle the chunk boundaries on purpose (a chunk's own
    largest can fall out when a later chunk's is a few ulps larger)."""
    rng = random.Random(32)
    for case in range(300):
        n = rng.randint(1, 60)
        top = rng.choice([1.0, 3.7, 1e-3, 0.0])
        status = np.array([rng.choice([0, 0, 0, 1, 2, 3, -1]) for _ in range(n)])
        col, other = _peak_column(rng, status, top), _peak_column(rng, status, top)
        want, flagged = force_peaks(status[None, :], col[None, :], other[None, :])
        cuts = sorted(rng.sample(range(1, n), min(n - 1, rng.randint(0, 6)))) if n > 1 else []
        t = PeakTracker(2)
        for a, b in zip([0, *cuts], [*cuts, n]):
            t.add(status[a:b], col[a:b], other[a:b])
        at, count = t.peaks()
        assert at == [int(want[0][0]), int(want[1][0])], case
        assert count == int(flagged[0]), case
    t = PeakTracker(1)
    t.add(np.array([3, -1]), np.array([np.nan, np.nan]))
    assert t.peaks() == ([-1], 1)


def _loads_memory(m, cols, loads, chunk: int) -> int:
    tracemalloc.start()
    try:
        sweep_load_columns(m, cols, loads, 10.0, 0.0, chunk=chunk)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_loaded_sweep_cost_15_kb_a_position_now_a_few_numbers_a_position() -> None:
    """The memory the loads add grows by the columns' few numbers a position (at most 1 KB:
    16 float columns and a status byte here), not by a position's objects; a chunk's
    working memory does not grow with the sweep. Measured by tracemalloc (bytes
    allocated, not time): 4 and 16 chunks of 64 positions."""
    m = load(LOADED)
    r = sweep_mechanism(m, [i * 360.0 / 1023 for i in range(1024)], speed=10.0)
    cols = sweep_columns(r)
    loads = m.extra["loads"]
    # (not _replace: SweepColumns' own length is its positions')
    small = type(cols)(**{**cols._asdict(), "inputs": cols.inputs[:256], "status": cols.status[:256],
                          "solution": {k: v[:256] for k, v in cols.solution.items()},
                          "rates": cols.rates[:256]})
    _loads_memory(m, small, loads, 64)  # imports and first-call caches, not counted
    few, many = _loads_memory(m, small, loads, 64), _loads_memory(m, cols, loads, 64)
    per_position = (many - few) / (1024 - 256)
    assert per_position <= 1024, per_position
    # the loads' own columns are most of it: 16 numbers and a status a position
    columns = len(sweep_load_columns(m, small, loads, 10.0, 0.0).columns)
    assert columns == len(FORCE_KEYS) + 8 and per_position <= 8 * columns + 200


def test_loaded_sweep_cost_15_kb_a_position_command_line_equals_each_position(tmp_path) -> None:
    """The command line's loads table over several chunks (7,201 positions on the batch
    engine) is the one-position-at-a-time Forces' every column, number for number, and its
    peak line names the one rule's peak."""
    import csv
    import io

    out = tmp_path / "l.csv"
    code = run_cli(["sweep", str(LOADED), "--step", "0.05", "--speed", "10", "--batch", "-f", "csv",
                    "-o", str(out)])
    assert code == 0
    rows = list(csv.reader(io.StringIO((tmp_path / "l.loads.csv").read_text())))  # one table a file
    head, body = rows[0], rows[1:]
    assert len(body) == 7201
    _, r, _ = _swept(LOADED, [float(row[0]) for row in body], 10.0, batch=True)
    ref = r.force_columns()
    assert [row[1] for row in body] == ref["status"]
    for j, h in enumerate(head[2:], start=2):
        name = h.rsplit(" (", 1)[0]
        got = np.array([float(row[j]) if row[j] else math.nan for row in body])
        assert _same(got, _as_array(ref[name])), name

"""A sweep's positions table streamed to its file (render.sweep.RateCells and CellColumn,
kinematics.columns.RateChunks, kinematics.force_sweeps.LoadColumns;
docs/performance_loads.md): with a driver speed, each position's rates are computed a chunk
at a time as the writer takes the rows, the loads from the same chunk, and no sweep holds
every position's rates or their cells. The file is the same whatever the chunk size, its
numbers each position's own rates (kinematics.rates, one position at a time) bit for bit,
and the memory grows by well under 1 KB a position."""

from __future__ import annotations

import csv
import io
import math
import subprocess
import sys
from pathlib import Path

import pytest

from linkage.cli import run_cli
from linkage.kinematics import batch as batch_engine
from linkage.kinematics.loading import load
from linkage.kinematics.rates import rates_at

ROOT = Path(__file__).resolve().parents[1]
LOADED = ROOT / "docs" / "crank_rocker_loads.toml"
ME581 = ROOT / "sample_inputs" / "fourbar_me581_joints.toml"  # unsolved, near_toggle positions
ME581_ARGS = ["--from", "0", "--to", "360", "--step", "0.25", "--speed", "4", "--torque", "rocker=2",
              "--batch"]


def _tables(path: Path) -> dict[str, list[list[str]]]:
    """A report's CSV files (one table a file: ``x.csv`` positions, ``x.NAME.csv`` beside it)
    as name -> rows (header first)."""
    out = {"positions": list(csv.reader(io.StringIO(path.read_text())))}
    for other in path.parent.glob(f"{path.stem}.*.csv"):
        out[other.name[len(path.stem) + 1:-len(".csv")]] = list(csv.reader(io.StringIO(other.read_text())))
    return out


def _run(tmp_path: Path, name: str, args: list[str]) -> Path:
    out = tmp_path / name
    assert run_cli(["sweep", str(ME581), *args, "-o", str(out)]) == 0
    return out


def test_a_loaded_sweeps_file_is_the_same_whatever_the_chunk(tmp_path, monkeypatch) -> None:
    """The me581 four-bar over a turn (1,441 positions: unsolved ones, near_toggle ones, on
    the batch engine) at --speed with a torque: its CSV with the rates a chunk of 16
    positions at a time (90 chunks, their boundaries inside the gaps and the flagged runs)
    is byte for byte the one with every position in one chunk, and its parquet files read
    back equal; every rate in it is that position's own rates (kinematics.rates, one at a
    time), bit for bit; the loads table's peaks line up with the one-chunk run's."""
    import pyarrow.parquet as pq

    whole = _run(tmp_path, "whole.csv", ME581_ARGS)
    _run(tmp_path, "whole.parquet", ME581_ARGS)
    monkeypatch.setattr(batch_engine, "RATES_CHUNK", 16)
    chunked = _run(tmp_path, "chunked.csv", ME581_ARGS)
    _run(tmp_path, "chunked.parquet", ME581_ARGS)
    assert chunked.read_bytes() == whole.read_bytes()
    assert (tmp_path / "chunked.loads.csv").read_bytes() == (tmp_path / "whole.loads.csv").read_bytes()
    for stem in ("", ".loads"):
        a, b = (pq.read_table(tmp_path / f"{k}{stem}.parquet") for k in ("whole", "chunked"))
        assert a.num_rows == 1441 and a.equals(b), stem
    tables = _tables(whole)
    head, body = tables["positions"][0], tables["positions"][1:]
    status = [row[1] for row in body]
    forces = [row[1] for row in tables["loads"][1:]]
    cuts = range(16, 1441, 16)
    # chunk boundaries inside a gap and beside flagged loads (what the test is for)
    assert any(status[c - 1] != "converged" and status[c] != "converged" for c in cuts)
    assert any({forces[c - 1], forces[c]} & {"near_toggle", "ill_conditioned", "undefined"} for c in cuts)
    # every rate is the position's own (the one definition, one position at a time)
    m = load(ME581)
    names = [u.name for u in m.unknowns]
    col = {h.rsplit(" (", 1)[0]: j for j, h in enumerate(head)}
    checked = 0
    for row in body[::7]:
        if row[1] != "converged":
            assert all(row[col[f"d{n}/dt"]] == "" for n in names)
            continue
        q = [math.radians(float(row[col[n]])) if u.kind == "angle" else float(row[col[n]])
             for n, u in zip(names, m.unknowns)]
        r = rates_at(m, q, speed=4.0, driver=math.radians(float(row[0])))
        assert row[col["rates status"]] == r.status
        for n in names:
            if r.velocities:
                assert float(row[col[f"d{n}/dt"]]) == r.velocities[n]
                assert float(row[col[f"d2{n}/dt2 bound"]]) == r.acceleration_bounds[n]
        for j, (x, y) in r.joints.items():
            assert (float(row[col[f"{j}.x"]]), float(row[col[f"{j}.y"]])) == (x, y)
        checked += 1
    assert checked > 100


def test_the_positions_rates_are_not_all_computed_before_writing(monkeypatch, tmp_path) -> None:
    """The rates are computed as the writer takes the rows: when the first block of rows
    reaches the file, only the chunks of that block have been computed (the loads taken
    from the same chunks), not the sweep's."""
    from linkage.kinematics.columns import RateChunks
    from linkage.render import formats

    monkeypatch.setattr(batch_engine, "RATES_CHUNK", 16)
    computed: list[int] = []
    real = RateChunks.chunk_block

    def counted(self, start):  # each chunk of rates as it is computed (or read again)
        computed.append(start)
        return real(self, start)

    monkeypatch.setattr(RateChunks, "chunk_block", counted)
    seen: list[tuple[int, int]] = []
    rows = formats.CsvSink.rows

    def watched(self, values):
        if self.name == "positions" and not seen:
            seen.append((len(values[0]), len(set(computed))))
        return rows(self, values)

    monkeypatch.setattr(formats.CsvSink, "rows", watched)
    _run(tmp_path, "s.csv", ME581_ARGS)
    first_block, chunks_then = seen[0]
    assert first_block == 64 and chunks_then <= 64 // 16 + 1  # (+1: the first solved, for the joints' names)
    assert len(set(computed)) >= 1441 // 16


GROWTH = """
import sys, tracemalloc
from linkage.cli import loads, run_cli
from linkage.kinematics import batch, force_sweeps
from linkage.render import cells
# small chunks and blocks (rates, loads, CSV rows): what a block holds is then small beside
# the growth measured, at sizes a test can afford
batch.RATES_CHUNK = force_sweeps.LOADS_CHUNK = 128
cells.SLICE, cells.ARROW_BATCH, cells.CSV_WINDOW, loads._Later.block = 256, 512, 512, 512
tracemalloc.start()
code = run_cli(sys.argv[1:])
print(tracemalloc.get_traced_memory()[1])
sys.exit(code)
"""


def _peak(tmp_path: Path, path: Path, positions: int, speed: bool) -> int:
    step = 360.0 / (positions - 1)
    motion = ["--speed", "10"] if speed else []
    out = subprocess.run([sys.executable, "-c", GROWTH, "sweep", str(path), "--step", repr(step), *motion,
                          "--batch", "-f", "csv", "-o", str(tmp_path / "g.csv")],
                         capture_output=True, text=True, check=True)
    return int(out.stdout.split()[-1])


@pytest.mark.parametrize("path, speed", [(LOADED, True), (LOADED, False)],
                         ids=["loaded-speed", "loaded-static"])
def test_loaded_sweep_memory_is_flat_in_the_position_count(tmp_path, path: Path, speed: bool) -> None:
    """Finding: a loaded sweep cost 15 KB a position (and the unloaded one with --speed 6
    to 9 KB: every position's rates and their cells held for the table). Now the memory a
    sweep to CSV allocates (tracemalloc's peak, in a fresh process: bytes, not time) grows
    by less than 1 KB a position from 1,025 to 3,073 positions (the engine's and the loads'
    arrays, a few numbers a position); before, 6 KB and more."""
    small, large = 1025, 3073
    growth = (_peak(tmp_path, path, large, speed) - _peak(tmp_path, path, small, speed)) / (large - small)
    assert growth < 1024, growth

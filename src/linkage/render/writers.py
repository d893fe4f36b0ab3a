"""Writing a report in the format asked: the format chosen from --format or -o's suffix
(every choice read from the registry, :data:`.formats.FORMATS`), the tables streamed into
the format's sink a block of rows at a time (never one Python object per cell of a large
table), or the display shown.

A file is written to a temporary name beside it and renamed when complete
(:func:`~linkage.files.atomic_target`): a failed or interrupted run leaves no
half-written file (nor sidecar: each is renamed only when the whole report is written).
``--table NAME`` keeps one table of any data format (:func:`pick_table`).
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

from ..errors import InputError, OutputError
from .cells import SLICE, Sink, safe_name
from .data import Column, DataTable, Report
from .formats import COMMON_TABULATE, FORMATS, TABULATE_SUFFIXES


def tabulate_formats() -> list[str]:
    from tabulate import tabulate_formats as names

    return [n for n in names if n not in FORMATS]


def suffix_map() -> dict[str, str]:
    out = {s: f.name for f in FORMATS.values() for s in f.suffixes}
    return {**out, **TABULATE_SUFFIXES}


def known_suffixes() -> str:
    return ", ".join(f"{s} ({n})" for s, n in suffix_map().items() if s)


def is_data(fmt: str) -> bool:
    """Writes the report's tables (a sink's format), not its display."""
    return fmt in FORMATS and FORMATS[fmt].streams


def is_binary(fmt: str) -> bool:
    """Written to a file only."""
    return fmt in FORMATS and FORMATS[fmt].binary


def data_formats() -> str:
    """The formats that write the tables, as a sentence's list: ``csv, json, parquet or xlsx``."""
    names = [f.name for f in FORMATS.values() if f.streams]
    return ", ".join(names[:-1]) + f" or {names[-1]}" if len(names) > 1 else "".join(names)


def format_help() -> str:
    """--format's help, from the registry: the display formats with what they are, the data
    formats and which of them need -o FILE, and tabulate's."""
    shown = [f"{f.name} ({f.help})" if f.help else f.name for f in FORMATS.values() if not f.streams]
    binary = [f.name for f in FORMATS.values() if f.binary]
    files = f" ({' and '.join(binary)} to -o FILE)" if binary else ""
    return (f"{', '.join(shown)}, {data_formats()}{files}, or any tabulate format "
            f"({', '.join(COMMON_TABULATE[:3])}, ...).")


def output_help() -> str:
    """-o's help, from the registry."""
    suffixes = ", ".join(s for s in suffix_map() if s)
    return (f"Write to this file instead of standard output; the format follows the suffix "
            f"({suffixes}) unless --format is given.")


def choose_format(fmt: str | None, output: Path | None, *, terminal: bool | None = None) -> str:
    """The format of this run: --format if given (checked), else -o's suffix, else table on
    a terminal and plain when piped. An unknown format or suffix, or a binary format for
    standard output, is an InputError naming what works."""
    to_stdout = output is None or str(output) == "-"
    if fmt is not None:
        fmt = fmt.strip().lower()  # --format CSV as --format csv, as a suffix .CSV is .csv
    if fmt is None:
        if not to_stdout:
            suffix = output.suffix.lower()  # type: ignore[union-attr]
            chosen = suffix_map().get(suffix)
            if chosen is None:
                raise InputError(f"-o {output}: unknown suffix {suffix}; use {known_suffixes()}, "
                                 "or --format NAME (any format to any file name)")
            fmt = chosen
        else:
            tty = sys.stdout.isatty() if terminal is None else terminal
            fmt = "table" if tty else "plain"
    elif fmt not in FORMATS and fmt not in tabulate_formats():
        raise InputError(f"unknown format {fmt!r}; use {', '.join(FORMATS)} or a tabulate format "
                         f"({', '.join(f for f in COMMON_TABULATE if f in tabulate_formats())}, ...)")
    spec = FORMATS.get(fmt)
    if to_stdout and spec is not None and spec.binary:
        raise InputError(f"{fmt} is a binary format: give -o FILE{spec.suffixes[0]}")
    if spec is not None and spec.needs is not None:
        from importlib.util import find_spec

        if find_spec(spec.needs[0].split(".")[0]) is None:  # found, not imported: see prefetch
            raise InputError(missing(fmt))
    return fmt


def missing(fmt: str) -> str:
    """The refusal of a format whose package is not installed."""
    module, how = FORMATS[fmt].needs  # type: ignore[misc]
    return f"{fmt} output needs {module.split('.')[0]}: {how}"


def prefetch(fmt: str, rows: int | None = None) -> None:
    """Start importing, on a thread, the modules ``fmt``'s writer will need for a table of
    ``rows`` rows, so that the import (pyarrow: 0.13 to 0.17 s, a third of a
    360,001-position sweep's computing) runs beside the command's computing; the writer's
    own import then finds them loaded, or waits for them. An import that fails here is
    left to fail where the writer needs it (:func:`open_sink` says so in one line)."""
    spec = FORMATS.get(fmt)
    sink = spec.sink if spec else None
    names = [m for m in (sink.modules(rows) if sink else ()) if m not in sys.modules]
    if names and sink is not None:
        import threading

        thread = threading.Thread(target=import_quietly, args=(names,),
                                  name="linkage-prefetch")
        _prefetching.append(thread)
        thread.start()


_prefetching: list[Any] = []
"""Prefetch threads started: the writer waits for them before its own import, so that a
package that fails to import fails there, in one line, and not in a race between two
threads importing it at once (a flaky refusal, seen in tests/test_format_registry.py)."""


def wait_for_prefetch() -> None:
    """Wait for the prefetch threads started (their imports) to finish."""
    while _prefetching:
        _prefetching.pop().join()


def import_quietly(names: Sequence[str]) -> None:
    """Import ``names``, quietly: a failure is left to the writer, which meets it again and
    says so."""
    try:
        for name in names:
            __import__(name)
    except Exception:
        return


def sidecar_name(output: Path | str, table: str) -> str:
    """Where a one-table format puts a report's table ``table`` beside ``output``."""
    p = Path(output)
    return str(p.with_name(f"{p.stem}.{safe_name(table)}{p.suffix}"))


@contextlib.contextmanager
def open_sink(fmt: str, output: Path | None, meta: dict[str, Any] | None = None) -> Iterator[Sink]:
    """A sink for a data format, to ``output`` (None or "-": standard output), finished and
    renamed into place only if the block completes; a one-table format puts a second table
    in a sidecar file (:func:`side_paths`), renamed with the first."""
    to_stdout = output is None or str(output) == "-"
    spec = FORMATS[fmt]
    make: Any = spec.sink
    wait_for_prefetch()
    if spec.needs is not None:
        try:
            __import__(spec.needs[0])
        except ImportError:
            raise InputError(missing(fmt)) from None
    try:
        with contextlib.ExitStack() as stack:
            if to_stdout:
                sink: Sink = make(sys.stdout, None, meta)
                yield sink
                sink.close()
                sys.stdout.flush()
                return
            from ..files import atomic_target

            tmp = stack.enter_context(atomic_target(output))  # type: ignore[arg-type]
            if spec.binary:
                sink = make(None, tmp, meta)
                if spec.one_table:
                    sink.side = lambda t: sidecar_target(stack, output, t)  # type: ignore[arg-type]
                try:
                    yield sink
                except BaseException:
                    sink.abandon()  # an interrupt stays an interrupt, and nothing is saved
                    raise
                sink.close()
            else:
                fh = stack.enter_context(open(tmp, "w", encoding="utf-8", newline=""))
                sink = make(fh, tmp, meta)
                if spec.one_table:
                    sink.side = lambda t: stack.enter_context(
                        open(sidecar_target(stack, output, t), "w", encoding="utf-8", newline=""))  # type: ignore[arg-type]
                yield sink
                sink.close()
                sink.out.flush()  # type: ignore[union-attr]
    except OSError as exc:
        where = "standard output" if to_stdout else str(output)
        raise OutputError(f"cannot write to {where}: {exc.strerror or exc}") from None


def sidecar_target(stack: contextlib.ExitStack, output: Path, table: str) -> str:
    """A sidecar file's temporary path, renamed into place (synced) with the main file."""
    from ..files import atomic_target

    return stack.enter_context(atomic_target(Path(sidecar_name(output, table))))


def check_report_paths(report: Report, fmt: str, output: Path | None, table: str | None = None) -> list[Path]:
    """The sidecar files :func:`write` writes for ``report``, named only once the report is
    made, checked against the inputs and the outputs the command named at its start
    (files.check_more_outputs) before anything is written: a table file on the --plot's
    path is refused with neither written, as every command writes its report before its
    pictures. A one-table
    format of several tables on standard output is refused here too. ``table``: --table's
    (the report then has that one table)."""
    to_stdout = output is None or str(output) == "-"
    if table is not None:
        report = pick_table(report, fmt, table)
    spec = FORMATS.get(fmt)
    if spec is None or spec.sink is None or not spec.one_table:
        return []
    tables = [t for t in report.tables if t.columns]
    if to_stdout:
        if len(tables) > 1:
            names = ", ".join(t.name for t in tables)
            raise InputError(f"{fmt} holds one table and this report has {len(tables)} ({names}): add "
                             f"--table NAME for one on standard output, or -o FILE{spec.suffixes[0]} "
                             "(one file each)")
        return []
    sides = side_paths(output, report)  # type: ignore[arg-type]
    if sides:
        from ..files import check_more_outputs

        check_more_outputs([(f"-o {output}'s table file", p) for p in sides])
    return sides


def side_paths(output: Path, report: Report) -> list[Path]:
    """The files a one-table format's report of several tables writes beside ``output``."""
    return [Path(sidecar_name(output, t.name)) for t in [t for t in report.tables if t.columns][1:]]


PROGRESS_ROWS = 16 * SLICE
"""Rows handed to a sink at a time when a progress bar is shown."""


def write_tables(sink: Sink, tables: Sequence[DataTable],
                 progress: Callable[[int], None] | None = None) -> None:
    """Every table into ``sink``; ``progress(rows written so far)`` after each block. A
    column made as it is read (its values with a ``block`` attribute: a sweep's rates,
    render.sweep.CellColumn) sets the rows handed over at a time, so no more than a block
    of it is ever made."""
    done = 0
    for t in tables:
        n = t.row_count
        sink.begin(t.name, t.columns, n)
        step = PROGRESS_ROWS if progress is not None else max(n, 1)
        blocks = [b for b in (getattr(c.values, "block", None) for c in t.columns) if b]
        if blocks:
            step = min(step, *blocks)
        for a in range(0, n, step):
            whole = step >= n
            sink.rows([c.values if whole else c.values[a:a + step] for c in t.columns])
            done += min(step, n - a)
            if progress is not None:
                progress(done)
        sink.end()


# --- the one entry point --------------------------------------------------------------------

def write(report: Report, fmt: str, output: Path | None, *,
          progress: Callable[[int], None] | None = None, table: str | None = None) -> None:
    """Write ``report`` in ``fmt`` to ``output`` (None or "-": standard output);
    ``progress(rows written)`` as a data format's rows go out; ``table`` (--table) keeps
    that one of the report's tables (:func:`pick_table`). The report's sidecar files are
    checked first (:func:`check_report_paths`)."""
    to_stdout = output is None or str(output) == "-"
    if table is not None:
        report = pick_table(report, fmt, table)
    spec = FORMATS.get(fmt)
    sides = check_report_paths(report, fmt, output)  # a csv or parquet report's sidecar files
    if spec is not None and spec.sink is not None:
        tables = [t for t in report.tables if t.columns]
        files = [Path(str(output)).name] + [p.name for p in sides] if not to_stdout else []
        with open_sink(fmt, output, spec.sink.meta_of(report, files)) as sink:
            write_tables(sink, tables, progress)
    else:
        from .display import display_text, print_table

        if fmt == "table" and to_stdout:
            try:
                print_table(report)
            except OSError as exc:
                raise OutputError(f"cannot write to standard output: {exc.strerror or exc}") from None
            return
        text = display_text(report, "plain" if fmt == "table" else fmt)
        if to_stdout:
            try:
                sys.stdout.write(text)
                sys.stdout.flush()
            except OSError as exc:
                raise OutputError(f"cannot write to standard output: {exc.strerror or exc}") from None
            return
        from ..files import write_atomic

        write_atomic(output, text)  # type: ignore[arg-type]
    if not to_stdout:
        made = [str(output)] + [str(p) for p in sides]
        print(f"wrote {', '.join(made)}", file=sys.stderr)


def pick_table(report: Report, fmt: str, name: str) -> Report:
    """``--table NAME``: the report with that one of its tables (any data format; the
    display formats show the whole report and refuse it). A name that is not one of the
    report's tables is an InputError naming those there are."""
    names = [t.name for t in report.tables if t.columns]
    if not is_data(fmt):
        raise InputError(f"--table picks a table of {data_formats()} output, not {fmt}")
    kept = tuple(t for t in report.tables if t.name == name.strip() and t.columns)
    if not kept:
        raise InputError(f"--table {name!r}: no such table; this report has {', '.join(names) or 'none'}")
    return report._replace(tables=kept)


def _matching_nothing(report: Report, wanted: Sequence[str]) -> list[str]:
    """The names of ``--columns`` that begin no column's name or header, in the tables or in
    the display's tables (whose headers may differ: tolerance's "nominal"), first columns too."""
    from .report import Table

    heads = {h.lower() for t in report.tables for c in t.columns for h in (c.name, c.header)}
    if any(not any(h.startswith(w) for h in heads) for w in wanted):
        heads |= {h.lower() for b in report.blocks() if isinstance(b, Table) for h in b.headers}
    return [w for w in wanted if not any(h.startswith(w) for h in heads)]


def pick_columns(report: Report, names: str) -> Report:
    """``--columns``: keep each table's first column and the columns whose name (or
    header) begins with one of ``names`` (comma-separated, case-insensitive), in the tables
    and in the display; a display table says which columns it left out. None matching is
    an InputError naming the columns there are."""
    from .report import pick_columns as pick_blocks

    wanted = [w.strip().lower() for w in names.split(",") if w.strip()]

    def keep(c: Column) -> bool:
        return any(c.name.lower().startswith(w) or c.header.lower().startswith(w) for w in wanted)

    tables = []
    matched = False
    for t in report.tables:
        cols = t.columns[:1] + tuple(c for c in t.columns[1:] if keep(c))
        matched = matched or len(cols) > 1
        tables.append(t._replace(columns=cols) if len(cols) > 1 else t)
    there = sorted({c.name for t in report.tables for c in t.columns[1:]})
    if not matched:
        raise InputError(f"--columns {names!r} matches no column; the columns are {', '.join(there)}")
    unmatched = _matching_nothing(report, wanted)
    if unmatched:  # one name that matches nothing is a mistake, even beside one that matches
        raise InputError(f"--columns {', '.join(repr(w) for w in unmatched)}: matches no column; the "
                         f"columns are {', '.join(there)}")
    blocks = report.blocks

    def picked() -> Any:
        try:
            return pick_blocks(blocks(), ((), ()), names)[0]
        except InputError:
            return blocks()  # the display shows fewer columns than the tables: keep it whole

    return report._replace(tables=tuple(tables), blocks=picked)


"""A report is a list of blocks; backends print it with rich or tabulate.

Numbers are formatted here, once, to ``digits`` significant digits: the engine keeps
full double precision and rounding happens only on the way to the screen.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from itertools import zip_longest
from typing import Any

from ..records import NamedTuple


# A NamedTuple, not a frozen dataclass: built once per class at import, it costs
# 0.1 ms against 0.7 ms, and every command's start pays for its classes.
class Text(NamedTuple):
    text: str
    style: str = ""


class Table(NamedTuple):
    title: str
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]
    notes: tuple[str, ...] = ()


Block = Text | Table


def fmt(v: Any, digits: int = 12) -> str:
    """One cell: integers as they are, floats to ``digits`` significant digits."""
    if isinstance(v, float):  # first: a table's usual cell (a sweep's table has thousands)
        if math.isfinite(v):
            # printf's %g: the text of format(v, f".{digits}g") (the same conversion,
            # tested), without building the format spec for every cell
            return "%.*g" % (digits, v) if v != 0.0 else "0"  # noqa: UP031 (the faster of the two)
        return "NaN" if math.isnan(v) else "inf" if v > 0 else "-inf"
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else "no"
    return str(v)  # an integer as it is, or text


NOISE_ULPS = 16
"""How many rounding errors of its scale a displayed value may be and still be zero."""


def is_noise(v: Any, scale: float, bound: float | None = None) -> bool:
    """Whether ``v`` is rounding noise around zero: within ``NOISE_ULPS`` rounding errors
    of ``scale`` (the size of the quantities it was computed from: a mechanism's largest
    coordinate for a joint's x and y, its fastest joint for a velocity), or within its own
    error bound where it has one. Display tables print such a value as 0 (a joint at the
    origin computed as 9.18e-15 cm); CSV, JSON, parquet and xlsx keep every bit. Never for
    a number that is small on its own (an iteration's error or residual): those have no
    larger scale beside them and are passed through untouched."""
    if not isinstance(v, float) or not math.isfinite(v):
        return False
    limit = NOISE_ULPS * 2.220446049250313e-16 * abs(scale) if math.isfinite(scale) else 0.0
    if bound is not None and math.isfinite(bound):
        limit = max(limit, bound)
    return abs(v) <= limit


def denoise(v: Any, scale: float, bound: float | None = None) -> Any:
    """``v``, or 0.0 where it is rounding noise (:func:`is_noise`): for display only."""
    return 0.0 if is_noise(v, scale, bound) else v


def table(title: str, headers: Sequence[str], rows: Sequence[Sequence[Any]], digits: int,
          notes: Sequence[str] = ()) -> Table:
    return Table(title, tuple(headers), tuple(tuple(fmt(v, digits) for v in r) for r in rows),
                 tuple(notes))


def pick_columns(blocks: Sequence[Block], csv_table: tuple[Any, Any],
                 names: str) -> tuple[list[Block], tuple[Any, Any]]:
    """Keep the first column and the columns whose names begin with one of ``names``
    (comma-separated, case-insensitive) in every table that has any, and in the CSV; a
    table says which columns it left out."""
    from ..errors import InputError

    wanted = [w.strip().lower() for w in names.split(",") if w.strip()]

    def keep(headers: Sequence[str]) -> list[int]:
        return [0] + [j for j, h in enumerate(headers) if j and any(h.lower().startswith(w) for w in wanted)]

    out: list[Block] = []
    matched = False
    for b in blocks:
        if isinstance(b, Table) and len(keep(b.headers)) > 1:
            cols = keep(b.headers)
            matched = True
            left = [h for j, h in enumerate(b.headers) if j not in cols]
            notes = (*b.notes, f"(--columns: left out {', '.join(left)})") if left else b.notes
            b = Table(b.title, tuple(b.headers[j] for j in cols),
                      tuple(tuple(r[j] for j in cols) for r in b.rows), notes)
        out.append(b)
    headers, rows = csv_table
    if headers and len(keep(headers)) > 1:
        cols = keep(headers)
        matched = True
        csv_table = (tuple(headers[j] for j in cols), [tuple(r[j] for j in cols) for r in rows])
    if not matched:
        raise InputError(f"--columns {names!r} matches no column")
    return out, csv_table


def history_blocks(h: Any, digits: int) -> list[Block]:
    """A recorded history as a table, with a visible gap and a note where a long run's
    history left rows out; nothing for an empty one."""
    if h is None or not h.rows:
        return []
    rows = h.rows
    if h.elided:
        rows = (*rows[:h.gap_at], ("...",) * len(h.columns), *rows[h.gap_at:])
    blocks: list[Block] = [table("", h.columns, rows, digits)]
    if h.elided:
        blocks.append(Text(h.note))
    return blocks


def tabulate_formats() -> list[str]:
    from tabulate import tabulate_formats as names

    return list(names)


def simple_table(headers: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """Headers over a rule, columns right-aligned and two spaces apart: tabulate's
    ``simple`` format (tests check they agree), without importing tabulate (about 20 ms
    of every piped command's start)."""
    widths = [len(h) + 2 for h in headers]  # tabulate's MIN_PADDING around a header
    for j, cells in enumerate(zip_longest(*rows, fillvalue="")):  # a column at a time
        widths[j] = max(widths[j], max(map(len, cells)))
    # every line through one format (each cell right-aligned, as str.rjust): a sweep's
    # table is hundreds of lines; a short row's missing cells are blanks, stripped below
    n = len(widths)
    aligned = "  ".join(f"{{:>{w}}}" for w in widths).format
    lines = [aligned(*headers), "  ".join("-" * w for w in widths)]
    lines += [aligned(*r) if len(r) == n else aligned(*r, *("",) * (n - len(r))) for r in rows]
    return "\n".join(line.rstrip() for line in lines)


def render_text(blocks: Sequence[Block], tablefmt: str) -> str:
    """Render as text: ``plain`` is tabulate's ``simple`` (headers over a rule), drawn
    here; any other name is a tabulate format (imported only then)."""
    out: list[str] = []
    for b in blocks:
        if isinstance(b, Text):
            out.append(b.text)
        else:
            if b.title:
                out.append(b.title)
            if tablefmt == "plain":
                out.append(simple_table(b.headers, b.rows))
            else:
                from tabulate import tabulate

                out.append(tabulate(b.rows, headers=b.headers, tablefmt=tablefmt,
                                    disable_numparse=True, stralign="right"))
            out.extend(b.notes)
            out.append("")
    return "\n".join(out).rstrip("\n") + "\n"


PROSE_WIDTH = 30
"""A cell of words longer than this (a benchmark target, a note) wraps between them."""


def _cell_width(cell: str) -> int:
    if len(cell) <= PROSE_WIDTH or " " not in cell:
        return len(cell)
    return max(PROSE_WIDTH, *(len(w) for w in cell.split()))


def column_widths(headers: Sequence[str], rows: Sequence[Sequence[str]],
                  width: int | None = None) -> list[int]:
    """Each column's width: its widest cell (a number or a status is never broken) or its
    header's longest word (headers wrap between words), whichever is wider. If that
    table is wider than ``width``, sentences wrap between words at PROSE_WIDTH first."""
    def widths(cell: Any) -> list[int]:
        return [max(max((cell(r[j]) for r in rows), default=0),
                    max((len(w) for w in h.split()), default=1)) for j, h in enumerate(headers)]

    natural = widths(len)
    if width is None or 1 + sum(w + 3 for w in natural) <= width:
        return natural
    return widths(_cell_width)


def is_prose(rows: Sequence[Sequence[str]], j: int, width: int) -> bool:
    """Column j holds sentences wrapped to ``width`` (read from the left)."""
    return any(len(r[j]) > width and " " in r[j] for r in rows)


def column_groups(headers: Sequence[str], rows: Sequence[Sequence[str]], width: int) -> list[list[int]]:
    """Split columns into groups that fit ``width`` with every cell whole (see
    :func:`column_widths`; a column also takes 3 characters of padding and separator,
    the table 1 more). Groups after the first repeat column 0 (the iteration or the
    driver value), so each stacked table reads on its own."""
    need = [w + 3 for w in column_widths(headers, rows, width)]
    groups: list[list[int]] = []
    current: list[int] = [0]
    used = 1 + need[0]
    for j in range(1, len(headers)):
        if used + need[j] > width and len(current) > 1:
            groups.append(current)
            current, used = [0], 1 + need[0]
        current.append(j)
        used += need[j]
    groups.append(current)
    return groups


def widen_headers(headers: Sequence[str], cols: Sequence[int], widths: list[int], width: int) -> list[int]:
    """The widths of one group of columns, with the room the group leaves in ``width``
    given, left to right, to columns whose header would wrap (a header such as
    "true error (deg) vs crossed" over narrow numbers reads on one line where it fits,
    not one word a line)."""
    out = [widths[j] for j in cols]
    spare = width - 1 - sum(w + 3 for w in out)
    for i, j in enumerate(cols):
        extra = min(max(len(headers[j]) - out[i], 0), max(spare, 0))
        out[i] += extra
        spare -= extra
    return out


def print_rich(blocks: Sequence[Block], file: Any = None) -> None:
    """Render to a terminal with rich (imported only here). A table wider than the
    terminal is split into stacked tables (:func:`column_groups`): numbers and status
    words are never wrapped or cut."""
    import sys

    from rich import box
    from rich.console import Console
    from rich.table import Table as RichTable

    out = file or sys.stdout
    # Off a terminal there is no width to respect; never let rich elide digits.
    width = None if getattr(out, "isatty", lambda: False)() else 240
    console = Console(file=out, highlight=False, width=width)
    for b in blocks:
        if isinstance(b, Text):
            console.print(b.text, style=b.style or None, markup=False)
            continue
        groups = column_groups(b.headers, b.rows, console.width) if b.headers else [[]]
        for k, cols in enumerate(groups):
            title = b.title or None
            if len(groups) > 1:
                part = f"(columns part {k + 1} of {len(groups)})"
                # a title that cannot take the part on its line gets it on the next, whole
                sep = "\n" if b.title and len(b.title) + 1 + len(part) > console.width else " "
                title = f"{b.title + sep if b.title else ''}{part}"
            widths = column_widths(b.headers, b.rows, console.width)
            shown = widen_headers(b.headers, cols, widths, console.width)
            if title and len(title) > 1 + sum(w + 3 for w in shown):
                # rich wraps a title to its table's width: a narrow table's long title
                # would break every few words, so it is printed above, as one line
                console.print(title, style="bold", markup=False)
                title = None
            t = RichTable(title=title, box=box.SIMPLE_HEAVY, title_justify="left", title_style="bold")
            for j, w in zip(cols, shown):
                # a fixed width: rich wraps the header in it and never shrinks a number
                t.add_column(b.headers[j], justify="left" if is_prose(b.rows, j, widths[j]) else "right",
                             overflow="fold", width=w)
            for r in b.rows:
                t.add_row(*(r[j] for j in cols))
            console.print(t)
        for n in b.notes:
            console.print(n, markup=False)

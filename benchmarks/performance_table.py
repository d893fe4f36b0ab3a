"""Regenerate the speed-target tables of README.md and docs/performance.md from one run of
the bench: ``linkage bench --full -f json -o bench.json``, then
``python benchmarks/performance_table.py bench.json --label "abc1234, the machine quiet"``.

Each file keeps its table between the markers ``<!-- targets: begin -->`` and
``<!-- targets: end -->``; everything outside them is left as it is. The figures are the
run's own (the bench's ``targets`` table: ratio, the medians of the pairs, met), rounded
only here, for printing. docs/performance.md also keeps issue 34's two tables (absolute
times, and every root checked at 50 digits: the bench's ``continuation`` record) between
``<!-- continuation: begin -->`` and ``<!-- continuation: end -->``."""

from __future__ import annotations

import argparse
import json
import re
from pathlib import Path

from linkage.measure.targets import ROWS

BEGIN, END = "<!-- targets: begin -->", "<!-- targets: end -->"
ROOT = Path(__file__).resolve().parent.parent


def table(targets: list[dict], label: str) -> str:
    """The markdown table of the bench's targets, a row each, as measured: issue 33's
    first, then the earlier targets the bench still judges."""
    lines = [f"One run of `linkage bench --full -f json -o bench.json` ({label}), written here by "
             "`python benchmarks/performance_table.py bench.json`; each ratio is the median of "
             "interleaved pairs.",
             "", "| target | ratio | measured (median of pairs) | met |", "|---|---|---|---|"]
    for row in targets:
        ratio = row["measured"]
        shown = "n/a" if ratio is None else f"{ratio:.3g}"
        met = {True: "yes", False: "no", None: "n/a"}[row["met"]]
        pairs = row["ratio"].split(": ", 1)[-1]
        lines.append(f"| {row['target']} | {shown} | {pairs} | {met} |")
    return "\n".join(lines)


def seconds(t: float) -> str:
    """A time in seconds as the bench prints it: ms below a second, 3 significant digits."""
    return f"{t * 1e3:.3g} ms" if t < 1 else f"{t:.3g} s"


def continuation_tables(record: dict, label: str) -> str:
    """Issue 34's two tables from the bench's ``continuation`` record: the absolute
    times against their bounds, then the 50-digit check of every root."""
    yes = {True: "yes", False: "no", None: "n/a"}
    lines = [f"The same run as issue 33's table above ({label}; {record['cores']}):", "",
             "| target | bound | median | runs | found | met |", "|---|---|---|---|---|---|"]
    for row in record["targets"]:
        median = "n/a" if row["median"] is None else seconds(row["median"])
        lines.append(f"| {row['target']} | {row['bound']:g} s | {median} | {row['runs']} | "
                     f"{row['found']} | {yes[row['met']]} |")
    lines += ["", "| roots of | roots | worst residual | above 1e-12 | worst error | duplicates "
              "| spurious | met |", "|---|---|---|---|---|---|---|---|"]
    for row in record["certified"]:
        lines.append(f"| {row['target']} | {row['roots']} | {row['worst residual']:.3g} "
                     f"| {row['above 1e-12']} | {row['worst error']:.3g} | {row['duplicates']} "
                     f"| {row['spurious']} | {yes[row['met']]} |")
    return "\n".join(lines)


def replace(path: Path, text: str, begin: str = BEGIN, end: str = END) -> None:
    """``text`` between the markers of ``path`` (which must hold them, once)."""
    old = path.read_text()
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if len(pattern.findall(old)) != 1:
        raise SystemExit(f"{path}: expected one {begin} ... {end} block")
    path.write_text(pattern.sub(lambda _: f"{begin}\n{text}\n{end}", old))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("bench_json", type=Path)
    parser.add_argument("--label", required=True, help="the commit and the machine's state")
    args = parser.parse_args()
    run = json.loads(args.bench_json.read_text())
    targets = run["targets"]
    # the README shows issue 33's rows (its guide's length is bounded); the page, all
    for name, rows in (("README.md", targets[:len(ROWS)]), ("docs/performance.md", targets)):
        replace(ROOT / name, table(rows, args.label))
        print(f"updated {name}")
    if run.get("continuation"):
        replace(ROOT / "docs/performance.md", continuation_tables(run["continuation"], args.label),
                "<!-- continuation: begin -->", "<!-- continuation: end -->")
        print("updated docs/performance.md's issue 34 tables")


if __name__ == "__main__":
    main()

"""Regenerate the speed-target tables of README.md and docs/performance.md from one run of
the bench: ``linkage bench --full -f json -o bench.json``, then
``python benchmarks/performance_table.py bench.json --label "abc1234, the machine quiet"``.

Each file keeps its table between the markers ``<!-- targets: begin -->`` and
``<!-- targets: end -->``; everything outside them is left as it is. The figures are the
run's own (the bench's ``targets`` table: ratio, the medians of the pairs, met), rounded
only here, for printing."""

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
    lines = [f"One run of `linkage bench --full` ({label}); each ratio is the median of interleaved pairs.",
             "", "| target | ratio | measured (median of pairs) | met |", "|---|---|---|---|"]
    for row in targets:
        ratio = row["measured"]
        shown = "n/a" if ratio is None else f"{ratio:.3g}"
        met = {True: "yes", False: "no", None: "n/a"}[row["met"]]
        pairs = row["ratio"].split(": ", 1)[-1]
        lines.append(f"| {row['target']} | {shown} | {pairs} | {met} |")
    return "\n".join(lines)


def replace(path: Path, text: str) -> None:
    """``text`` between the markers of ``path`` (which must hold them, once)."""
    old = path.read_text()
    pattern = re.compile(re.escape(BEGIN) + r".*?" + re.escape(END), re.S)
    if len(pattern.findall(old)) != 1:
        raise SystemExit(f"{path}: expected one {BEGIN} ... {END} block")
    path.write_text(pattern.sub(lambda _: f"{BEGIN}\n{text}\n{END}", old))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("bench_json", type=Path)
    parser.add_argument("--label", required=True, help="the commit and the machine's state")
    args = parser.parse_args()
    targets = json.loads(args.bench_json.read_text())["targets"]
    # the README shows issue 33's rows (its guide's length is bounded); the page, all
    for name, rows in (("README.md", targets[:len(ROWS)]), ("docs/performance.md", targets)):
        replace(ROOT / name, table(rows, args.label))
        print(f"updated {name}")


if __name__ == "__main__":
    main()

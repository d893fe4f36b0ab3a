"""Measure some of issue 33's speed targets (docs/performance.md) without the whole bench:
``python benchmarks/target_rows.py 1 2 --repeats 5`` measures rows 1 and 2 of
``linkage.measure.targets.ROWS`` (numbered from 1, in the order of the bench's Targets
table) as ``linkage bench --full`` does, interleaved pairs and their median ratio."""

from __future__ import annotations

import argparse

from linkage.measure.targets import MEASURES, ROWS, run_rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("rows", nargs="+", type=int, help=f"row numbers, 1..{len(ROWS)}")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--budget", type=float, default=0.005, help="seconds a batch (the bench's)")
    args = parser.parse_args()
    chosen = {ROWS[k - 1]: MEASURES[ROWS[k - 1]] for k in args.rows}
    for k, outcome in zip(args.rows, run_rows(True, args.repeats, args.budget, measures=chosen)):
        label, shown, ratio, met = outcome.target
        print(f"{k:2d}. {label}\n    {shown}\n    ratio {ratio if ratio is None else f'{ratio:.3g}'}"
              f"  met {met}")


if __name__ == "__main__":
    main()

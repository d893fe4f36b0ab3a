"""The Moré-Garbow-Hillstrom square systems (MINPACK's hybrd tests, 66 cases): our
system solvers beside scipy's root(hybr) and root(lm), all with the exact Jacobian.

    python benchmarks/mgh.py            # the summary table (README, "Robustness")
    python benchmarks/mgh.py --cases    # every case, every solver
"""

from __future__ import annotations

import sys

from linkage.measure.mgh_table import SOLVED_RESIDUAL, run_table, summary


def main() -> None:
    table = run_table()
    print(f"solved: success claimed and max|F| <= {SOLVED_RESIDUAL:g}; "
          "false success: claimed, but above it\n")
    print("| solver | cases | solved | false successes |")
    print("|---|---|---|---|")
    for name, cases, solved, false in summary(table):
        print(f"| {name} | {cases} | {solved} | {false} |")
    if "--cases" in sys.argv:
        names = list(table)
        print("\n| case | " + " | ".join(names) + " |")
        print("|---|" + "---|" * len(names))
        for i, o in enumerate(table[names[0]]):
            cells = []
            for n in names:
                r = table[n][i]
                cells.append("solved" if r.solved else ("FALSE" if r.false_success else r.status[:24]))
            print(f"| {o.case} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()

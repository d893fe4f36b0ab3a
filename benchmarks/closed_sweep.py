"""Issue 19's sweep targets: the rows 3 and 6 of ``linkage bench``'s Targets table alone.

Times, interleaved in one run (one untimed run of each, then the repeats in turn; medians),
the whole ``linkage.sweep(...)`` call over 0..360 step 1 of crank_rocker.toml beside
pylinkage 1.3's ``Linkage.step_fast`` on the same geometry, and of watt_sixbar.toml beside
the one-at-a-time engine (``batch=False``); prints the medians and the two targets.
``linkage bench`` prints the same rows at the end of its full run.

    python benchmarks/closed_sweep.py              # 15 repeats
    python benchmarks/closed_sweep.py --repeats 31
"""

from __future__ import annotations

import argparse

from linkage.measure.precision import has_pylinkage
from linkage.measure.sweeps import sweep_targets, sweep_times


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=15)
    args = ap.parse_args()
    if not has_pylinkage():
        print("pylinkage is not installed: target 3 is n/a (pip install 'pylinkage==1.3.0')")
    times = sweep_times(args.repeats, None)
    for label, t in times.items():
        print(f"{label:55s} {t * 1e3:9.3f} ms")
    for target, comparison, r, met in sweep_targets(times):
        shown = "n/a" if r is None else f"{r:.2f}x"
        verdict = "n/a" if met is None else ("yes" if met else "no")
        print(f"{target}: {comparison} = {shown} (met: {verdict})")


if __name__ == "__main__":
    main()

"""The work-precision benchmark: the same as ``linkage bench``, with the diagram.

    python benchmarks/work_precision.py            # every problem, about a minute
    python benchmarks/work_precision.py --quick    # about 10 seconds

Prints every measurement, the cold-start times and the targets as ratios measured in
this run, and writes docs/work_precision.png.
"""

import sys
from pathlib import Path

from linkage.cli import run_cli

if __name__ == "__main__":
    out = Path(__file__).resolve().parents[1] / "docs" / "work_precision.png"
    sys.exit(run_cli(["bench", *sys.argv[1:], "--plot", str(out)]))

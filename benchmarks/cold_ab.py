"""A/B cold starts: one command in fresh interpreters on this tree's sources and on another
tree's (a worktree of an earlier commit), interleaved, medians (bytecode cached as an
installed package has it):

    git worktree add --detach /tmp/before 11913eb
    python benchmarks/cold_ab.py /tmp/before/src 31 sweep sample_inputs/crank_rocker.toml
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from pathlib import Path


def main(other_src: str, repeats: int, args: list[str]) -> None:
    here = str(Path(__file__).resolve().parents[1] / "src")
    base = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    trees = {"this tree": dict(base, PYTHONPATH=here), "other tree": dict(base, PYTHONPATH=other_src)}
    times: dict[str, list[float]] = {k: [] for k in trees}
    command = [sys.executable, "-m", "linkage", *args]
    for env in trees.values():  # once untimed: the bytecode cached
        subprocess.run(command, env=env, capture_output=True, check=False)
    for i in range(repeats):
        order = list(trees.items()) if i % 2 else list(trees.items())[::-1]
        for name, env in order:
            t0 = time.perf_counter()
            subprocess.run(command, env=env, capture_output=True, check=False)
            times[name].append(time.perf_counter() - t0)
    med = {k: statistics.median(v) * 1000 for k, v in times.items()}
    for k, v in med.items():
        print(f"{k:12s} {v:8.1f} ms (median of {repeats})")
    print(f"ratio        {med['this tree'] / med['other tree']:.3f}")


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]), sys.argv[3:])

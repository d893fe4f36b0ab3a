"""How a scan is cut into tasks for the local workers (linkage.scan.task.balanced): every
worker busy to the end, no task above the size a task may hold, and the records the same
whatever the cut."""

from __future__ import annotations

from pathlib import Path

import numpy as np

import linkage
from linkage.scan.task import MIN_TASK_POSITIONS, TASKS_PER_WORKER, balanced

CRANK = Path(__file__).resolve().parents[1] / "sample_inputs" / "crank_rocker.toml"


def test_a_loaded_scan_of_900_designs_is_cut_into_equal_tasks_for_two_workers():
    """Finding: 900 designs in tasks of 555 (the size limit) left one of two cores idle
    for the last 40% of the scan."""
    size = balanced(555, 900, 360, 2)
    tasks = -(-900 // size)
    assert tasks == TASKS_PER_WORKER * 2 and size * tasks - 900 < tasks


def test_a_loaded_scan_of_200_designs_is_cut_into_a_task_per_worker():
    """Finding: 200 designs x 360 positions in three tasks of 67 on two workers kept one
    idle for the last third of the scan (issue 33's loaded-scan row)."""
    assert balanced(555, 200, 360, 2) == 100
    for designs in (150, 200, 250, 400, 900, 5_000):
        for workers in (2, 3, 4):
            size = balanced(10**6, designs, 360, workers)
            tasks = -(-designs // size)
            if designs * 360 >= workers * MIN_TASK_POSITIONS:
                assert tasks % workers == 0, (designs, workers)


def test_the_cut_never_exceeds_the_size_nor_splits_a_small_scan():
    for designs in (1, 7, 50, 900, 10_000, 10**6):
        for workers in (1, 2, 8):
            for size in (1, 16, 555):
                got = balanced(size, designs, 360, workers)
                assert 1 <= got <= size
                if workers == 1:
                    assert got == size
    assert balanced(555, 10, 360, 2) == 10  # 3,600 positions: one task, run here
    assert balanced(555, 2 * MIN_TASK_POSITIONS // 360, 360, 8) >= MIN_TASK_POSITIONS // 360


def test_the_records_are_the_same_whatever_the_workers():
    grid = {"r2": (20.0, 60.0, 30), "r4": (60.0, 100.0, 20)}
    one = linkage.scan_designs(str(CRANK), grid, workers=1)
    two = linkage.scan_designs(str(CRANK), grid, workers=2)
    assert one.keys() == two.keys()
    for k in one:
        np.testing.assert_array_equal(one[k], two[k])

"""Running a scan's chunks: here (one chunk, or synchronous), on dask's local threaded or
process scheduler, or on a dask.distributed cluster given by address; always in design
order, with a bounded number of chunks in flight."""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from ..errors import InputError
from .designs import DesignPlan
from .task import run_chunk


def chunk_bounds(total: int, size: int) -> list[tuple[int, int]]:
    return [(a, min(a + size, total)) for a in range(0, total, size)]


def run_chunks(job: Any, plan: DesignPlan, size: int, *, scheduler: str | None = None,
               workers: int | None = None, task: Callable[..., dict[str, np.ndarray]] | None = None
               ) -> Iterator[dict[str, np.ndarray]]:
    """Every chunk's records, in design order. ``scheduler``: None or "threads" (dask's
    local threads), "processes", "synchronous", or the address of a dask.distributed
    scheduler (tcp://host:port). A scan of one chunk, not sent to a cluster, runs here
    without importing dask. ``task(job, start, designs)`` makes a chunk's records
    (default :func:`run_chunk`; a synthesis search passes its own, a module-level
    function, so it pickles)."""
    task = task or run_chunk
    bounds = chunk_bounds(plan.total, size)
    remote = scheduler is not None and "://" in scheduler
    if remote:
        check_scheduler(scheduler)  # type: ignore[arg-type]
    if not remote and (len(bounds) == 1 or scheduler == "synchronous" or workers == 1):
        for a, b in bounds:
            yield task(job, a, plan.chunk(a, b))
        return
    if remote:
        yield from _distributed(job, plan, bounds, scheduler, task)  # type: ignore[arg-type]
        return
    yield from _local(job, plan, bounds, scheduler or "threads", workers, task)


def _local(job: Any, plan: DesignPlan, bounds: list[tuple[int, int]], kind: str,
           workers: int | None, task: Callable[..., dict[str, np.ndarray]] = run_chunk
           ) -> Iterator[dict[str, np.ndarray]]:
    import os

    if kind not in ("threads", "processes"):
        raise InputError(f"--scheduler must be threads, processes, synchronous or tcp://HOST:PORT, "
                         f"got {kind!r}")
    try:
        if kind == "threads":
            from dask.threaded import get
        else:
            from dask.multiprocessing import get
    except ImportError:
        print("note: dask is not installed, so the chunks run one after another here "
              "(pip install 'linkage-kinematics[scan]' to run them in parallel)", file=sys.stderr)
        for a, b in bounds:
            yield task(job, a, plan.chunk(a, b))
        return
    n = workers or os.cpu_count() or 1
    window = 2 * n  # chunks in flight: memory stays bounded however many designs there are
    for w in range(0, len(bounds), window):
        part = bounds[w:w + window]
        graph = {("chunk", i): (task, job, a, plan.chunk(a, b)) for i, (a, b) in enumerate(part)}
        yield from get(graph, [("chunk", i) for i in range(len(part))], num_workers=n)


def check_scheduler(address: str) -> tuple[str, int]:
    """The host and port of ``tcp://HOST:PORT``, after one quick connection attempt (a
    closed port answers at once, where dask's client retries for its whole timeout);
    anything else an InputError."""
    import socket
    from urllib.parse import urlsplit

    try:
        parts = urlsplit(address)
        host, port = parts.hostname, parts.port
    except ValueError as exc:  # a port beyond 65535 or not a number
        raise InputError(f"--scheduler {address!r}: {exc}; give tcp://HOST:PORT") from None
    if parts.scheme != "tcp" or not host or port is None or parts.path not in ("", "/"):
        raise InputError(f"--scheduler {address!r}: give tcp://HOST:PORT (threads, processes and "
                         "synchronous run here; only tcp:// clusters are supported)")
    try:
        socket.create_connection((host, port), timeout=5.0).close()
    except OSError as exc:
        raise InputError(f"cannot reach the dask scheduler at {address}: "
                         f"{exc.strerror or exc}") from None
    return host, port


def _distributed(job: Any, plan: DesignPlan, bounds: list[tuple[int, int]], address: str,
                 task: Callable[..., dict[str, np.ndarray]] = run_chunk) -> Iterator[dict[str, np.ndarray]]:
    from collections import deque

    try:
        from distributed import Client
    except ImportError:
        raise InputError("--scheduler tcp://... needs dask.distributed: pip install "
                         "'linkage-kinematics[scan]'") from None
    try:
        client = Client(address, timeout="10s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise InputError(f"cannot reach the dask scheduler at {address}: {exc}") from None
    try:
        n = max(1, sum(client.nthreads().values()))
        window = 2 * n
        pending: deque[Any] = deque()
        queue = iter(bounds)
        for a, b in queue:
            pending.append(client.submit(task, job, a, plan.chunk(a, b), pure=False))
            if len(pending) >= window:
                break
        while pending:
            result = pending.popleft().result()
            nxt = next(queue, None)
            if nxt is not None:
                pending.append(client.submit(task, job, nxt[0], plan.chunk(*nxt), pure=False))
            yield result
    finally:
        client.close()


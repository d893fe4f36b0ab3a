"""Design-space scans: many variants of one mechanism, each over its whole cycle, reduced to
one flat record per design, filtered, ranked and streamed out chunk by chunk.

Designs come from a grid (``NAME=LO:HI:N`` per parameter, the last varying fastest) or
from ``samples`` random or Latin-hypercube draws (:mod:`.designs`). They are cut into
chunks; each chunk is one task (:func:`.task.run_chunk`), which runs the design batch
engine (:mod:`linkage.kinematics.designs`) and returns the records' columns
(:mod:`.metrics`). A scan of one chunk runs in this process; more chunks run on dask
(:mod:`.engine`): its local threaded scheduler by default (numpy releases the GIL in the
chunks' array work; measured against processes in ``benchmarks/scan.py``), or a
dask.distributed cluster given by address. A task carries the mechanism file's text, never
a path, so workers need only this package installed. Results do not depend on who ran them:
every computation in a chunk is per design. :mod:`.keep` filters, ranks and keeps;
:mod:`.request` checks a scan once for the API and the command line and streams it
(:func:`run_scan`). A tolerance study (:mod:`.tolerance`) is a scan of perturbed designs.
"""

from .designs import MAX_DESIGNS, MAX_SCAN_POSITIONS, DesignPlan, Vary, parse_vary
from .engine import run_chunks
from .keep import Keeper, concat, take
from .request import ScanRequest, open_scan, run_scan, scan
from .task import ScanJob, run_chunk

__all__ = ["MAX_DESIGNS", "MAX_SCAN_POSITIONS", "DesignPlan", "Keeper", "ScanJob", "ScanRequest", "Vary",
           "concat", "open_scan", "parse_vary", "run_chunk", "run_chunks", "run_scan", "scan", "take"]

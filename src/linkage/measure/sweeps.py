"""The earlier speed targets still judged beside issue 33's table (:mod:`.targets`):
issue 19's sweeps against pylinkage and the one-at-a-time engine, and its scan of Watt
six-bars against the crank-rocker's. Each is a median of interleaved runs in this
process."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .precision import has_pylinkage
from .timing import interleaved

WATT_CLOSED = "linkage.sweep watt_sixbar.toml 361 positions"
WATT_ONE = "one-at-a-time sweep watt_sixbar.toml 361 positions"


def sweep_times(repeats: int = 5, scan_designs: int | None = None) -> dict[str, float]:
    """Median seconds: ``linkage.sweep`` of crank_rocker.toml over 0..360 step 1 beside
    pylinkage's ``Linkage.step_fast`` on the same geometry (when installed); the same
    sweep of watt_sixbar.toml beside the one-at-a-time engine (``batch=False``), all four
    interleaved; and the scans of :func:`scan_times` (``scan_designs`` designs; None: not
    run). Each time is of the whole call, the front door's checks and the result
    included."""
    from ..samples import sample_path
    from ..units import radians
    from . import api

    m = api.load_mechanism(sample_path("crank_rocker.toml"))
    w = api.load_mechanism(sample_path("watt_sixbar.toml"))
    v = {k: q.value for k, q in m.parameters.items()}
    values = [float(k) for k in range(361)]
    pair: dict[str, Callable[[], Any]] = {"linkage.sweep 361 positions": lambda: api.sweep(m, values),
                                          WATT_CLOSED: lambda: api.sweep(w, values),
                                          WATT_ONE: lambda: api.sweep(w, values, batch=False)}
    if has_pylinkage():
        import pylinkage as pl

        o2, o4 = pl.Ground(0.0, 0.0), pl.Ground(v["r1"], 0.0)
        crank = pl.Crank(o2, radius=v["r2"], angular_velocity=radians(1.0), initial_angle=0.0)
        b = pl.RRRDyad(crank, o4, distance1=v["r3"], distance2=v["r4"], x=v["r1"] + 37.0, y=71.0)
        lk = pl.Linkage([o2, o4, crank, b])
        pair["pylinkage step_fast 361 positions"] = lambda: lk.step_fast(iterations=361)
    out = {k: t for k, (t, _, _) in interleaved(pair, max(repeats, 5)).items()}
    if scan_designs is not None:
        out.update(scan_times(repeats, scan_designs))
    return out


SCAN_DESIGNS = 2_000
"""Designs in the scan target's comparison (issue 19); --quick scans a tenth."""


def scan_keys(designs: int) -> tuple[str, str]:
    """The sweep-table keys of the six-bar scan and the four-bar scan."""
    return (f"linkage.scan {designs:,} Watt six-bar designs x 360 positions",
            f"linkage.scan {designs:,} crank-rocker designs x 360 positions")


def scan_times(repeats: int, designs: int) -> dict[str, float]:
    """Median seconds of the same scan (r2, r3, r4 sampled; 0..359 deg; in-process, one
    chunk after another) of watt_sixbar.toml and crank_rocker.toml, taken in turn
    (benchmarks/scan.py --sixbar is the same comparison)."""
    from ..samples import sample_path
    from . import api

    vary = {"r2": (20.0, 60.0), "r3": (80.0, 160.0), "r4": (50.0, 120.0)}
    six, four = scan_keys(designs)
    runs = interleaved({
        key: (lambda f=f: api.scan_designs(str(sample_path(f)), vary, samples=designs,
                                               scheduler="synchronous"))
        for key, f in ((six, "watt_sixbar.toml"), (four, "crank_rocker.toml"))}, max(3, min(5, repeats)))
    return {k: t for k, (t, _, _) in runs.items()}


Target = tuple[str, str, "float | None", "bool | None"]


def ratio_of(a: float | None, b: float | None) -> float | None:
    """a / b, or None where either is missing, zero or NaN."""
    return a / b if a and b and a == a and b == b else None


def targets(sweeps: dict[str, float] | None = None) -> list[Target]:
    """(target, comparison, measured ratio, met; None where this run cannot judge it) for
    issue 19's sweeps and its scan (issue 10's against scipy is a row of :mod:`.targets`)."""
    sw = sweeps or {}
    rows = sweep_targets(sw)
    six, four = scan_keys(SCAN_DESIGNS)
    r = ratio_of(sw.get(six), sw.get(four))
    if r is None and any(k.startswith("linkage.scan") for k in sw):  # --quick: fewer designs
        six, four = scan_keys(SCAN_DESIGNS // 10)
        rows.append((f"issue 19: scan of {SCAN_DESIGNS // 10:,} Watt six-bar designs (the target: "
                     f"{SCAN_DESIGNS:,}) against the crank-rocker's", "six-bar / four-bar",
                     ratio_of(sw.get(six), sw.get(four)), None))
    else:
        rows.append((f"issue 19: scan of {SCAN_DESIGNS:,} Watt six-bar designs x 360 positions within 3x "
                     "of the crank-rocker's", "six-bar / four-bar", r, None if r is None else r <= 3.0))
    return rows


def sweep_targets(sw: dict[str, float]) -> list[Target]:
    """Issue 19's sweep targets from :func:`sweep_times`' medians: crank_rocker.toml at
    least 2x faster than pylinkage's step_fast, watt_sixbar.toml at least 5x faster than
    the one-at-a-time engine (n/a where this run could not time both)."""

    py = next((v for k, v in sw.items() if k.startswith("pylinkage")), None)
    r = ratio_of(py, sw.get("linkage.sweep 361 positions"))
    out: list[Target] = [
        ("3. linkage.sweep of crank_rocker.toml 0..360 step 1 at least 2x faster than pylinkage step_fast",
         "pylinkage / linkage", r, None if r is None else r >= 2.0)]
    r = ratio_of(sw.get(WATT_ONE), sw.get(WATT_CLOSED))
    out.append(("6. linkage.sweep of watt_sixbar.toml 0..360 step 1 at least 5x faster than the "
                "one-at-a-time sweep", "one-at-a-time / linkage", r, None if r is None else r >= 5.0))
    return out

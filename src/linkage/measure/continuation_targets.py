"""Issue 34's targets (docs/performance.md, "Issue 34's targets"): absolute times, not
ratios. Each row is the median of repeated runs against a bound in seconds on this machine,
whose core count is printed beside them, and what the runs found: every listed root's
relative residual (at most 1e-12), its duplicates and its spurious roots (none), checked at
50 digits (mpmath) from the double-precision roots the run returned.

The published figures the rows are judged against: Wampler, Morgan and Sommese, "Complete
solution of the nine-point path synthesis problem for four-bar linkages", J. Mech. Des.
114(1):153-159, 1992 (Problem 3: 1,442 four-bars up to Roberts cognates and the order of
the dyads); Hauenstein and Sottile, "alphaCertified", ACM TOMS 38(4), 2012 (64 of them
real, certified).

Problem 3 takes about half a minute and is ``long``: measured with ``linkage bench --full``
only, one run.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..records import frozen
from ..synthesis.path import PROBLEM_3

PUBLISHED_ORBITS = 1442
PUBLISHED_REAL = 64
FIVE_POSES = ((1.478, 2.018, 53.31), (0.7226, 2.672, 40.19), (-0.7101, 2.167, 41.29),
              (-1.278, 0.7609, 55.47), (-0.0114, -0.2412, 85.51))
"""docs/motion_synthesis.md's five poses (docs/motion_poses.txt): x, y (mm), angle (deg)."""
SIXBAR = "stephenson_sixbar.toml"

RESIDUAL = 1e-12
"""The issue's bound on every certified root's relative residual."""
DIGITS = 50
NEWTON_STEPS = 20
CONVERGED = 1e-25
"""A 50-digit Newton step below this, against max(1, |x|), has converged: from a root good
to double precision the second step is about the condition times 1e-32, so most roots are
confirmed in two steps (each costs about 20 ms at 50 digits: Problem 3 has 1,442 roots), and
a root of condition up to 1e13 (Problem 3's worst) still settles far below this."""
SAME_ROOT = 1e-8
"""An endpoint is confirmed when the root that 50-digit Newton converges to from it is
within this of it, against max(1, |x|)."""
DUPLICATE = 1e-6
"""Two listed roots this close, against max(1, |x|), are counted as one root listed twice
(looser than the engines' own test, 1e-8, so that a near miss shows)."""


@frozen
class Certificate:
    """The roots a run listed, checked at 50 digits: the worst relative residual and how
    many are above RESIDUAL, the worst distance to the 50-digit root (relative), roots
    listed twice, and endpoints that 50-digit Newton does not confirm (spurious)."""

    roots: int
    worst_residual: float
    worst_error: float
    duplicates: int
    spurious: int
    above: int = 0

    @property
    def met(self) -> bool:
        return self.worst_residual <= RESIDUAL and self.duplicates == 0 and self.spurious == 0


@frozen
class Found:
    """What a run found, said in a line; whether it is all the target asks; its roots checked."""

    summary: str
    complete: bool
    certificate: Certificate


@frozen
class Timed:
    """Seconds of each run, and what the last run found."""

    seconds: tuple[float, ...]
    found: Found

    @property
    def median(self) -> float:
        return float(np.median(self.seconds))


@frozen
class Row:
    """One target: met when the median run takes at most ``bound`` seconds and finds all
    the target asks (``Found.complete``)."""

    name: str
    bound: float
    long: bool = False

    def met(self, timed: Timed) -> bool:
        return timed.median <= self.bound and timed.found.complete


Measure = Callable[[int], Timed]
"""Runs a row ``repeats`` times (a long row once)."""


def refined(jet: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], roots: np.ndarray) -> list[Any]:
    """Newton's method at DIGITS digits from each row of ``roots``; ``jet`` gives F (N, m)
    and dF/dx (N, m, n) at object arrays of mpmath numbers. Each converged root rounded to
    complex, or None (a singular Jacobian, or no convergence in NEWTON_STEPS)."""
    import mpmath

    out: list[Any] = [None] * len(roots)
    with mpmath.workdps(DIGITS):
        X = np.array([[mpmath.mpc(complex(v)) for v in row] for row in roots], dtype=object)
        active = list(range(len(roots)))
        for _ in range(NEWTON_STEPS):
            if not active:
                break
            F, J = jet(X[active])
            still = []
            for k, i in enumerate(active):
                try:
                    step = mpmath.lu_solve(mpmath.matrix(J[k].tolist()), mpmath.matrix(F[k].tolist()))
                except ZeroDivisionError:
                    continue
                X[i] = X[i] - np.array([step[j] for j in range(X.shape[1])], dtype=object)
                size = max(mpmath.mpf(1), max(abs(v) for v in X[i]))
                if max(abs(step[j]) for j in range(X.shape[1])) <= CONVERGED * size:
                    out[i] = np.array([complex(v) for v in X[i]])
                else:
                    still.append(i)
            active = still
    return out


def duplicates(X: np.ndarray, owner: np.ndarray) -> int:
    """Roots listed twice: rows of ``X`` (members of each root's set: the root itself, or
    its orbit) of different owners within DUPLICATE of each other; the later owner of each
    such pair counts. Rows are compared in the order of a fixed projection (of norm 1), only
    those whose projections are within reach: a row that close to row i is within
    DUPLICATE max(|x_i|, |x_j|) <= 1.01 DUPLICATE |x_i| of it, so its projection is too."""
    if not len(X):
        return 0
    direction = np.cos(np.arange(1, X.shape[1] + 1)) + 1j * np.sin(np.arange(1, X.shape[1] + 1) ** 2)
    direction /= np.linalg.norm(direction)
    keys = (X @ direction).real
    order = np.argsort(keys)
    scale = np.maximum(1.0, np.linalg.norm(X, axis=1))
    doubled: set[int] = set()
    for pos, i in enumerate(order):
        for j in order[pos + 1:]:
            if keys[j] - keys[i] > 1.01 * DUPLICATE * scale[i]:
                break
            close = np.linalg.norm(X[i] - X[j]) <= DUPLICATE * max(scale[i], scale[j])
            if close and owner[i] != owner[j]:
                doubled.add(int(max(owner[i], owner[j])))
    return len(doubled)


def certify(roots: np.ndarray, residuals: Sequence[float], exact: Sequence[Any],
            members: tuple[np.ndarray, np.ndarray] | None = None) -> Certificate:
    """A run's roots, their residuals at 50 digits and their 50-digit refinements (None where
    Newton did not converge) as a :class:`Certificate`. ``members``: rows and their owners
    to look for duplicates in (default: the roots themselves)."""
    errors = [np.inf if e is None else float(np.linalg.norm(e - x)) / max(1.0, float(np.linalg.norm(x)))
              for x, e in zip(roots, exact)]
    rows, owner = members if members is not None else (roots, np.arange(len(roots)))
    return Certificate(len(roots), float(max(residuals, default=0.0)), float(max(errors, default=0.0)),
                       duplicates(rows, owner), sum(not e <= SAME_ROOT for e in errors),
                       sum(not r <= RESIDUAL for r in residuals))


def polynomial_jet(system: Any) -> Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]:
    """F and dF/dx of a PolySystem (:mod:`linkage.homotopy`) at object arrays of mpmath
    numbers, term by term from its coefficients."""
    import mpmath

    def jet(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        N, n, m = len(X), system.n, len(system.polynomials)
        F = np.empty((N, m), dtype=object)
        J = np.empty((N, m, n), dtype=object)
        for r, x in enumerate(X):
            for i, poly in enumerate(system.polynomials):
                F[r, i] = mpmath.fsum(mpmath.mpc(c) * mpmath.fprod(x[v] ** k for v, k in enumerate(e))
                                      for e, c in poly.items())
                for v in range(n):
                    J[r, i, v] = mpmath.fsum(mpmath.mpc(c) * e[v] * mpmath.fprod(
                        x[u] ** (k - (u == v)) for u, k in enumerate(e)) for e, c in poly.items() if e[v])
        return F, J

    return jet


def polynomial_certificate(system: Any, roots: list[np.ndarray]) -> Certificate:
    """The finite roots of a PolySystem checked at 50 digits: the residual as
    :func:`linkage.homotopy.solve.relative_residual` defines it (max |F_i(x)| over the
    equation's size at x), with F evaluated at 50 digits."""
    import mpmath

    from ..homotopy.solve import equation_sizes

    X = np.array(roots, dtype=complex).reshape(-1, system.n)
    jet = polynomial_jet(system)
    with mpmath.workdps(DIGITS):
        F, _ = jet(np.array([[mpmath.mpc(complex(v)) for v in x] for x in X], dtype=object).reshape(X.shape))
        residuals = [max(float(abs(f)) / s for f, s in zip(F[r], equation_sizes(system, X[r])))
                     for r in range(len(X))]
    return certify(X, residuals, refined(jet, X))


def nine_point_certificate(Z: np.ndarray, d: np.ndarray, db: np.ndarray) -> Certificate:
    """Four-bars through nine points, one per orbit (rows of ``Z``: a, x, b, y and their
    bars, :mod:`linkage.homotopy.ninepoint`; ``d``, ``db``: the points less the first, and
    their bars), checked at 50 digits on the nine-point equations: the residual as
    :func:`linkage.homotopy.ninepoint_alpha.residuals` defines it; a duplicate is two
    listed four-bars of one orbit (any of the six members)."""
    import mpmath

    from ..homotopy import ninepoint as npt
    from ..homotopy import ninepoint_alpha as npa

    Z = np.asarray(Z, dtype=complex).reshape(-1, 8)
    with mpmath.workdps(DIGITS):
        dd = np.array([mpmath.mpc(complex(v)) for v in d], dtype=object)
        ddb = np.array([mpmath.mpc(complex(v)) for v in db], dtype=object)

        def jet(X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            E, J, _, _ = npt.equations(X, dd, ddb)
            return E, J

    # the residual against the equations' terms multiplied out, as every polynomial
    # system's is measured (ninepoint_alpha.residuals says why not the factored form's)
    residuals = [float(r) for r in npa.residuals(npa.polynomial_system(d, db), Z, d, db)] if len(Z) else []
    with np.errstate(all="ignore"):
        orbits = [npt.orbit(z) for z in Z]
    members = np.concatenate(orbits) if orbits else np.zeros((0, 8), complex)
    owner = np.repeat(np.arange(len(Z)), [len(o) for o in orbits])
    keep = np.all(np.isfinite(members), axis=1)
    return certify(Z, residuals, refined(jet, Z), (members[keep], owner[keep]))


def runs(fn: Callable[[], Any], repeats: int, warm: bool = True) -> tuple[tuple[float, ...], Any]:
    """Seconds of ``repeats`` calls (after one untimed call when ``warm``), and the last result."""
    if warm:
        from .timing import interleaved

        _, times, last = interleaved({"run": fn}, repeats)["run"]
        return tuple(times), last
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        last = fn()
        times.append(time.perf_counter() - t0)
    return tuple(times), last


def problem_3(repeats: int) -> Timed:
    """``synthesize --path``'s engine on Problem 3 from the stored start instance, once (a
    run is half a minute; the first call loads the instance, as a command does)."""
    from ..homotopy.ninepoint_track import solve_points

    seconds, res = runs(lambda: solve_points([complex(x, y) for x, y in PROBLEM_3]), 1, warm=False)
    real = int(np.sum(res.real))
    summary = (f"{len(res.solutions)} of {PUBLISHED_ORBITS:,} four-bars, {real} of {PUBLISHED_REAL} real; "
               f"{res.paths} paths a route, {res.routes} route(s), failed {list(res.failed)}")
    complete = len(res.solutions) == PUBLISHED_ORBITS and real == PUBLISHED_REAL
    d = np.asarray(res.points[1:]) - res.points[0]
    return Timed(seconds, Found(summary, complete, nine_point_certificate(res.solutions, d, np.conj(d))))


def burmester(repeats: int) -> Timed:
    """Burmester's points of :data:`FIVE_POSES` (``synthesize --motion``'s engine): every
    path's endpoint, the real cranks kept."""
    from ..synthesis.burmester import burmester_points

    seconds, res = runs(lambda: burmester_points(FIVE_POSES), repeats)
    sols = res.solutions
    summary = (f"{len(res.cranks)} real cranks, {res.complex_count} complex, {res.infinite} at infinity, "
               f"{res.failed} failed of {sols.bound} paths")
    complete = res.failed == 0 and res.unresolved == 0 and res.singular == 0
    roots = [e.x for e in sols.endpoints if e.kind == "finite" and e.x is not None]
    return Timed(seconds, Found(summary, complete, polynomial_certificate(sols.system, roots)))


def sixbar_assemblies(repeats: int) -> Timed:
    """``linkage.assemblies`` of the Stephenson six-bar sample at its driver value (the file
    loaded once, outside the timing)."""
    from ..samples import sample_path
    from . import api

    m = api.load_mechanism(sample_path(SIXBAR))
    seconds, res = runs(lambda: api.assemblies(m), repeats)
    sols = res.solutions
    summary = (f"{len(res.real)} real, {res.complex_count} complex, {res.infinite} at infinity, "
               f"{res.failed} failed of {sols.bound} paths")
    complete = res.failed == 0 and res.unresolved == 0 and not res.continuum
    roots = [e.x for e in sols.endpoints if e.kind == "finite" and e.x is not None]
    return Timed(seconds, Found(summary, complete, polynomial_certificate(sols.system, roots)))


ROWS = (
    Row("Problem 3, nine points: all 1,442 four-bars and the 64 real, from the stored start instance",
        600.0, long=True),
    Row("five-pose Burmester: every solution of one problem", 0.1),
    Row("every assembly of a Stephenson six-bar (stephenson_sixbar.toml)", 0.05),
)
"""In the order of issue 34's targets."""
MEASURES: dict[Row, Measure] = dict(zip(ROWS, (problem_3, burmester, sixbar_assemblies)))


@frozen
class Outcome:
    row: Row
    timed: Timed | None
    note: str = ""
    """Why there is no run: not measured (long, without --full), or failed (and why)."""

    @property
    def met(self) -> bool | None:
        return None if self.timed is None else self.row.met(self.timed)

    @property
    def certified(self) -> bool | None:
        return None if self.timed is None else self.timed.found.certificate.met


def run_rows(full: bool, repeats: int, *, progress: Callable[[str], None] | None = None,
             measures: dict[Row, Measure] | None = None) -> list[Outcome]:
    """Every row, measured (the long ones only when ``full``)."""
    out = []
    for row, measure in (measures or MEASURES).items():
        if progress:
            progress(row.name)
        if row.long and not full:
            out.append(Outcome(row, None, "not measured (long: linkage bench --full)"))
            continue
        out.append(Outcome(row, measure(repeats)))
    return out


def cores_line() -> str:
    """The machine's cores, and those this process may run on."""
    import os

    from .targets import cores

    return f"{os.cpu_count() or 1} cores ({cores()} for this process)"


TIME_HEADERS = (("target", "", "text"), ("bound", "s", "number"), ("median", "s", "number"),
                ("runs", "", "int"), ("found", "", "text"), ("met", "", "bool"))
ROOT_HEADERS = (("target", "", "text"), ("roots", "", "int"), ("worst residual", "", "number"),
                ("above 1e-12", "", "int"), ("worst error", "", "number"), ("duplicates", "", "int"),
                ("spurious", "", "int"), ("met", "", "bool"))
"""The two tables: the times against their bounds, and the roots checked at 50 digits
(residual relative, bound 1e-12; error: distance to the 50-digit root, relative)."""


def tables(outcomes: Sequence[Outcome]) -> tuple[list[tuple[Any, ...]], list[tuple[Any, ...]]]:
    """The rows of the two tables (None where a row was not measured; its note says why)."""
    times, roots = [], []
    for o in outcomes:
        if o.timed is None:
            times.append((o.row.name, o.row.bound, None, 0, o.note, None))
            continue
        c = o.timed.found.certificate
        times.append((o.row.name, o.row.bound, o.timed.median, len(o.timed.seconds), o.timed.found.summary,
                      o.met))
        roots.append((o.row.name, c.roots, c.worst_residual, c.above, c.worst_error, c.duplicates,
                      c.spurious, c.met))
    return times, roots


CONTINUATION_TABLES = ("continuation", "certified")


def with_continuation(report: Any, outcomes: Sequence[Outcome]) -> Any:
    """``linkage bench``'s report with issue 34's two tables after its own."""
    from ..render.data import Report, from_rows
    from ..render.report import Text, table

    times, roots = tables(outcomes)
    cores = cores_line()
    title = f"Issue 34's targets (seconds on this machine, {cores}; median of the runs)"

    def verdict(ok: bool | None) -> str:
        return "n/a" if ok is None else ("yes" if ok else "no")

    def blocks() -> list[Any]:
        shown = [(*r[:-1], verdict(r[-1])) for r in times]
        checked = [(*r[:-1], verdict(r[-1])) for r in roots]
        return [*report.blocks(), Text(""),
                table(title, [f"{n} ({u})" if u else n for n, u, _ in TIME_HEADERS], shown, 3),
                table("Their roots at 50 digits (residual: relative, at most 1e-12; error: from the "
                      "50-digit root, relative; spurious: not confirmed by 50-digit Newton)",
                      [n for n, _, _ in ROOT_HEADERS], checked, 3)]

    def document() -> dict[str, Any]:
        doc = dict(report.document()) if report.document else {}
        doc["continuation"] = {"cores": cores, "targets": [dict(zip([n for n, _, _ in TIME_HEADERS], r))
                                                           for r in times],
                               "certified": [dict(zip([n for n, _, _ in ROOT_HEADERS], r)) for r in roots]}
        return doc

    extra = (from_rows("continuation", TIME_HEADERS, times), from_rows("certified", ROOT_HEADERS, roots))
    return Report(report.title, (*report.tables, *extra), blocks, document)

"""The search: many candidate angle ranges synthesised and judged at once by the numpy
twins of the one-design rules, in chunks on the scan's runner (docs/synthesis.md,
"Search")."""

from __future__ import annotations

import functools
from collections.abc import Callable, Sequence
from typing import Any

from ..errors import InputError
from ..records import frozen
from .defects import turns_np
from .request import GRID, MIN_TRANSMISSION_DEG, Request, make_request, parse_range, value_of
from .solve import (
    assembly_gap_np,
    linkage_of_np,
    off_branch_np,
    precision_xs,
    real_coefficients,
    solve_coefficients,
    solve_coefficients_np,
    transmission_deg_np,
)

SEARCH_NAMES = ("alpha0", "alpha_span", "phi0", "phi_span")
"""The free choices a search varies (deg): each angle range's start and span."""
SEARCH_CHUNK = 200
"""Candidates per task: each holds a few arrays of GRID values per candidate."""


@frozen
class SearchJob:
    """What a search task needs (picklable: the function travels as its text)."""

    text: str
    x_range: tuple[float, float]
    alpha_range: tuple[float, float]
    phi_range: tuple[float, float]
    names: tuple[str, ...]
    points: int
    spacing: str
    at: tuple[float, ...] | None
    ground: float
    min_transmission: float


@functools.lru_cache(maxsize=8)
def search_request(job: SearchJob) -> Request:
    """The job's request, checked once per job (every chunk of a search shares it)."""
    return make_request(
        job.text,
        job.x_range,
        job.alpha_range,
        job.phi_range,
        points=job.points,
        spacing=job.spacing,
        at=job.at,
        ground=job.ground,
        min_transmission=job.min_transmission,
    )


@functools.lru_cache(maxsize=8)
def grid_of(req: Request, grid: int) -> tuple[Any, Any, Any]:
    """The dense grid's x, and its t and u (x and y mapped onto 0..1), once per request: f
    is evaluated in Python, which holds the GIL, so not in every chunk."""
    import numpy as np

    lo, hi = req.x_range
    y0, y1 = req.y_ends
    gx = np.linspace(lo, hi, grid)
    gy = np.array([value_of(req.f, x) for x in gx])
    return gx, (gx - lo) / (hi - lo), (gy - y0) / (y1 - y0)


@frozen
class Candidates:
    """Candidates' linkages as columns (one row each): the precision points' angles, R,
    the real lengths (NaN: no linkage), the turned links' shifts (deg) and the branch sign
    through point 1."""

    alphas: Any
    phis: Any
    r: Any
    lengths: tuple[Any, Any, Any, Any]
    real: Any
    shift_a: Any
    shift_p: Any
    sign: Any

    @property
    def ok(self) -> Any:
        """Whether each candidate has a real linkage."""
        import numpy as np

        return np.isfinite(self.lengths[0])


def candidate_linkages(req: Request, a0: Any, da: Any, p0: Any, dp: Any) -> Candidates:
    """The numpy twins of :func:`.function.precision_points` and :func:`.error_curve.design_of`."""
    import numpy as np

    from ..problems.freudenstein import branch_sign_np

    lo, hi = req.x_range
    y0, y1 = req.y_ends
    xs = np.array(precision_xs(req))
    ys = np.array([value_of(req.f, x) for x in xs])
    t, u = (xs - lo) / (hi - lo), (ys - y0) / (y1 - y0)
    alphas = a0[:, None] + t[None, :] * da[:, None]
    phis = p0[:, None] + u[None, :] * dp[:, None]
    if len(xs) == 3:
        r = solve_coefficients_np(alphas, phis)
    else:
        r = np.array([solve_coefficients(list(al), list(ph))[0] for al, ph in zip(alphas, phis)])
    a, b, c, d, turned_in, turned_out = linkage_of_np(r, req.ground)
    real = np.stack(real_coefficients(a, b, c, d), axis=-1)
    shift_a, shift_p = np.where(turned_in, 180.0, 0.0), np.where(turned_out, 180.0, 0.0)
    sign = branch_sign_np(alphas[:, 0] + shift_a, phis[:, 0] + shift_p, real[:, 0], real[:, 1], real[:, 2])
    return Candidates(alphas, phis, r, (a, b, c, d), real, shift_a, shift_p, sign)


def peak_errors(err: Any, gx: Any, step: float) -> tuple[Any, Any]:
    """Each row's largest |error| on the grid, refined by a parabola through the grid
    neighbours of an interior maximum, and its x (``step``: the grid's)."""
    import numpy as np

    grid = gx.shape[0]
    mag = np.where(np.isfinite(err), np.abs(err), -1.0)
    k = np.argmax(mag, axis=-1)
    rows = np.arange(err.shape[0])
    best = mag[rows, k]
    inner = (k > 0) & (k < grid - 1)
    km, kp = np.clip(k - 1, 0, grid - 1), np.clip(k + 1, 0, grid - 1)
    fm, f0, fp = mag[rows, km], best, mag[rows, kp]
    curv = fm - 2.0 * f0 + fp
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.where(inner & (curv < 0.0), 0.5 * (fm - fp) / curv, 0.0)
    offset = np.clip(offset, -0.5, 0.5)
    return f0 - 0.25 * (fm - fp) * offset, gx[k] + offset * step


def evaluate_candidates(req: Request, a0: Any, da: Any, p0: Any, dp: Any, grid: int = GRID, *,
                        judge_all: bool = True) -> dict[str, Any]:
    """Every candidate (alpha range A0..A0+dA, phi range P0..P0+dP) synthesised and judged
    at once: the numpy twins of :func:`.function.synthesize_at`'s rules on the dense grid
    (the closed form on the branch through point 1, no continuation), with the largest
    error refined by a parabola through its grid neighbours. Columns, one entry per
    candidate. Every step is a numpy kernel on whole rows, which releases the GIL: the
    chunks of a search run side by side on threads. Without ``judge_all`` only the rows
    with no defect found from the precision points and the assembly rule (no_linkage,
    branch, grashof's assembly_gap) go on to the dense grid, so their other columns (the
    max error, order, transmission) are NaN or unjudged: a search keeps only defect-free
    rows."""
    import numpy as np

    a0, da, p0, dp = (np.asarray(v, float) for v in (a0, da, p0, dp))
    cand = candidate_linkages(req, a0, da, p0, dp)
    a, b, c, d = cand.lengths
    real, shift_a, shift_p = cand.real, cand.shift_a, cand.shift_p
    linkage_ok = cand.ok
    gap = assembly_gap_np(real[:, 0], real[:, 1], real[:, 2], a0 + shift_a, a0 + da + shift_a)
    # branch: a precision point on the other assembly (the one rule, off_branch)
    branch = linkage_ok & np.any(
        off_branch_np(cand.alphas + shift_a[:, None], cand.phis + shift_p[:, None],
                      real[:, 0:1], real[:, 1:2], real[:, 2:3], cand.sign[:, None]),
        axis=-1,
    )
    # the dense grid, most of the work: on every row, or (a search, which keeps only
    # defect-free rows) on the rows still without a defect
    rows = np.arange(len(a0)) if judge_all else np.flatnonzero(linkage_ok & ~gap & ~branch)
    finite, peak, at_x, min_mu, order = judge_on_grid(req, cand, (a0, da, p0, dp), rows, grid)
    assembles = linkage_ok & finite & ~gap
    max_err = np.where(assembles, peak, np.nan)
    order &= assembles
    with np.errstate(invalid="ignore"):
        low_mu = linkage_ok & (min_mu < req.min_transmission)
    defects = defect_column(
        [("no_linkage", ~linkage_ok), ("branch", branch), ("grashof", linkage_ok & ~assembles),
         ("order", order), ("transmission", low_mu)]
    )
    return {
        "R1": cand.r[:, 0], "R2": cand.r[:, 1], "R3": cand.r[:, 2],
        "input": a, "coupler": b, "output": c, "ground": np.where(linkage_ok, d, np.nan),
        "grashof": grashof_column(cand),
        "max_error_deg": max_err,
        "at_x": np.where(assembles, at_x, np.nan),
        "max_error_y": max_err * abs(req.y_per_deg),
        "min_transmission_deg": min_mu,
        "defects": defects,
        "ok": defects == "",
    }


def judge_on_grid(req: Request, cand: Candidates, ranges: tuple[Any, Any, Any, Any], rows: Any,
                  grid: int) -> tuple[Any, Any, Any, Any, Any]:
    """The candidates ``rows`` on the dense grid (the branch's closed form through point 1):
    whether the output is found everywhere, the largest |error| (:func:`peak_errors`) and
    its x, the least transmission angle (folded, deg) and whether the output turns back
    where the function does not. Columns for every candidate: NaN or False off ``rows``."""
    import numpy as np

    from ..problems.freudenstein import branch_root_np

    n = len(ranges[0])
    a0, da, p0, dp = (v[rows] for v in ranges)
    real, shift_a, shift_p, sign = cand.real[rows], cand.shift_a[rows], cand.shift_p[rows], cand.sign[rows]
    a, _, c, d = (v[rows] for v in cand.lengths)
    gx, gt, gu = grid_of(req, grid)
    al_g = a0[:, None] + gt[None, :] * da[:, None] + shift_a[:, None]
    phi_g = branch_root_np(al_g, real[:, 0:1], real[:, 1:2], real[:, 2:3], sign[:, None]) - shift_p[:, None]
    want = p0[:, None] + gu[None, :] * dp[:, None]
    err = np.remainder(phi_g - want + 180.0, 360.0) - 180.0
    lo, hi = req.x_range
    peak, at_x = peak_errors(err, gx, (hi - lo) / (grid - 1))
    fold = transmission_deg_np(a[:, None], c[:, None], d[:, None], al_g, phi_g + shift_p[:, None])
    lowest = np.min(np.where(np.isfinite(fold), fold, np.inf), axis=-1)
    with np.errstate(invalid="ignore"):
        # the generated output unwrapped as the scalar rule reads it: desired + error
        gen = want + np.where(np.isfinite(err), err, 0.0)
        turned = turns_np(gen) > turns_np(want)
    finite, order = np.zeros(n, bool), np.zeros(n, bool)
    full_peak, full_at, min_mu = np.full(n, np.nan), np.full(n, np.nan), np.full(n, np.nan)
    finite[rows] = np.all(np.isfinite(err), axis=-1)
    full_peak[rows], full_at[rows], order[rows] = peak, at_x, turned
    min_mu[rows] = np.where(cand.ok[rows] & np.isfinite(lowest), lowest, np.nan)
    return finite, full_peak, full_at, min_mu, order


def grashof_column(cand: Candidates) -> Any:
    """Each candidate's Grashof class (closed_form.grashof_np); "" without a linkage."""
    import numpy as np

    from ..problems.closed_form import grashof_np

    ok = cand.ok
    a, b, c, d = (np.where(ok, v, 1.0) for v in cand.lengths)
    return np.where(ok, grashof_np(d, a, b, c), "").astype(object)


def defect_column(names: Sequence[tuple[str, Any]]) -> Any:
    """The defects' names of each row, space-separated ("" for none), from a mask per name."""
    import numpy as np

    n = len(names[0][1])
    return np.array([" ".join(name for name, m in names if m[i]) for i in range(n)], dtype=object)


def search_chunk(job: SearchJob, start: int, designs: Any) -> dict[str, Any]:
    """One task of a search: the candidates ``start, start + 1, ...`` as columns."""
    import numpy as np

    req = search_request(job)
    given = {
        "alpha0": job.alpha_range[0],
        "alpha_span": job.alpha_range[1] - job.alpha_range[0],
        "phi0": job.phi_range[0],
        "phi_span": job.phi_range[1] - job.phi_range[0],
    }
    n = designs.shape[0]
    cols = {
        name: (designs[:, job.names.index(name)] if name in job.names else np.full(n, given[name]))
        for name in SEARCH_NAMES
    }
    out = {"design": np.arange(start, start + n)}
    out.update(cols)
    out.update(evaluate_candidates(req, cols["alpha0"], cols["alpha_span"], cols["phi0"], cols["phi_span"],
                                   judge_all=False))
    return out


def check_varies(varies: Sequence[Any]) -> None:
    """Each --vary of a search: a search name, once, a span on one side of 0 and within a turn."""
    seen: set[str] = set()
    for v in varies:
        if v.name not in SEARCH_NAMES:
            raise InputError(f"--vary {v.name}: a search varies {', '.join(SEARCH_NAMES)} (degrees)")
        if v.name in seen:
            raise InputError(f"--vary {v.name} is given twice")
        seen.add(v.name)
        if v.name.endswith("_span") and (v.lo <= 0.0 <= v.hi or max(abs(v.lo), abs(v.hi)) >= 360.0):
            raise InputError(
                f"--vary {v.name}={v.lo:g}:{v.hi:g}: a span must stay on one side of 0 and within +-360 deg"
            )
        if max(abs(v.lo), abs(v.hi)) > 1e6:
            raise InputError(f"--vary {v.name}: bounds beyond 1e6 deg are not supported")


@frozen
class SearchResult:
    rows: dict[str, Any]
    """The kept candidates (no defects), best first: columns."""
    scanned: int
    without_defects: int
    job: SearchJob


def search(
    f: str,
    x_range: Any,
    alpha_range: Any,
    phi_range: Any,
    vary: Sequence[str],
    *,
    points: int = 3,
    spacing: str = "chebyshev",
    at: Sequence[float] | str | None = None,
    ground: float = 1.0,
    min_transmission: float = MIN_TRANSMISSION_DEG,
    samples: int | None = None,
    seed: int = 0,
    sampling: str = "lhs",
    top: int = 10,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[int], None] | None = None,
) -> SearchResult:
    """Synthesise every candidate of a grid (or ``samples`` random draws) over the free
    choices (``vary``: alpha0, alpha_span, phi0, phi_span as NAME=LO:HI[:N], degrees),
    keep those without defects, best (smallest max structural error) first: on the scan's
    chunked runner, so ``scheduler`` may be a dask cluster's address. ``alpha_range`` and
    ``phi_range`` give what is not varied (None where both of its names are)."""
    from ..scan import MAX_DESIGNS, DesignPlan, Keeper, concat, parse_vary, run_chunks, take

    if not isinstance(f, str):
        raise InputError("a search takes the function as text (it travels to the workers)")
    if spacing == "optimal":
        raise InputError(
            "--search keeps the spacing fixed (chebyshev, uniform or --at): optimal "
            "spacing is for one design; run it on the best candidate"
        )
    varies = [parse_vary(v) for v in vary]
    if not varies:
        raise InputError(
            "--search: give at least one --vary NAME=LO:HI[:N] (alpha0, alpha_span, phi0, phi_span)"
        )
    check_varies(varies)
    if isinstance(top, bool) or not isinstance(top, int) or not 1 <= top <= 100_000:
        raise InputError(f"--top must be a whole number from 1 to 100000, got {top!r}")

    def base(name: str, given: Any) -> tuple[float, float]:
        if given is not None:
            return parse_range(f"--{name}", given)
        start = next((v for v in varies if v.name == f"{name}0"), None)
        span = next((v for v in varies if v.name == f"{name}_span"), None)
        if start is None or span is None:
            raise InputError(f"--{name}: give the range, or vary both {name}0 and {name}_span")
        return start.lo, start.lo + span.lo

    ar, pr = base("alpha", alpha_range), base("phi", phi_range)
    req = make_request(
        f,
        x_range,
        ar,
        pr,
        points=points,
        spacing=spacing,
        at=at,
        ground=ground,
        min_transmission=min_transmission,
    )
    plan = DesignPlan(varies, samples, seed, sampling)
    if plan.total > MAX_DESIGNS:
        raise InputError(f"{plan.total:,} candidates: at most {MAX_DESIGNS:,}")
    job = SearchJob(
        req.text,
        req.x_range,
        req.alpha_range,
        req.phi_range,
        plan.names,
        req.points,
        req.spacing,
        req.at,
        req.ground,
        req.min_transmission,
    )
    keeper = Keeper("max_error_deg", False, top, None)
    scanned = good = 0
    for cols in run_chunks(job, plan, SEARCH_CHUNK, scheduler=scheduler, workers=workers, task=search_chunk):
        scanned += len(cols["design"])
        import numpy as np

        ok = np.flatnonzero(cols["ok"])
        good += len(ok)
        if len(ok):
            keeper.add(take(cols, ok))
        if progress is not None:
            progress(scanned)
    rows = keeper.result() or concat([])
    return SearchResult(rows, scanned, good, job)

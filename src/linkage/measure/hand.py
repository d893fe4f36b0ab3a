"""The baselines ``linkage bench`` compares the library with: each the same work written
plainly by hand, with no checks, the floor any library pays over. They are the reference
of the speed figures (README, "Performance"), so they use nothing of the engines they are
compared with; tests/test_bench.py holds each to the library's answer."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

from ..records import frozen
from ..units import degrees


def hand_newton(f: Callable[[float], float], fp: Callable[[float], float], x: float, tol: float) -> float:
    """The floor: Newton in ten lines of plain Python."""
    for _ in range(100):
        step = f(x) / fp(x)
        x -= step
        if abs(step) <= tol:
            return x
    return x


def hand_newton_2x2(
    F: Callable[..., list[float]], J: Callable[..., list[list[float]]], q: Sequence[float], tol: float
) -> tuple[float, float]:
    """The floor for a four-bar: Newton with Cramer's rule, no checks."""
    a, b = q
    for _ in range(50):
        f1, f2 = F((a, b))
        (j11, j12), (j21, j22) = J((a, b))
        det = j11 * j22 - j12 * j21
        da = (-f1 * j22 + f2 * j12) / det
        db = (-f2 * j11 + f1 * j21) / det
        a, b = a + da, b + db
        if abs(da) <= tol and abs(db) <= tol:
            break
    return a, b


def fourbar_open(theta2: Any, r1: float, r2: float, r3: float, r4: float) -> tuple[Any, Any]:
    """theta3, theta4 (deg) of a four-bar (ground r1 along x from O2 to O4, crank r2,
    coupler r3, rocker r4) at every crank angle ``theta2`` (rad, a numpy array): the
    intersection of the circle of radius r3 about the crank pin A with the circle of radius
    r4 about O4, on the side where sin(theta4 - theta3) > 0 for a crank-rocker drawn as
    sample_inputs/crank_rocker.toml is (Norton, *Design of Machinery*, section 4.5: the open
    configuration). Written tight: in place where numpy allows, one temporary at a time."""
    t3, t4, _, _ = fourbar_open_radians(theta2, r1, r2, r3, r4)
    return degrees(t3), degrees(t4)


def fourbar_open_radians(theta2: Any, r1: float, r2: float, r3: float, r4: float,
                         margin_floor: float | None = None) -> tuple[Any, Any, Any, Any]:
    """:func:`fourbar_open`'s work: theta3, theta4 (rad) and the crank pin A's x and y. With
    ``margin_floor``, raises ValueError where a position's margin, (h / d)^2, is not above it."""
    import numpy as np

    ax = np.cos(theta2)
    ax *= r2
    ay = np.sin(theta2)
    ay *= r2
    dx = ax - r1  # O4 -> A
    d2 = dx * dx
    d2 += ay * ay
    a = d2 + (r4 * r4 - r3 * r3)  # 2 d times the distance from O4 to the chord, along O4 -> A
    a /= 2.0 * d2
    h = np.square(a)  # (h / d)^2 = (r4 / d)^2 - (a / d)^2
    np.subtract(r4 * r4 / d2, h, out=h)
    if margin_floor is not None and np.count_nonzero(h > margin_floor) != h.size:
        raise ValueError("a position near a limit")
    np.sqrt(h, out=h)
    bx = a * dx
    bx += h * ay  # B - O4 = a (A - O4) - h perp(A - O4), the open side
    by = a * ay
    by -= h * dx
    t4 = np.arctan2(by, bx)
    bx += r1 - ax
    by -= ay
    return np.arctan2(by, bx), t4, ax, ay


def fourbar_open_certified(theta2_deg: Sequence[float], r1: float, r2: float, r3: float, r4: float,
                           tol: float, gate: float, margin_floor: float) -> tuple[Any, Any, Any, Any]:
    """The floor of a sweep that keeps the single solve's promise, by hand: theta3, theta4
    (deg), det J and whether each position is certified, for crank angles ``theta2_deg``
    (deg, a list, as ``linkage.sweep`` takes them). The least such a sweep computes: the
    values as an array, checked strictly ascending; :func:`fourbar_open`'s closed form; each
    position's assembly margin, (h / d)^2, above ``margin_floor``; the evidence that each
    answer is a root (Phi and J at the reported angles, the Newton step they imply, the step
    within ``tol`` and max|Phi| within ``gate``); det J of one sign. No unwrapping,
    anchoring, branch names or result object. Raises ValueError where a check fails."""
    import numpy as np

    from ..units import radians

    d = np.asarray(theta2_deg, dtype=float)
    if np.count_nonzero(np.diff(d) > 0.0) != d.size - 1:
        raise ValueError("driver values not strictly ascending")
    t3, t4, ax, ay = fourbar_open_radians(radians(d), r1, r2, r3, r4, margin_floor)
    c3, s3, c4, s4 = np.cos(t3), np.sin(t3), np.cos(t4), np.sin(t4)
    px = ax + r3 * c3  # Phi at the reported angles
    px -= r4 * c4
    px -= r1
    py = ay + r3 * s3
    py -= r4 * s4
    j11, j12, j21, j22 = -r3 * s3, r4 * s4, r3 * c3, -r4 * c4
    det = j11 * j22
    det -= j12 * j21
    step = np.maximum(np.abs((j22 * px - j12 * py) / det), np.abs((j11 * py - j21 * px) / det))
    certified = (step <= tol) & (np.maximum(np.abs(px), np.abs(py)) <= gate)
    if not (np.count_nonzero(det > 0.0) == det.size or np.count_nonzero(det < 0.0) == det.size):
        raise ValueError("det J changes sign")
    return degrees(t3), degrees(t4), det, certified


CRANK_ROCKER_POINT = (60.0, 30.0)
"""sample_inputs/crank_rocker.toml's coupler point P: 60 mm from A, at theta3 + 30 deg."""


def sweep_file_columns(theta2_deg: Any, theta3_deg: Any, theta4_deg: Any, r1: float, r2: float, r3: float,
                       r4: float, point: tuple[float, float] = CRANK_ROCKER_POINT) -> dict[str, Any]:
    """The columns of a four-bar sweep's file that vary from row to row, by hand from its
    angles (deg, numpy arrays): theta2, theta3, theta4 (deg), det J (mm^2/rad^2), the
    transmission angle folded into 0..90 (deg), and x, y (mm) of the crank pin A, the
    coupler-rocker pin B and the coupler point ``point`` (its distance from A and its angle
    from the coupler, deg), each as vector loops place them (Norton, *Design of Machinery*,
    sections 4.5 and 4.8)."""
    import numpy as np

    from ..units import radians

    t2, t3 = radians(theta2_deg), radians(theta3_deg)
    ax, ay = r2 * np.cos(t2), r2 * np.sin(t2)
    bx, by = ax + r3 * np.cos(t3), ay + r3 * np.sin(t3)
    t3 += radians(point[1])
    px, py = ax + point[0] * np.cos(t3), ay + point[0] * np.sin(t3)
    mu = np.abs(theta4_deg - theta3_deg) % 180.0
    return {"theta2": theta2_deg, "theta3": theta3_deg, "theta4": theta4_deg,
            "det": r3 * r4 * np.sin(radians(theta3_deg - theta4_deg)),
            "transmission": np.minimum(mu, 180.0 - mu),
            "A.x": ax, "A.y": ay, "B.x": bx, "B.y": by, "P.x": px, "P.y": py}


def write_sweep_file(theta2_deg: Any, theta3_deg: Any, theta4_deg: Any,
                     links: tuple[float, float, float, float], path: str, suffix: str,
                     rows_per_slice: int = 32_768) -> None:
    """A four-bar sweep's file by hand, from its angles (deg, numpy arrays) and links r1..r4:
    :func:`sweep_file_columns` of each slice of ``rows_per_slice`` rows, on a thread per
    core (numpy's cos and sin, and pyarrow, release the GIL), each slice's columns made a
    pyarrow record batch; then CSV text by pyarrow's CSV writer, formatted on the same
    threads and written in order, or Parquet in one ``pyarrow.parquet.write_table`` of the
    batches, without dictionaries (which doubles that vary from row to row never use:
    pyarrow tries one per column first). Less than the command line's file (no status,
    branch, iteration or constant ground-pivot columns, no header, written in place: no
    temporary file, rename or fsync), with the writers the package has."""
    import os
    from concurrent.futures import ThreadPoolExecutor

    import pyarrow as pa

    csv = suffix != "parquet"
    if csv:
        import pyarrow.csv as pcsv

    def block(a: int) -> Any:
        z = slice(a, a + rows_per_slice)
        cols = sweep_file_columns(theta2_deg[z], theta3_deg[z], theta4_deg[z], *links)
        batch = pa.RecordBatch.from_arrays([pa.array(v) for v in cols.values()], names=list(cols))
        if not csv:
            return batch
        out = pa.BufferOutputStream()
        pcsv.write_csv(batch, out, pcsv.WriteOptions(include_header=False, quoting_style="none"))
        return out.getvalue()

    with ThreadPoolExecutor(os.cpu_count() or 1) as pool:
        blocks = pool.map(block, range(0, len(theta2_deg), rows_per_slice))
        if csv:
            with open(path, "wb") as f:
                for text in blocks:
                    f.write(text)
            return
        import pyarrow.parquet as pq

        pq.write_table(pa.Table.from_batches(list(blocks)), path, use_dictionary=False)


@frozen
class DrawnFourbar:
    """A crank-rocker as sample_inputs/crank_rocker_joints.toml draws it (mm): O2 at the
    origin, O4 on the x axis, the crank pin A, the coupler-rocker pin B, a coupler point P,
    all at the drawn crank angle."""

    a: tuple[float, float]
    b: tuple[float, float]
    o4x: float
    p: tuple[float, float]


def loaded_scan(drawn: DrawnFourbar, o4x: Any, force_p: tuple[float, float], rocker_torque: float,
                theta2_deg: Any) -> dict[str, Any]:
    """The static forces of a four-bar scan, by hand: for each design (O4 moved along x to
    ``o4x``, the moving links as drawn) at each crank angle, the open
    configuration by :func:`fourbar_open`, then the nine equilibrium equations of the three
    moving links (two forces and a moment each; Norton, *Design of Machinery*, section
    11.6) solved as a batch of 9x9 systems for the ground's forces at O2 and O4, the pin
    forces at A and B and the input torque. ``force_p`` (N) acts at P on the coupler,
    ``rocker_torque`` (N m) on the rocker. Per design: the largest |input torque| (N m),
    pin force and ground force (N) over the positions."""
    import numpy as np

    from ..units import radians

    ax, ay = drawn.a
    bx, by = drawn.b
    r2, r3, r4 = math.hypot(ax, ay), math.hypot(bx - ax, by - ay), math.hypot(bx - drawn.o4x, by)
    off = math.atan2(drawn.p[1] - ay, drawn.p[0] - ax) - math.atan2(by - ay, bx - ax)
    rp = math.hypot(drawn.p[0] - ax, drawn.p[1] - ay)
    r1 = np.asarray(o4x, float)[:, None]
    t2 = radians(np.asarray(theta2_deg, float))[None, :]
    t3, t4 = (radians(t) for t in fourbar_open(t2, r1, r2, r3, r4))
    shape = np.broadcast_shapes(t2.shape, r1.shape)
    n = int(np.prod(shape))
    pa = (np.broadcast_to(r2 * np.cos(t2), shape).reshape(n),
          np.broadcast_to(r2 * np.sin(t2), shape).reshape(n))
    ab = (r3 * np.cos(t3)).reshape(n), (r3 * np.sin(t3)).reshape(n)
    ap = (rp * np.cos(t3 + off)).reshape(n), (rp * np.sin(t3 + off)).reshape(n)
    o4b = (r4 * np.cos(t4)).reshape(n), (r4 * np.sin(t4)).reshape(n)
    # unknowns: ground on crank at O2 (x, y), crank on coupler at A, coupler on rocker at B,
    # ground on rocker at O4, the input torque; moments in N mm
    m = np.zeros((n, 9, 9))
    rhs = np.zeros((n, 9))
    m[:, 0, 0] = m[:, 1, 1] = 1.0  # crank: G2 - FA = 0
    m[:, 0, 2] = m[:, 1, 3] = -1.0
    m[:, 2, 2], m[:, 2, 3], m[:, 2, 8] = pa[1], -pa[0], 1.0  # about O2: T - A x FA = 0
    m[:, 3, 2] = m[:, 4, 3] = 1.0  # coupler: FA - FB + F_P = 0
    m[:, 3, 4] = m[:, 4, 5] = -1.0
    rhs[:, 3], rhs[:, 4] = -force_p[0], -force_p[1]
    m[:, 5, 4], m[:, 5, 5] = ab[1], -ab[0]  # about A: -(B - A) x FB + (P - A) x F_P = 0
    rhs[:, 5] = -(ap[0] * force_p[1] - ap[1] * force_p[0])
    m[:, 6, 4] = m[:, 7, 5] = m[:, 6, 6] = m[:, 7, 7] = 1.0  # rocker: FB + G4 = 0
    m[:, 8, 4], m[:, 8, 5] = -o4b[1], o4b[0]  # about O4: (B - O4) x FB + T_rocker = 0
    rhs[:, 8] = -rocker_torque * 1000.0
    f = np.linalg.solve(m, rhs[..., None])[..., 0]
    pins = np.max([np.hypot(f[:, k], f[:, k + 1]) for k in (0, 2, 4, 6)], axis=0).reshape(shape)
    ground = np.hypot(f[:, 0] + f[:, 6], f[:, 1] + f[:, 7]).reshape(shape)
    torque = np.abs(f[:, 8]).reshape(shape) / 1000.0
    return {"peak_input": torque.max(axis=1), "max_pin_force": pins.max(axis=1),
            "max_shaking_force": ground.max(axis=1)}


def function_search(xs: Sequence[float], ys: Sequence[float], grid_x: Any, grid_y: Any,
                    candidates: Any, min_transmission: float, chunk: int = 500) -> dict[str, Any]:
    """A Freudenstein function-generator search by hand, in one thread: for each candidate
    (alpha0, alpha_span, phi0, phi_span; deg) the three precision points' angles (``xs``,
    ``ys`` the function there), the 3x3 system R1 cos(a) - R2 cos(p) + R3 = cos(a - p) solved
    for R (Norton, *Design of Machinery*, section 5.12), the output phi on the branch through
    the first point at every x of ``grid_x`` (closed form), its largest error from the
    desired phi (refined by a parabola through the grid neighbours) and the smallest
    transmission angle (links from R for a ground of 1). Per candidate: max_error_deg and
    min_transmission_deg, and ok where it assembles everywhere and the transmission is at
    least ``min_transmission``."""
    import numpy as np

    from ..units import degrees, radians

    x0, x1, y0, y1 = grid_x[0], grid_x[-1], grid_y[0], grid_y[-1]
    t, u = (np.asarray(xs) - x0) / (x1 - x0), (np.asarray(ys) - y0) / (y1 - y0)
    gt, gu = (grid_x - x0) / (x1 - x0), (grid_y - y0) / (y1 - y0)
    out: dict[str, list[Any]] = {"max_error_deg": [], "min_transmission_deg": [], "ok": []}
    for start in range(0, len(candidates), chunk):
        a0, da, p0, dp = (c[:, None] for c in np.asarray(candidates[start:start + chunk]).T)
        a, p = radians(a0 + t * da), radians(p0 + u * dp)
        mat = np.stack([np.cos(a), -np.cos(p), np.ones_like(a)], axis=-1)
        r1, r2, r3 = (v[:, None] for v in np.linalg.solve(mat, np.cos(a - p)[..., None])[..., 0].T)
        ga = radians(a0 + gt * da)
        base = np.arctan2(np.sin(ga), r2 + np.cos(ga))
        first = np.arctan2(np.sin(a[:, :1]), r2 + np.cos(a[:, :1]))
        sign = np.where(np.remainder(p[:, :1] - first + np.pi, 2 * np.pi) - np.pi >= 0.0, 1.0, -1.0)
        with np.errstate(invalid="ignore"):
            phi = base + sign * np.arccos((r1 * np.cos(ga) + r3) / np.hypot(r2 + np.cos(ga), np.sin(ga)))
        err = np.abs(np.remainder(degrees(phi) - (p0 + gu * dp) + 180.0, 360.0) - 180.0)
        k = np.argmax(np.where(np.isnan(err), -1.0, err), axis=1)
        rows = np.arange(len(k))
        fm, f0, fp = (err[rows, np.clip(k + s, 0, len(gt) - 1)] for s in (-1, 0, 1))
        curv = fm - 2.0 * f0 + fp
        with np.errstate(invalid="ignore", divide="ignore"):
            step = np.where((k > 0) & (k < len(gt) - 1) & (curv < 0.0), 0.5 * (fm - fp) / curv, 0.0)
        peak = f0 - 0.25 * (fm - fp) * np.clip(step, -0.5, 0.5)
        # links for a ground of 1: input 1/R2, output 1/R1, coupler from R3; the
        # transmission angle between coupler and output (cosine rule on the diagonal)
        ai, co = 1.0 / r2, 1.0 / r1
        b2 = ai * ai + co * co + 1.0 - 2.0 * ai * co * r3
        diag2 = ai * ai + 1.0 + 2.0 * ai * np.cos(ga)
        with np.errstate(invalid="ignore"):
            cos_mu = (b2 + co * co - diag2) / (2.0 * np.sqrt(b2) * np.abs(co))
            mu = degrees(np.arccos(np.clip(np.abs(cos_mu), 0.0, 1.0))).min(axis=1)
        assembles = ~np.isnan(err).any(axis=1) & (b2[:, 0] > 0.0)
        out["max_error_deg"].append(np.where(assembles, peak, np.nan))
        out["min_transmission_deg"].append(mu)
        out["ok"].append(assembles & (mu >= min_transmission))
    return {k: np.concatenate(v) for k, v in out.items()}

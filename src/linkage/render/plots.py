"""Drawings and plots (matplotlib, the optional ``plot`` extra, imported only here).

- :func:`sweep_plot`: each unknown against the driver, positions without a solution on
  the followed branch shaded, limit and toggle positions marked, the branch named.
- :func:`draw_mechanism`: the mechanism at one position, drawn from its joint
  coordinates (the cumulative vector sums of each loop), links and joints labelled.
- :func:`animate_sweep`: the same drawing over a sweep, as a GIF.
- :func:`convergence_plot`: log10 of the error against the iteration, per method.
The output format follows the file suffix (.png, .svg, .pdf; .gif for animations).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ..errors import InputError
from ..units import RAD_PER_DEG, radians

SUFFIXES = (".png", ".svg", ".pdf")


def pyplot() -> Any:
    try:
        import matplotlib
    except ImportError:
        raise InputError("plots need matplotlib: pip install 'linkage-kinematics[plot]'") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _check_suffix(path: Path, allowed: Sequence[str]) -> None:
    if path.suffix.lower() not in allowed:
        raise InputError(f"{path}: use one of {', '.join(allowed)} for the picture")


def save_figure(fig: Any, path: Path) -> None:
    import warnings

    from ..files import atomic_target

    try:
        with atomic_target(path) as tmp, warnings.catch_warnings(record=True) as seen:
            warnings.simplefilter("always")
            fig.savefig(tmp, dpi=120, bbox_inches="tight", format=path.suffix.lower()[1:])
        # matplotlib's two-line warning per missing glyph (a name in a script the font
        # lacks) becomes one line saying what the reader will see
        if any("missing from font" in str(w.message) for w in seen):
            import sys

            print(f"note: {path}: the font has no glyph for some characters of the names; "
                  "they show as boxes", file=sys.stderr)
        for w in seen:
            if "missing from font" not in str(w.message):
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def _series(result: Any) -> list[tuple[str, list[float]]]:
    """(axis label, values) of every curve: each unknown, and with a driver speed its
    velocity and acceleration (rad/s for angles)."""
    from ..kinematics.rates import rate_label

    out = []
    for name, unit in zip(result.names, result.units):
        out.append((f"{name} ({unit})", [p.solution[name] if p.solution else math.nan
                                         for p in result.positions]))
        if result.motion is not None:
            base = "rad" if unit == "deg" else unit
            for key, label, u in (("velocities", f"d{name}/dt", f"{base}/s"),
                                  ("accelerations", f"d2{name}/dt2", f"{base}/s^2")):
                order = 1 if key == "velocities" else 2
                # undefined and ill-conditioned rates are NaN: the line breaks there
                out.append((f"{label}\n({u})", [getattr(p.rates, key).get(name, math.nan)
                                                if p.rates is not None and p.rates.velocities
                                                and not p.rates.flagged(rate_label(name, order)) else math.nan
                                                for p in result.positions]))
    return out


def sweep_plot(result: Any, path: Path, motion_text: str | None = None) -> None:
    """``motion_text``: the driver's speed (and acceleration) as the user gave them, e.g.
    "600 rpm"; without it the title says the internal rad/s (or length/s)."""
    _check_suffix(path, SUFFIXES)
    plt = pyplot()
    series = _series(result)
    # constrained layout places the panels under the title: the default subplot margins
    # left a band of empty figure above a tall stack (12 % of its height)
    fig, axes = plt.subplots(len(series), 1, sharex=True, figsize=(8, 1.9 * len(series) + 1.2),
                             squeeze=False, layout="constrained")
    xs = [p.input for p in result.positions]
    gaps = bands(result)
    # a re-entry on the other assembly that carries the branch's label is a jump, not a
    # motion: the line breaks before it
    from ..kinematics.continuation import REENTERED

    jumps = {i for i, p in enumerate(result.positions) if i and p.note == REENTERED}
    for ax, (label, ys) in zip(axes[:, 0], series):
        ax.plot(*_broken(xs, ys, jumps), color="tab:blue", lw=1.6)
        ax.set_ylabel(label, fontsize=9)
        ax.grid(True, alpha=0.3)
        for a, b, status in gaps:
            ax.axvspan(a, b, color="tab:red" if status == "no_solution" else "tab:orange", alpha=0.15, lw=0)
        for t in result.toggles:
            ax.axvline(t, color="tab:red", ls="--", lw=1.0)
    axes[-1, 0].set_xlabel(f"{result.driver} ({result.driver_unit})")
    shaded = {status for _, _, status in gaps}
    legend = []
    if "no_solution" in shaded:
        legend.append("red band: cannot be assembled")
    if "off_branch" in shaded:
        legend.append("orange band: another assembly, not connected")
    if result.toggles:
        legend.append("dashed: limit/toggle positions")
    if jumps:
        legend.append("a break in a line: re-entered on the other assembly")
    # a sign string is the followed assembly (a rocker-driven four-bar's, whose positions'
    # names change along it), named or not by --branch
    signs = bool(result.branch) and set(result.branch) <= {"+", "-"}
    title = f"{result.mechanism}: " + (f"{result.branch} branch" if result.branch in ("open", "crossed")
                                       or signs else "the branch of the file's guess")
    if result.motion is not None and motion_text:
        title += f"; driver at {motion_text}"
    elif result.motion is not None:
        per = "rad" if result.driver_unit == "deg" else result.driver_unit
        title += f"; driver at {result.motion[0]:g} {per}/s, {result.motion[1]:g} {per}/s^2"
    import textwrap

    notes = "\n".join(textwrap.wrap("; ".join(legend), 100))
    fig.suptitle(title + ("\n" + notes if legend else ""), fontsize=10)
    save_figure(fig, path)


def path_plot(result: Any, mechanism: Any, names: Sequence[str], path: Path) -> None:
    """The paths of named joints or points over a sweep (a coupler curve), with the
    mechanism drawn faintly at the first solved position."""
    _check_suffix(path, SUFFIXES)
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 5.5))
    first = next((p for p in result.positions if p.rates is not None), None)
    if first is not None:
        scale = RAD_PER_DEG if mechanism.driver.kind == "angle" else 1.0
        q = [radians(first.solution[u.name]) if u.kind == "angle" else first.solution[u.name]
             for u in mechanism.unknowns]
        # the second line says where the faint linkage stands: without it a reader takes
        # it for any position of the curve
        _draw(ax, mechanism, q, first.input * scale,
              f"{result.mechanism}: path of {', '.join(names)} over {result.driver} "
              f"{result.positions[0].input:g} to {result.positions[-1].input:g} {result.driver_unit}\n"
              f"linkage drawn at {result.driver} = {first.input:g} {result.driver_unit}")
    for k, name in enumerate(names):
        pts = [p.rates.joints[name] if p.rates is not None else (math.nan, math.nan)
               for p in result.positions]
        ax.plot([x for x, _ in pts], [y for _, y in pts], lw=1.8, color=("tab:green", "tab:purple",
                                                                        "tab:brown")[k % 3], label=name)
    ax.legend(fontsize=9)
    save_figure(fig, path)


def _broken(xs: Sequence[float], ys: Sequence[float], before: set[int]) -> tuple[list[float], list[float]]:
    """The curve with a NaN point before each index in ``before`` (matplotlib breaks there)."""
    bx: list[float] = []
    by: list[float] = []
    for i, (x, y) in enumerate(zip(xs, ys)):
        if i in before:
            bx.append(x)
            by.append(math.nan)
        bx.append(x)
        by.append(y)
    return bx, by


def bands(result: Any) -> list[tuple[float, float, str]]:
    """The shaded intervals of a sweep plot: runs of positions off the branch, a run that
    cannot be assembled cut back to the feasible ranges' ends."""
    xs = [p.input for p in result.positions]
    return [(a, b, status) for lo, hi, status in _runs([p.status for p in result.positions], xs)
            for a, b in (_outside(lo, hi, result.feasible_ranges) if status == "no_solution"
                         else [(lo, hi)])]


def _outside(lo: float, hi: float, ranges: Sequence[tuple[float, float]]) -> list[tuple[float, float]]:
    """The parts of [lo, hi] outside the feasible ranges: a run of unassembled grid
    positions reaches to its solved neighbours, but the linkage assembles up to the limit
    positions inside that interval (exact where a closed form locates them)."""
    out = [(lo, hi)]
    for a, b in ranges:
        out = [piece for x, y in out for piece in ((x, min(y, a)), (max(x, b), y)) if piece[1] > piece[0]]
    return out


def _runs(statuses: Sequence[str], xs: Sequence[float]) -> list[tuple[float, float, str]]:
    """Contiguous runs of positions off the branch, as (from, to, status) intervals
    reaching to the neighbouring solved positions."""
    out: list[tuple[float, float, str]] = []
    i = 0
    while i < len(statuses):
        if statuses[i] == "converged":
            i += 1
            continue
        j = i
        while j + 1 < len(statuses) and statuses[j + 1] == statuses[i]:
            j += 1
        lo = xs[i - 1] if i > 0 else xs[i]
        hi = xs[j + 1] if j + 1 < len(xs) else xs[j]
        out.append((lo, hi, statuses[i]))
        i = j + 1
    return out


def _geometry(mechanism: Any, q: Sequence[float], driver: float) -> list[tuple[list[complex], Any]]:

    model = mechanism.model
    return list(zip(model.points(q, driver), mechanism.loops))


def _draw(ax: Any, mechanism: Any, q: Sequence[float], driver: float, title: str,
          adjustable: str = "datalim") -> None:
    drawn_joints: dict[tuple[float, float], str] = {}
    names_of = {u.name for u in mechanism.unknowns}
    moving = names_of | {mechanism.driver.name}

    def moves(ref: object) -> bool:
        return isinstance(ref, str) and ref in moving

    for points, loop in _geometry(mechanism, q, driver):
        for k, term in enumerate(loop.vectors):
            a, b = points[k], points[k + 1]
            fixed = not moves(term.length) and not moves(term.angle)
            slider = isinstance(term.length, str) and term.length in names_of
            driven = term.angle == mechanism.driver.name
            style = dict(color="0.55", ls="--", lw=1.2) if fixed else (
                dict(color="tab:orange", ls=":", lw=2.0) if slider else
                dict(color="tab:red" if driven else "tab:blue", lw=3.0 if driven else 2.4))
            ax.plot([a.real, b.real], [a.imag, b.imag], solid_capstyle="round", **style)
            if not fixed and isinstance(term.length, str) and b != a:
                mid = (a + b) / 2
                normal = 1j * (b - a) / abs(b - a)  # label beside the link, never on it:
                # the text's near corner on the normal, so a steep link's label clears it
                ha = "center" if abs(normal.real) < 0.3 else ("left" if normal.real > 0 else "right")
                va = "center" if abs(normal.imag) < 0.3 else ("bottom" if normal.imag > 0 else "top")
                ax.annotate(term.length, (mid.real, mid.imag), textcoords="offset points",
                            xytext=(5 * normal.real, 5 * normal.imag), ha=ha, va=va,
                            fontsize=8, color=style["color"])
        labels = loop.joints or ("",) * len(loop.vectors)
        for k, label in enumerate(labels):
            if not label:
                continue
            p = points[k]
            key = (round(p.real, 6), round(p.imag, 6))
            if key in drawn_joints:
                continue
            drawn_joints[key] = label
            ax.plot([p.real], [p.imag], "o", ms=6, mfc="white", mec="black", zorder=5)
            ax.annotate(label, (p.real, p.imag), textcoords="offset points", xytext=(5, -11), fontsize=9)
    for name, (origin, pos) in _named_points(mechanism, q, driver).items():
        ax.plot([origin.real, pos.real], [origin.imag, pos.imag], color="tab:blue", lw=1.2, alpha=0.6)
        ax.plot([pos.real], [pos.imag], "D", ms=6, color="tab:green", zorder=6)
        ax.annotate(name, (pos.real, pos.imag), textcoords="offset points", xytext=(6, 4), fontsize=9,
                    color="tab:green")
    ax.set_aspect("equal", adjustable=adjustable)
    ax.grid(True, alpha=0.25)
    ax.set_xlabel(f"x ({mechanism.length_unit})")
    ax.set_ylabel(f"y ({mechanism.length_unit})")
    ax.set_title(title, fontsize=10)


def _named_points(mechanism: Any, q: Sequence[float], driver: float) -> dict[str, tuple[complex, complex]]:
    """Each named point with the joint it hangs from: name -> (joint, point)."""
    if not mechanism.points:
        return {}
    from ..kinematics.placing import place

    placed = place(mechanism.model, q, driver)
    return {name: (placed[origin][0], placed[name][0]) for name, (origin, _) in mechanism.points.items()}


def draw_on(ax: Any, mechanism: Any, q: Sequence[float], driver: float, title: str) -> None:
    """The mechanism at (q, driver) drawn on ``ax``, as :func:`draw_mechanism` draws it: for
    pictures built on the drawing (the instant centres, render.centres)."""
    _draw(ax, mechanism, q, driver, title)


def draw_mechanism(mechanism: Any, q: Sequence[float], path: Path, title: str) -> None:
    _check_suffix(path, SUFFIXES)
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 5.5))
    _draw(ax, mechanism, q, mechanism.driver.value, title)
    save_figure(fig, path)


def assembly_gaps(result: Any) -> list[tuple[float, float]]:
    """The driver intervals of a sweep where the linkage cannot be assembled (the red
    bands of its plot), in the driver's unit."""
    return [(a, b) for a, b, status in bands(result) if status == "no_solution"]


def frame_notes(values: Sequence[float], gaps: Sequence[tuple[float, float]], unit: str) -> list[str]:
    """A note per animation frame: the last frame before a gap and the first after it say
    where the linkage cannot be assembled (the animation jumps over that interval).
    ``values``: each frame's driver value, increasing, in ``unit`` like ``gaps``."""
    notes = [""] * len(values)
    for a, b in gaps:
        text = f"cannot be assembled from {a:.4g} to {b:.4g} {unit}"
        before = [i for i, v in enumerate(values) if v <= a]
        after = [i for i, v in enumerate(values) if v >= b]
        for i in ([before[-1]] if before else []) + ([after[0]] if after else []):
            notes[i] = "; ".join(filter(None, (notes[i], text)))
    return notes


def sweep_frames(mechanism: Any, sweep: Any) -> list[tuple[float, list[float]]]:
    """The solved positions of a sweep as animation frames: (driver, unknowns), angles in
    radians (the file's degrees converted), lengths as they are."""
    scale = RAD_PER_DEG if mechanism.driver.kind == "angle" else 1.0
    return [(p.input * scale,
             [radians(p.solution[u.name]) if u.kind == "angle" else p.solution[u.name]
              for u in mechanism.unknowns]) for p in sweep.positions if p.solution]


def animate_sweep(mechanism: Any, frames: Sequence[tuple[float, Sequence[float]]], path: Path,
                  fps: float = 12, progress: Any = None, gaps: Sequence[tuple[float, float]] = ()) -> None:
    """frames: (driver value in internal units, q) per frame; ``fps``: frames per second
    (0.01 to 100: a GIF counts a frame's delay in hundredths of a second); ``gaps``: the
    driver intervals (the driver's unit) that cannot be assembled, noted on the frames
    either side (see :func:`assembly_gaps`)."""
    from ..arguments import check_fps

    fps = check_fps("fps", fps)
    _check_suffix(path, (".gif",))
    plt = pyplot()
    from matplotlib.animation import FuncAnimation, PillowWriter

    scale = 180.0 / math.pi if mechanism.driver.kind == "angle" else 1.0
    values = [d * scale for d, _ in frames]
    notes = frame_notes(values, gaps, mechanism.driver.unit)
    fig, ax = plt.subplots(figsize=(6, 5.1 if any(notes) else 4.8))
    if any(notes):
        fig.subplots_adjust(bottom=0.16)  # room for a note under the x label
    allpts = [p for d, q in frames for pts, _ in _geometry(mechanism, q, d) for p in pts]
    xs, ys = [p.real for p in allpts], [p.imag for p in allpts]
    pad = 0.08 * max(max(xs) - min(xs), max(ys) - min(ys), 1e-9)

    traces = [_named_points(mechanism, q, d) for d, q in frames]
    # the traced path breaks across a gap: a straight stroke there is no motion
    cuts = {i for i in range(1, len(values)) for a, b in gaps if values[i - 1] <= a and values[i] >= b}
    for t in traces:
        for _, pos in t.values():
            xs.append(pos.real)
            ys.append(pos.imag)

    def update(i: int) -> None:
        ax.clear()
        d, q = frames[i]
        for name in mechanism.points:  # the path each named point has traced so far
            path_pts = [t[name][1] for t in traces[: i + 1]]
            ax.plot(*_broken([p.real for p in path_pts], [p.imag for p in path_pts], cuts),
                    color="tab:green", lw=1.0, alpha=0.7)
        _draw(ax, mechanism, q, d, f"{mechanism.name}: {mechanism.driver.name} = {d * scale:.1f} "
                                   f"{mechanism.driver.unit}", adjustable="box")
        if notes[i]:
            # under the axes, where it hides no link (ax.clear() removes it for the next frame)
            ax.text(0.5, 0.015, notes[i], transform=fig.transFigure, ha="center", va="bottom", fontsize=9,
                    color="tab:red", bbox=dict(boxstyle="round", fc="white", ec="tab:red"))
        ax.set_xlim(min(xs) - pad, max(xs) + pad)
        ax.set_ylim(min(ys) - pad, max(ys) + pad)

    anim = FuncAnimation(fig, update, frames=len(frames))
    from ..files import atomic_target

    try:
        with atomic_target(path) as tmp:
            anim.save(tmp, writer=PillowWriter(fps=fps),
                      progress_callback=(lambda i, n: progress(i + 1)) if progress else None)
    finally:
        plt.close(fig)


def error_series(results: Sequence[Any]) -> list[tuple[str, list[float | None]]]:
    """Each run's label and its iterates' error sizes (None where an iterate has none)."""
    series = []
    for r in results:
        errors = [abs(e) if isinstance(e, (int, float)) else None for e in r.history.errors()] \
            if r.history is not None else []
        series.append((f"{r.method} ({r.status.value})", errors))
    return series


def convergence_plot(runs: Sequence[tuple[str, Sequence[float]]], path: Path, title: str,
                     unit: str = "") -> None:
    """runs: (label, errors per iteration); ``unit``: the errors' unit."""
    _check_suffix(path, SUFFIXES)
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label, errors in runs:
        pts = [(k + 1, math.log10(e)) for k, e in enumerate(errors)
               if e is not None and e > 0 and math.isfinite(e)]
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", ms=4, label=label)
    ax.set_xlabel("iteration")
    from matplotlib.ticker import MaxNLocator

    ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # iteration 2.5 does not exist
    ax.set_ylabel(f"log10 of the error ({unit})" if unit else "log10 of the error")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    save_figure(fig, path)


def work_precision_plot(measurements: Sequence[Any], path: Path) -> None:
    """log10 error against log10 time, one line per contender, one panel per problem."""
    _check_suffix(path, SUFFIXES)
    plt = pyplot()
    problems = list(dict.fromkeys(m.problem for m in measurements))
    fig, axes = plt.subplots(1, len(problems), figsize=(6.5 * len(problems), 5.5), squeeze=False)
    for ax, problem in zip(axes[0], problems):
        series: dict[str, list[tuple[float, float]]] = {}
        for m in measurements:
            if m.problem == problem:
                series.setdefault(m.contender, []).append(
                    (math.log10(m.seconds), math.log10(max(m.error, 1e-17))))
        colours = plt.get_cmap("tab20").colors
        markers = "osD^v<>pX*"
        for k, (label, pts) in enumerate(sorted(series.items())):
            pts.sort()
            style = "-" if label.startswith("linkage") else ("--" if label.startswith("scipy") else ":")
            # 20 colours and 10 markers: no two of up to 20 contenders look alike
            ax.plot([p[0] for p in pts], [p[1] for p in pts], style, marker=markers[k % len(markers)], ms=4,
                    lw=1.3, color=colours[k % len(colours)], label=label)
        ax.set_xlabel("log10 time per solve (s)")
        ax.set_ylabel("log10 error (errors of 0 drawn at -17)")
        ax.set_title(problem, fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, frameon=False)
    fig.suptitle("work-precision: lower left is better (solid: linkage, dashed: scipy, dotted: hand loops)",
                 fontsize=11)
    save_figure(fig, path)

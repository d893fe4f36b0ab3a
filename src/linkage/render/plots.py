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

SUFFIXES = (".png", ".svg", ".pdf")


def _pyplot() -> Any:
    try:
        import matplotlib
    except ImportError:
        raise InputError("plots need matplotlib: pip install 'linkage[plot]'") from None
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _check_suffix(path: Path, allowed: Sequence[str]) -> None:
    if path.suffix.lower() not in allowed:
        raise InputError(f"{path}: use one of {', '.join(allowed)} for the picture")


def _save(fig: Any, path: Path) -> None:
    from ..files import atomic_target

    try:
        with atomic_target(path) as tmp:
            fig.savefig(tmp, dpi=120, bbox_inches="tight", format=path.suffix.lower()[1:])
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def sweep_plot(result: Any, path: Path) -> None:
    _check_suffix(path, SUFFIXES)
    plt = _pyplot()
    names, units = result.names, result.units
    fig, axes = plt.subplots(len(names), 1, sharex=True, figsize=(8, 1.9 * len(names) + 1.2), squeeze=False)
    xs = [p.input for p in result.positions]
    gaps = _runs([p.status for p in result.positions], xs)
    for ax, name, unit in zip(axes[:, 0], names, units):
        ys = [p.solution[name] if p.solution else math.nan for p in result.positions]
        ax.plot(xs, ys, color="tab:blue", lw=1.6)
        ax.set_ylabel(f"{name} ({unit})")
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
    title = f"{result.mechanism}: {result.branch or ''} branch"
    fig.suptitle(title + ("\n" + "; ".join(legend) if legend else ""), fontsize=10)
    _save(fig, path)


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
    from ..problems.loops import LoopModel

    model = LoopModel.compile(mechanism)
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
            if not fixed and isinstance(term.length, str):
                mid = (a + b) / 2
                ax.annotate(term.length, (mid.real, mid.imag), textcoords="offset points", xytext=(4, 4),
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
    ax.set_aspect("equal", adjustable=adjustable)
    ax.grid(True, alpha=0.25)
    ax.set_xlabel(mechanism.length_unit)
    ax.set_title(title, fontsize=10)


def draw_mechanism(mechanism: Any, q: Sequence[float], path: Path, title: str) -> None:
    _check_suffix(path, SUFFIXES)
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 5.5))
    _draw(ax, mechanism, q, mechanism.driver.value, title)
    _save(fig, path)


def animate_sweep(mechanism: Any, frames: Sequence[tuple[float, Sequence[float]]], path: Path,
                  fps: int = 12) -> None:
    """frames: (driver value in internal units, q) per frame."""
    _check_suffix(path, (".gif",))
    plt = _pyplot()
    from matplotlib.animation import FuncAnimation, PillowWriter

    fig, ax = plt.subplots(figsize=(6, 4.8))
    allpts = [p for d, q in frames for pts, _ in _geometry(mechanism, q, d) for p in pts]
    xs, ys = [p.real for p in allpts], [p.imag for p in allpts]
    pad = 0.08 * max(max(xs) - min(xs), max(ys) - min(ys), 1e-9)
    scale = 180.0 / math.pi if mechanism.driver.kind == "angle" else 1.0

    def update(i: int) -> None:
        ax.clear()
        d, q = frames[i]
        _draw(ax, mechanism, q, d, f"{mechanism.name}: {mechanism.driver.name} = {d * scale:.1f} "
                                   f"{mechanism.driver.unit}", adjustable="box")
        ax.set_xlim(min(xs) - pad, max(xs) + pad)
        ax.set_ylim(min(ys) - pad, max(ys) + pad)

    anim = FuncAnimation(fig, update, frames=len(frames))
    from ..files import atomic_target

    try:
        with atomic_target(path) as tmp:
            anim.save(tmp, writer=PillowWriter(fps=fps))
    finally:
        plt.close(fig)


def convergence_plot(runs: Sequence[tuple[str, Sequence[float]]], path: Path, title: str) -> None:
    """runs: (label, errors per iteration)."""
    _check_suffix(path, SUFFIXES)
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for label, errors in runs:
        pts = [(k + 1, math.log10(e)) for k, e in enumerate(errors)
               if e is not None and e > 0 and math.isfinite(e)]
        if pts:
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", ms=4, label=label)
    ax.set_xlabel("iteration")
    ax.set_ylabel("log10 error")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title, fontsize=10)
    _save(fig, path)


def work_precision_plot(measurements: Sequence[Any], path: Path) -> None:
    """log10 error against log10 time, one line per contender, one panel per problem."""
    _check_suffix(path, SUFFIXES)
    plt = _pyplot()
    problems = list(dict.fromkeys(m.problem for m in measurements))
    fig, axes = plt.subplots(1, len(problems), figsize=(6.5 * len(problems), 5.5), squeeze=False)
    for ax, problem in zip(axes[0], problems):
        series: dict[str, list[tuple[float, float]]] = {}
        for m in measurements:
            if m.problem == problem:
                series.setdefault(m.contender, []).append(
                    (math.log10(m.seconds), math.log10(max(m.error, 1e-17))))
        for label, pts in sorted(series.items()):
            pts.sort()
            style = "-" if label.startswith("linkage") else ("--" if label.startswith("scipy") else ":")
            ax.plot([p[0] for p in pts], [p[1] for p in pts], style, marker="o", ms=3, lw=1.2, label=label)
        ax.set_xlabel("log10 time per solve (s)")
        ax.set_ylabel("log10 error (errors of 0 drawn at -17)")
        ax.set_title(problem, fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=6, loc="best")
    fig.suptitle("work-precision: lower left is better", fontsize=10)
    _save(fig, path)

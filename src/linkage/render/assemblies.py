"""The report of ``linkage assemblies``: every assembly, the paths that found them."""

from __future__ import annotations

import math
from typing import Any

from .data import DataTable, Report, from_rows
from .report import Block, Text, denoise, table


def _units(m: Any) -> list[str]:
    return [u.unit if u.kind == "angle" else m.length_unit for u in m.unknowns]


def assemblies_tables(a: Any) -> tuple[DataTable, ...]:
    from ..kinematics.assemblies import display

    m = a.mechanism
    names = [u.name for u in m.unknowns]
    times = a.multiplicity or (1,) * len(a.real)
    rows = [(i + 1, s.branch, s.signs, *display(m, s.q), s.residual, s.condition, s.singular, k)
            for i, (s, k) in enumerate(zip(a.real, times))]
    heads = [("assembly", "", "int"), ("branch", "", "text"), ("signs", "", "text"),
             *[(n, u, "number") for n, u in zip(names, _units(m))],
             ("residual", "", "number"), ("condition", "", "number"), ("near_limit", "", "bool"),
             ("multiplicity", "", "int")]
    joints = [(i + 1, name, x, y) for i, s in enumerate(a.real) for name, (x, y) in s.joints.items()]
    paths = [(k + 1, e.kind, e.real if e.kind in ("finite", "singular") else None, e.cycle, e.steps,
              e.rejected, e.newton, e.smallest_step if math.isfinite(e.smallest_step) else None,
              e.retracked, e.endgame, None if c is None else c.certified, None if c is None else c.alpha,
              e.note) for k, (e, c) in enumerate(zip(a.solutions.endpoints, a.solutions.certificates))]
    return (
        from_rows("assemblies", heads, rows),
        from_rows("joints", [("assembly", "", "int"), ("joint", "", "text"), ("x", m.length_unit, "number"),
                             ("y", m.length_unit, "number")], joints),
        from_rows("paths", [("path", "", "int"), ("endpoint", "", "text"), ("real", "", "bool"),
                            ("cycle", "", "int"), ("steps", "", "int"), ("rejected", "", "int"),
                            ("newton", "", "int"), ("smallest_step", "", "number"), ("retracked", "", "bool"),
                            ("endgame", "", "bool"), ("certified", "", "bool"), ("alpha", "", "number"),
                            ("note", "", "text")], paths),
    )


def title_of(a: Any) -> str:
    m = a.mechanism
    shown = a.driver / _scale(m.driver) if m.driver.kind == "angle" else a.driver
    unit = m.driver.unit if m.driver.kind == "angle" else m.length_unit
    return f"{m.name}: every assembly at {m.driver.name} = {float(f'{shown:.12g}'):g} {unit}"


def _scale(q: Any) -> float:
    from ..problems.loops import ANGLE_UNITS

    return ANGLE_UNITS[q.unit]


def summary_lines(a: Any) -> list[str]:
    s = a.solutions
    n_angles = sum(u.kind == "angle" for u in a.mechanism.unknowns)
    retracked = sum(e.retracked for e in s.endpoints)
    extra = []
    doubles = sum(k > 1 for k in a.multiplicity)
    if doubles:
        # named, not "of them": the line above counts the certified roots, not the real assemblies
        extra.append(f"{doubles} of the real assemblies double (two assemblies that meet here, to "
                     "rounding: a limit position or a change point)")
    if a.continuum:
        extra.append("not isolated: the loops close all along a curve here (the mechanism can move "
                     "with its driver held)")
    elif a.unresolved:
        extra.append(f"{a.unresolved} root(s) near a singular point neither found real nor shown complex")
    n_lengths = len(a.mechanism.unknowns) - n_angles
    return [
        f"polynomial system: {s.system.n} unknowns (z = e^(i theta) and w = e^(-i theta) of {n_angles} "
        f"angle{'s' if n_angles != 1 else ''}, z w = 1 each"
        + (f"; {n_lengths} length{'s' if n_lengths != 1 else ''}" if n_lengths else "") + "), "
        f"degrees {' '.join(map(str, s.system.degrees))}",
        f"{_bound_text(s, n_lengths > 0)}: {len(a.real)} real assembl"
        f"{'y' if len(a.real) == 1 else 'ies'}, {a.complex_count} complex, {a.infinite} at infinity, "
        f"{a.failed} failed" + (f" ({retracked} retracked)" if retracked else "")
        + f"; {sum(e.steps for e in s.endpoints)} steps in {s.seconds:.2f} s",
        certified_line(s),
        *extra,
    ]


def certified_line(s: Any) -> str:
    """How many finite roots Smale's alpha test certifies (linkage.homotopy.alpha)."""
    finite = s.count("finite")
    pairs = s.certified
    apart = s.undistinguished
    real = sum(c.real for _, c in pairs)
    return (f"alpha test (Smale; 50 digits): {len(pairs)} of {finite} nonsingular root"
            f"{'s' if finite != 1 else ''} certified, {real} of them real"
            + distinct_text(len(apart), len(pairs), finite))


def distinct_text(apart: int, certified: int, listed: int) -> str:
    """What the alpha test says of distinctness, ``apart`` pairs of the ``certified`` points
    not told apart (linkage.homotopy.alpha.undistinguished): "all distinct" only when every
    one of the ``listed`` points is certified (an uncertified one has no ball to compare)."""
    if apart:
        return f", {apart} pair(s) not told apart"
    if certified == listed:
        return ", all distinct"
    return ", the certified ones distinct" if certified > 1 else ""


def _bound_text(s: Any, lengths: bool) -> str:
    """How many paths, and which bound that is (issue 34: the bound stated)."""
    from ..homotopy.start import LINEAR_PRODUCT

    if s.start == LINEAR_PRODUCT:
        grouping = "{z}, {w}" + (", {lengths}" if lengths else "")
        return (f"{s.bound} paths (the linear-product Bezout number of the grouping {grouping}; "
                f"total degree {s.bezout})")
    return f"{s.bound} paths (Bezout's bound, the total degree)"


def _display(t: DataTable, digits: int, scale: float = 0.0, hide: tuple[str, ...] = ()) -> Block:
    """A table as the terminal shows it, without the columns ``hide`` names (files keep
    them); with ``scale``, numbers within rounding of zero at that scale (a joint at the
    origin computed as 2e-14) shown as 0."""
    shown = [c for c in t.columns if c.name not in hide]
    rows = [tuple(denoise(v, scale) if scale else v for v in row) for row in zip(*[c.values for c in shown])]
    return table("", [c.header for c in shown], rows, digits)


def quiet_columns(a: Any) -> tuple[str, ...]:
    """Columns the terminal leaves out because they say nothing the lines above do not: the
    multiplicity when every assembly is simple (the summary counts the double ones) and the
    paths' note when no path has one. At 80 columns each would otherwise stack a table of
    its own."""
    simple = ("multiplicity",) if all(k == 1 for k in a.multiplicity) else ()
    silent = ("note",) if not any(e.note for e in a.solutions.endpoints) else ()
    return simple + silent


def assemblies_report(a: Any, digits: int, show_paths: bool) -> Report:
    tables = assemblies_tables(a)

    def blocks() -> list[Block]:
        out: list[Block] = [Text(title_of(a), "bold"), *[Text(line) for line in summary_lines(a)], Text("")]
        if tables[0].row_count:
            out.append(_display(tables[0], digits, hide=quiet_columns(a)))
        elif a.continuum:  # the loops close along a curve: assembled, but no isolated assembly to list
            out.append(Text("no isolated assembly to list: the assemblies here form a curve"))
        else:
            out.append(Text("no real assembly: the mechanism cannot be assembled here"))
        if any(s.singular for s in a.real):
            out.append(Text("near_limit: close to where two assemblies meet (condition above 1e6): "
                            "digits beyond about 16 - log10(condition) are not significant"))
        if tables[1].row_count:
            size = max((abs(v) for s in a.real for xy in s.joints.values() for v in xy), default=0.0)
            out += [Text("Joints"), _display(tables[1], digits, size)]
        if show_paths:
            out += [Text("Paths"), _display(tables[2], digits, hide=quiet_columns(a))]
        for e in a.solutions.endpoints:
            if e.kind == "failed":
                out.append(Text(f"failed path: {e.note}"))
        return out

    def document() -> dict[str, Any]:
        s = a.solutions
        return {"title": title_of(a), "bezout": s.bezout, "bound": s.bound, "start": s.start,
                "paths": len(s.endpoints), "real": len(a.real),
                "complex": a.complex_count, "infinite": a.infinite, "failed": a.failed,
                "unresolved": a.unresolved, "continuum": a.continuum,
                "alpha_certified": len(s.certified),
                "alpha_certified_real": sum(c.real for _, c in s.certified),
                "alpha_undistinguished": len(s.undistinguished),
                "degrees": list(s.system.degrees), "seconds": s.seconds}

    return Report(title_of(a), tables, blocks, document)

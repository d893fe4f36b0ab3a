"""The tolerance study's report (every format, through the writers' registry) and its
picture: an output's nominal curve with its linear worst-case, RSS and Monte Carlo bands
over the cycle (docs/tolerance.md)."""

from __future__ import annotations

import math
from collections import Counter
from pathlib import Path
from typing import Any

import numpy as np

from .data import DataTable, Report, column, from_rows
from .report import Block, Text, fmt, table


def column_name(output: str) -> str:
    """An output's name as a column's stem: ``P.x`` -> ``P_x`` (--where and --columns read
    a dot as an attribute)."""
    return output.replace(".", "_")


def _floats(a: Any) -> list[float]:
    return [float(v) for v in np.asarray(a, dtype=float)]


def positions_table(s: Any) -> DataTable:
    """One row per driver value: status and linearity, the share of samples not assembled,
    and per output its nominal value, bands, Monte Carlo percentiles and each tolerance's
    contribution (signed: the output's change at +D)."""
    cols = [column(s.driver, s.driver_unit, list(s.values)), column("status", "", list(s.status), "text"),
            column("nonlinearity", "", _floats(s.nonlinearity))]
    if s.samples is not None:
        cols.append(column("not_assembled", "", _floats(s.not_assembled)))
    wc, rss, sig, contrib = s.worst_case, s.rss, s.linear_sigma, s.contributions
    for j, o in enumerate(s.outputs):
        stem = column_name(o.name)
        cols += [column(f"{stem}_nominal", o.unit, _floats(s.nominal[j])),
                 column(f"{stem}_worst_case", o.unit, _floats(wc[j])),
                 column(f"{stem}_rss", o.unit, _floats(rss[j])),
                 column(f"{stem}_sigma_linear", o.unit, _floats(sig[j]))]
        if s.samples is not None:
            cols += [column(f"{stem}_mc_low", o.unit, _floats(s.mc_low[j])),
                     column(f"{stem}_mc_median", o.unit, _floats(s.mc_median[j])),
                     column(f"{stem}_mc_high", o.unit, _floats(s.mc_high[j])),
                     column(f"{stem}_sigma_mc", o.unit, _floats(s.mc_sigma[j]))]
        cols += [column(f"{stem}_from_{column_name(t.name)}", o.unit, _floats(contrib[j, i]))
                 for i, t in enumerate(s.tolerances)]
    return DataTable("positions", tuple(cols))


def _peak(values: np.ndarray, xs: tuple[float, ...]) -> tuple[float, float | None]:
    """The largest finite value and the driver value where it is (NaN, None: none)."""
    v = np.where(np.isfinite(values), np.abs(values), -np.inf)
    if not len(v) or not np.isfinite(v.max()):
        return math.nan, None
    k = int(np.argmax(v))
    return float(values[k]), xs[k]


def summary_rows(s: Any) -> list[tuple[Any, ...]]:
    """Per output and tolerance: the largest |contribution| over the positions whose
    status is ok, and where; the last row of each output its worst case and RSS."""
    ok = np.array([st == "ok" for st in s.status])
    contrib = np.where(ok[None, None, :], s.contributions, np.nan)
    rows = []
    for j, o in enumerate(s.outputs):
        for i, t in enumerate(s.tolerances):
            peak, at = _peak(contrib[j, i], s.values)
            rows.append((o.name, o.unit, t.name, t.plus_minus, abs(peak), at))
        for label, band in (("worst case", s.worst_case[j]), ("RSS", s.rss[j])):
            peak, at = _peak(np.where(ok, band, np.nan), s.values)
            rows.append((o.name, o.unit, label, None, peak, at))
    return rows


def tolerance_report(s: Any, digits: int) -> Report:
    """The study as a report: the positions table (every format) and a summary of the
    largest contributions, the display one table per output."""
    span = (f"{fmt(s.values[0], digits)} to {fmt(s.values[-1], digits)} {s.driver_unit}"
            if len(s.values) > 1 else f"{fmt(s.values[0], digits)} {s.driver_unit}")
    title = f"{s.mechanism}: tolerances over {s.driver} = {span} ({len(s.values)} positions)"
    summary = from_rows("largest", [("output", "", "text"), ("unit", "", "text"), ("from", "", "text"),
                                    ("plus_minus", "", "number"), ("largest", "", "number"),
                                    (f"at_{s.driver}", s.driver_unit, "number")], summary_rows(s))
    tables = (positions_table(s), summary)

    def blocks() -> list[Block]:
        tols = ", ".join(f"{t.name} ±{fmt(t.plus_minus, digits)}" for t in s.tolerances)
        out: list[Block] = [Text(title, "bold"), Text(f"tolerances ({s.length_unit}): {tols}"),
                            Text(_reading(s))]
        if s.samples is not None:
            failed = round(s.not_assembled_anywhere * s.samples)
            out.append(Text(f"Monte Carlo: {s.samples:,} samples, seed {s.seed}; not assembling at some "
                            f"position: {fmt(100.0 * s.not_assembled_anywhere, 4)}% ({failed:,} of "
                            f"{s.samples:,})"))
        for j in range(len(s.outputs)):
            out += [Text(""), _output_table(s, j, digits)]
        out += [Text(""), table("largest contributions (at positions whose status is ok)",
                                ["output", "from", "±D", "largest", f"at {s.driver} ({s.driver_unit})"],
                                [(f"{r[0]} ({r[1]})", r[2], r[3], r[4] if r[5] is not None else None, r[5])
                                 for r in summary_rows(s)],  # no position: "—", as the values
                                digits)]
        out.append(Text(_status_line(s)))
        return out

    def document() -> dict[str, Any]:
        return {"title": title, "mechanism": s.mechanism, "source": s.source, "driver": s.driver,
                "driver_unit": s.driver_unit, "length_unit": s.length_unit, "branch": s.branch,
                "tolerances": {t.name: t.plus_minus for t in s.tolerances},
                "reading": _reading(s), "distribution": s.distribution, "samples": s.samples,
                "seed": s.seed if s.samples is not None else None,
                "percentiles": [0.135, 50.0, 99.865] if s.samples is not None else None,
                "not_assembled_anywhere": s.not_assembled_anywhere,
                "status_counts": dict(Counter(s.status))}

    return Report(title, tables, blocks, document)


def _reading(s: Any) -> str:
    if s.distribution == "normal":
        return ("±D read as 3 sigma: RSS = sqrt(sum (dq/dp D)^2) is the 3-sigma band; sigma linear "
                "= RSS/3, and the Monte Carlo draws normal, sigma D/3")
    return ("±D the bounds of a uniform draw: RSS = sqrt(sum (dq/dp D)^2) is sqrt(3) sigma; sigma "
            "linear = RSS/sqrt(3), and the Monte Carlo draws uniform within ±D")


def _output_table(s: Any, j: int, digits: int) -> Any:
    o = s.outputs[j]
    mc = s.samples is not None
    headers = [f"{s.driver} ({s.driver_unit})", "status", "nominal", "± worst case", "± RSS",
               "sigma linear"]
    if mc:
        headers += ["sigma MC", "MC 0.135%", "MC median", "MC 99.865%", "not assembled"]
    rows = []
    for k, x in enumerate(s.values):
        nom = float(s.nominal[j, k])
        row: list[Any] = [x, s.status[k], nom, float(s.worst_case[j, k]), float(s.rss[j, k]),
                          float(s.linear_sigma[j, k])]
        if mc:
            row += [float(s.mc_sigma[j, k]), float(s.mc_low[j, k]) - nom, float(s.mc_median[j, k]) - nom,
                    float(s.mc_high[j, k]) - nom, float(s.not_assembled[k])]
        rows.append([None if v != v else v for v in row])  # NaN (no value: not assembled) shows "—"
    title = f"{o.name} ({o.unit})" + (": Monte Carlo percentiles from nominal" if mc else "")
    return table(title, headers, rows, digits)


def _status_line(s: Any) -> str:
    counts = Counter(s.status)
    text = "status: " + ", ".join(f"{k}: {n}" for k, n in counts.items())
    near = [v for v, st in zip(s.values, s.status) if st == "near_limit"]
    if near:
        listed = ", ".join(f"{v:g}" for v in near[:8]) + (" ..." if len(near) > 8 else "")
        text += (f"; near_limit at {s.driver} = {listed} {s.driver_unit}: a limit or toggle is within "
                 "the tolerances' reach there, so the linear bands are not to be trusted (see the "
                 "Monte Carlo)")
    return text


# --- the picture ---------------------------------------------------------------------------------

def tolerance_plot(s: Any, name: str | None, path: Path) -> None:
    """One output over the cycle: above, its nominal curve inside its bands; below, the
    bands as deviations from nominal (worst case, RSS, the Monte Carlo's 0.135 and 99.865
    percentiles), positions whose linear band is near a limit marked, and the share of
    samples not assembling."""
    from .plots import pyplot, save_figure

    j = s.output(name) if name is not None else _default_output(s)
    o = s.outputs[j]
    x = np.array(s.values)
    nom, wc, rss = s.nominal[j], s.worst_case[j], s.rss[j]
    plt = pyplot()
    fig, (top, low) = plt.subplots(2, 1, figsize=(8, 7), sharex=True,
                                   gridspec_kw={"height_ratios": [1, 1.3]})
    # the bands are usually far thinner than the curve's swing: drawn magnified, and said so
    swing = float(np.nanmax(nom) - np.nanmin(nom)) if np.isfinite(nom).any() else 0.0
    widest = float(np.nanmax(wc)) if np.isfinite(wc).any() else 0.0
    zoom = _zoom(swing, widest)
    shown = f" x {zoom:g}" if zoom != 1 else ""
    top.fill_between(x, nom - zoom * wc, nom + zoom * wc, color="#fdd0a2", lw=0, label=f"± worst case{shown}")
    top.fill_between(x, nom - zoom * rss, nom + zoom * rss, color="#9ecae1", lw=0,
                     label=f"± RSS (3 sigma){shown}")
    top.plot(x, nom, color="black", lw=1.2, label="nominal")
    top.set_ylabel(f"{o.name} ({o.unit})")
    top.legend(fontsize=8, loc="best")
    low.fill_between(x, -wc, wc, color="#fdd0a2", lw=0, label="linear worst case")
    low.fill_between(x, -rss, rss, color="#9ecae1", lw=0, label="linear RSS (3 sigma)")
    if s.samples is not None:
        low.plot(x, s.mc_low[j] - nom, color="tab:green", lw=1.4,
                 label=f"Monte Carlo 0.135% / 99.865% ({s.samples:,} samples)")
        low.plot(x, s.mc_high[j] - nom, color="tab:green", lw=1.4)
        low.plot(x, s.mc_median[j] - nom, color="tab:green", lw=0.8, ls="--", label="Monte Carlo median")
    near = np.array([st == "near_limit" for st in s.status])
    if near.any():
        low.plot(x[near], np.zeros(near.sum()), "x", color="tab:red", ms=6,
                 label="near a limit: linear band unreliable")
    low.axhline(0.0, color="black", lw=0.6)
    low.set_ylabel(f"{o.name} from nominal ({o.unit})")
    low.set_xlabel(f"{s.driver} ({s.driver_unit})")
    low.legend(fontsize=8, loc="best")
    tols = ", ".join(f"{t.name} ±{t.plus_minus:g}" for t in s.tolerances)
    title = f"{s.mechanism}: {o.name} with tolerances {tols} {s.length_unit}"
    if s.samples is not None and s.not_assembled_anywhere:
        title += f"\n{100 * s.not_assembled_anywhere:.3g}% of samples fail to assemble somewhere"
    top.set_title(title, fontsize=9)
    fig.tight_layout()
    save_figure(fig, path)


def _zoom(swing: float, widest: float) -> float:
    """How much the top panel magnifies the bands: a round factor (1, 2, 5, 10, 20, ...)
    making the widest worst-case band about a twentieth of the curve's swing, never below 1."""
    if not (swing > 0.0 and widest > 0.0) or widest >= swing / 20.0:
        return 1.0
    want = swing / 20.0 / widest
    step = 10.0 ** math.floor(math.log10(want))
    return max(f * step for f in (1.0, 2.0, 5.0) if f * step <= want)


def _default_output(s: Any) -> int:
    """The last unknown (a four-bar's rocker, a slider-crank's slider): the usual output."""
    unknowns = [k for k, o in enumerate(s.outputs) if not o.point]
    return unknowns[-1] if unknowns else 0

"""``linkage simulate``'s report (every format, through the writers' registry) and its
picture: the driver's angle and speed against time (docs/simulate.md)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from ..records import frozen
from ..units import degrees
from .data import Report, from_rows
from .report import Block, Text, fmt, table


def _driver_columns(sim: Any, driver: str, length_unit: str) -> tuple[list[tuple[str, str]], Any]:
    """(name, unit) of the driver's three columns and the factor from SI to them."""
    if sim.sliding:
        from ..kinematics.bodies import metre

        k = metre(length_unit)
        return [(driver, length_unit), (f"d{driver}/dt", f"{length_unit}/s"),
                (f"d2{driver}/dt2", f"{length_unit}/s^2")], (1.0 / k, 1.0 / k, 1.0 / k)
    return [(driver, "deg"), (f"d{driver}/dt", "rad/s"), (f"d2{driver}/dt2", "rad/s^2")], \
        (degrees(1.0), 1.0, 1.0)


Headers = list[tuple[str, str]]
"""(name, unit) of each column."""


@frozen
class SimulationChecks:
    """The run's verdicts and the numbers its lines quote (:func:`simulation_checks`)."""

    energy_ok: bool | None
    """None: nothing to compare (one output time)."""
    drive_ok: bool | None
    """None: nothing to check (no output time has forces)."""
    energy_tol: float
    drive_tol: float
    target_cs: float

    @property
    def passed(self) -> bool:
        """No check missed (one with nothing to compare is not missed): with no event, exit 0."""
        return self.energy_ok is not False and self.drive_ok is not False


def simulation_checks(sim: Any, energy_tol: float, drive_tol: float, target_cs: float) -> SimulationChecks:
    """The energy balance within ``energy_tol`` of the largest energy and the kinetostatic
    input within ``drive_tol`` of the drive, each None where there is nothing to judge: one
    output time, or no output time with forces (a run that stopped at its start). A NaN
    figure is a miss."""
    forced = any(f is not None and f.input is not None for f in sim.forces)
    return SimulationChecks(bool(sim.balance <= energy_tol) if len(sim.t) > 1 else None,
                            bool(sim.drive_check <= drive_tol) if forced else None, energy_tol, drive_tol,
                            target_cs)


def simulate_report(sim: Any, mechanism: Any, digits: int, energy_tol: float, drive_tol: float,
                    target_cs: float) -> Report:
    """The motion, energies and pin forces at every output time, the checks, the event (if
    the span ended short) and the flywheel lines."""
    motion_headers, motion_rows = _motion(sim, mechanism)
    energy_headers, energy_rows = _energy(sim)
    pins, force_headers, force_rows = _pin_forces(sim)
    tables = (from_rows("motion", [(a, b, "number") for a, b in motion_headers], motion_rows),
              from_rows("energy", [(a, b, "number") for a, b in energy_headers], energy_rows),
              from_rows("pin_forces",
                        [(a, b, "text" if a == "status" else "number") for a, b in force_headers],
                        force_rows))
    title = (f"{mechanism.name or mechanism.source}: simulated from t = {fmt(sim.t[0], digits)} to "
             f"{fmt(sim.t[-1], digits)} s")
    checks = simulation_checks(sim, energy_tol, drive_tol, target_cs)

    def blocks() -> list[Block]:
        head = [f"{a} ({b})" for a, b in motion_headers]
        out: list[Block] = [Text(title, "bold"), Text(""), table("motion", head, motion_rows, digits),
                            Text("")]
        # the balance column is the integrator's error (rounding-level digits): the line below
        # sums it up, the csv and json keep it
        head = [f"{a} ({b})" for a, b in energy_headers[:-1]]
        out += [table("energy", head, [r[:-1] for r in energy_rows], digits), Text("")]
        if pins:
            out += _force_blocks(sim, pins, force_rows, digits)
        out += [Text(line, "" if ok is not False else "red") for line, ok in zip(
            _lines(sim, checks, digits), [checks.energy_ok, checks.drive_ok, True, True, True, True, False])]
        return out

    def document() -> dict[str, Any]:
        return _document(sim, title, checks)

    return Report(title, tables, blocks, document)


def _motion(sim: Any, mechanism: Any) -> tuple[Headers, list[tuple[Any, ...]]]:
    """Time, the driver's position, speed and acceleration, the drive, and the unknowns."""
    dcols, dk = _driver_columns(sim, mechanism.driver.name, mechanism.length_unit)
    kinds = {u.name: u.kind for u in mechanism.unknowns}
    ucols = [(n, "deg" if kinds[n] == "angle" else mechanism.length_unit) for n in sim.unknowns]

    def unknown(name: str, i: int) -> float:
        v = sim.unknowns[name][i]
        return degrees(v) if kinds[name] == "angle" else v

    headers = [("t", "s"), *dcols, ("drive", sim.input_unit), *ucols]
    rows = [(sim.t[i], sim.theta[i] * dk[0], sim.omega[i] * dk[1], sim.alpha[i] * dk[2], sim.drive[i],
             *(unknown(u, i) for u in sim.unknowns)) for i in range(len(sim.t))]
    return headers, rows


def _energy(sim: Any) -> tuple[Headers, list[tuple[Any, ...]]]:
    """The energies and works, and their balance from the start (the integrator's error)."""
    headers = [("t", "s"), ("kinetic", "J"), ("potential", "J"), ("work_drive", "J"),
               ("work_friction", "J"), ("work_loads", "J"), ("balance", "J")]
    total = sim.kinetic + sim.potential - sim.work_drive - sim.work_friction - sim.work_loads
    rows = [(sim.t[i], sim.kinetic[i], sim.potential[i], sim.work_drive[i], sim.work_friction[i],
             sim.work_loads[i], total[i] - total[0]) for i in range(len(sim.t))]
    return headers, rows


def _pin_forces(sim: Any) -> tuple[list[tuple[str, str]], Headers, list[tuple[Any, ...]]]:
    """The pins (joint, body) and the input and pin forces at every time ("undefined" where
    the kinetostatics has none)."""
    first = next((f for f in sim.forces if f is not None and f.input is not None), None)
    pins = [(p.joint, p.on) for p in first.pins] if first is not None else []
    headers = [("t", "s"), ("input", sim.input_unit), ("status", "")]
    for j, on in pins:
        headers += [(f"{j}_on_{on}_fx", "N"), (f"{j}_on_{on}_fy", "N")]
    rows = []
    for i, f in enumerate(sim.forces):
        if f is None or f.input is None:
            rows.append((sim.t[i], None, "undefined", *([None] * 2 * len(pins))))
            continue
        rows.append((sim.t[i], f.input, f.status, *(v for p in f.pins for v in (p.fx, p.fy))))
    return pins, headers, rows


def _force_blocks(sim: Any, pins: list[tuple[str, str]], force_rows: list[tuple[Any, ...]],
                  digits: int) -> list[Block]:
    """The pin forces' magnitudes as the terminal shows them."""
    rows = [(r[0], r[1], *(None if r[3 + 2 * k] is None else math.hypot(r[3 + 2 * k], r[4 + 2 * k])
                           for k in range(len(pins)))) for r in force_rows]
    head = ["t (s)", f"input ({sim.input_unit})", *(f"|{j} on {on}| (N)" for j, on in pins)]
    out: list[Block] = [table("pin forces (kinetostatic, at the simulated motion)", head, rows, digits)]
    if sim.flywheel:
        out.append(Text(f"(input: what the links need; the drive also turns the flywheel, "
                        f"{fmt(sim.flywheel, 4)} kg m^2 x the acceleration)"))
    out.append(Text(""))
    return out


def _lines(sim: Any, checks: SimulationChecks, digits: int) -> list[str]:
    """The checks, the flywheel, the integrator and the event, one line each."""
    verdict = {True: "within", False: "BEYOND"}
    out = [f"energy balance: {verdict[checks.energy_ok]} {checks.energy_tol:.2g} (kinetic + potential - "
           f"work moves by {sim.balance:.2g} of the largest energy)" if checks.energy_ok is not None else
           "energy balance: nothing to compare (one output time)",
           f"kinetostatic check: {verdict[checks.drive_ok]} {checks.drive_tol:.2g} (the matrix method's "
           f"input differs from the drive by {sim.drive_check:.2g} of the equation's terms)"
           if checks.drive_ok is not None else
           "kinetostatic check: nothing to check (no output time has forces)"]
    c = sim.cycle
    if sim.sliding:
        out.append("flywheel: a sliding driver has no turn to size one for")
    elif c is None:
        out.append("flywheel: no full turn of the driver at the end of the span (no cycle to size for)")
    else:
        out.append(f"last full turn, t = {fmt(c.start, 6)} to {fmt(c.end, 6)} s: speed "
                   f"{fmt(c.omega_min, 6)} to {fmt(c.omega_max, 6)} rad/s, "
                   f"mean {fmt(c.omega_mean, 6)} rad/s; "
                   f"Cs = {fmt(c.cs, 4)}" + ("" if c.steady else " (not steady: the turn before had "
                                             "another mean speed, or there was none)"))
        # an estimate: three digits
        target = checks.target_cs
        out.append(f"flywheel for Cs = {target:g}: about {fmt(c.flywheel_for(target), 3)} kg m^2 "
                   f"(kinetic energy swing {fmt(c.energy_swing, 3)} J over the turn)")
    out.append(f"integrator: DOP853, {sim.nfev} evaluations")
    if sim.beyond_rates:
        from ..arguments import MAX_RATE

        out.append(f"forces undefined at {sim.beyond_rates} of {len(sim.t)} output times: the speed or "
                   f"acceleration there is beyond {MAX_RATE:g} per s (the kinetostatic solver's range)")
    if sim.event is not None:
        out.append(f"event: {sim.event} at t = {fmt(sim.event_time, digits)} s: {sim.message}")
    return out


def _document(sim: Any, title: str, checks: SimulationChecks) -> dict[str, Any]:
    """The json document's summary."""
    c = sim.cycle
    return {"title": title, "event": sim.event, "event_time": sim.event_time, "message": sim.message,
            "forces_beyond_rates": sim.beyond_rates,
            "energy_balance": sim.balance, "energy_ok": checks.energy_ok, "drive_check": sim.drive_check,
            "drive_ok": checks.drive_ok, "evaluations": sim.nfev,
            "cycle": None if c is None else {"start": c.start, "end": c.end, "omega_min": c.omega_min,
                                             "omega_max": c.omega_max, "omega_mean": c.omega_mean,
                                             "cs": c.cs, "energy_swing": c.energy_swing,
                                             "flywheel_for_target": c.flywheel_for(checks.target_cs),
                                             "steady": c.steady,
                                             "target_cs": checks.target_cs}}


def simulate_plot(sim: Any, mechanism: Any, path: Path) -> None:
    """The driver's angle (or slide) and speed against time, the event marked."""
    from .plots import pyplot, save_figure

    plt = pyplot()
    dcols, dk = _driver_columns(sim, mechanism.driver.name, mechanism.length_unit)
    fig, (ax1, ax2) = plt.subplots(2, 1, sharex=True, figsize=(7, 5.5))
    t, theta, omega = sim.trace
    # a run that stopped at its start is one point: drawn as a dot (a line of it shows nothing)
    dot = "o" if len(sim.t) == 1 else None
    ax1.plot(t[:1] if dot else t, (theta * dk[0])[:1] if dot else theta * dk[0], color="tab:blue", marker=dot)
    ax1.set_ylabel(f"{dcols[0][0]} ({dcols[0][1]})")
    ax2.plot(t[:1] if dot else t, (omega * dk[1])[:1] if dot else omega * dk[1], color="tab:red", marker=dot)
    ax2.set_ylabel(f"{dcols[1][0]} ({dcols[1][1]})")
    ax2.set_xlabel("t (s)")
    c = sim.cycle
    if c is not None:
        ax2.axvspan(c.start, c.end, color="0.9", zorder=0, label=f"last full turn: Cs = {c.cs:.3g}")
        ax2.legend(loc="best", fontsize=8)
    if sim.event is not None:
        for ax in (ax1, ax2):
            ax.axvline(sim.event_time, color="k", linestyle="--", linewidth=0.8)
        ax1.set_title(f"{mechanism.name}: {sim.event} at t = {sim.event_time:.6g} s", fontsize=10)
    else:
        ax1.set_title(f"{mechanism.name}: forward dynamics", fontsize=10)
    for ax in (ax1, ax2):
        ax.grid(True, alpha=0.3)
    save_figure(fig, path)

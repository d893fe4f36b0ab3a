"""What a sweep returns (a :class:`Position` per driver value, a :class:`SweepResult`)
and the driver values it runs over, shared by every sweep engine."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import field
from typing import Any

from ..errors import InputError
from ..problems.loops import Mechanism, magnitude_problem
from ..records import frozen
from ..rules import GRID_RESOLUTION, grid_resolved
from ..units import RAD_PER_DEG


@frozen
class Position:
    input: float
    status: str  # "converged", "no_solution", "off_branch" or "failed"
    solution: dict[str, float] | None
    branch: str | None
    iterations: int
    det: float | None
    transmission: float | None = None
    substeps: int = 0
    note: str = ""
    rates: Any = None
    """The joints (and with a driver speed, the velocities and accelerations) here: a
    :class:`~linkage.kinematics.rates.Rates`, or None where unsolved."""


@frozen
class SweepResult:
    mechanism: str
    driver: str
    driver_unit: str
    names: tuple[str, ...]
    units: tuple[str, ...]
    positions: Sequence[Position]
    """Every position in driver order (a tuple, or built lazily for a batch sweep)."""
    feasible_ranges: tuple[tuple[float, float], ...]
    toggles: tuple[float, ...]
    branch: str | None
    classification: dict[str, Any] = field(default_factory=dict)
    method: str = "newton"
    motion: tuple[float, float] | None = None
    """The driver's (speed, acceleration) in internal units when rates were asked for."""
    length_unit: str = ""
    meetings: Sequence[float] = ()
    """The driver values (display units) of solved positions where two assemblies of the
    followed branch meet to rounding (a change point, s + l = p + q, or a limit exactly on
    the grid): there the branch is a matter of rounding, and each such position says so in
    its note (:data:`~.stepwise.MEETS_NOTE`). A tuple, or for a batch sweep one computed
    when first read (:class:`~.batch.BatchMeetings`, equal to the tuple)."""
    branch_note: str = ""
    """Why the followed branch is a matter of rounding, where it is (the file's pose is
    where its assemblies meet: :data:`~.pose.POSE_MEETS`); "" otherwise."""
    forces: tuple[Any, ...] | None = None
    """With loads (``sweep(..., loads=...)``): each position's
    :class:`~linkage.kinematics.forces.Forces`, None where unsolved."""

    @property
    def inputs(self) -> list[float]:
        """Every position's driver value, without building the positions (a batch sweep
        builds each one read, its rates with it)."""
        batch = getattr(self.positions, "batch", None)
        return [float(v) for v in batch.values] if batch is not None else [p.input for p in self.positions]

    def force_columns(self) -> dict[str, list[Any]]:
        """The loads as columns, one entry per position (SI units; None where there is no
        number): status, input (N m, or N for a sliding driver), virtual_power_input,
        max_pin_force, ground_fx, ground_fy, ground_moment, mechanical_advantage (None where
        it is not one number: kinematics.forces.mechanical_advantage), condition, each pin force as
        ``<joint>_on_<link>_fx`` and ``_fy``, and each slider's ``<slider>_normal`` (N, on the
        slider along its line's left normal) and ``_couple`` (N m). A flagged position (near_toggle,
        ill_conditioned) keeps its numbers beside its status; read the status first."""
        if self.forces is None:
            raise ValueError("this sweep has no loads: sweep(..., loads=...)")
        keys = ("input", "virtual_power_input", "max_pin_force", "ground_fx", "ground_fy", "ground_moment",
                "mechanical_advantage", "condition")
        out: dict[str, list[Any]] = {"status": [], **{k: [] for k in keys}}
        pins = dict.fromkeys([f"{p.joint}_on_{p.on}_{c}" for f in self.forces if f is not None
                              for p in f.pins for c in ("fx", "fy")]
                             + [f"{s.slider}_{c}" for f in self.forces if f is not None
                                for s in f.sliders for c in ("normal", "couple")])
        out.update({k: [] for k in pins})
        for f in self.forces:
            number = f is not None and f.status != "undefined"
            out["status"].append("unsolved" if f is None else f.status)
            vals = (f.input, f.virtual_power_input, f.max_pin_force, *f.ground_force, f.ground_moment,
                    f.mechanical_advantage, f.condition) if number else (None,) * len(keys)
            for k, v in zip(keys, vals):
                out[k].append(v)
            have = {f"{p.joint}_on_{p.on}_{c}": v for p in f.pins for c, v in (("fx", p.fx), ("fy", p.fy))
                    } if number else {}
            if number:
                have.update({f"{s.slider}_{c}": v for s in f.sliders
                             for c, v in (("normal", s.normal), ("couple", s.couple))})
            for k in pins:
                out[k].append(have.get(k))
        return out

    @property
    def summary(self) -> dict[str, int]:
        if hasattr(self.positions, "summary"):
            return self.positions.summary()  # type: ignore[no-any-return]
        out: dict[str, int] = {}
        for p in self.positions:
            out[p.status] = out.get(p.status, 0) + 1
        return out

    def column(self, name: str) -> Any:
        """One unknown over every position (display units; None or NaN where unsolved)."""
        if hasattr(self.positions, "column"):
            return self.positions.column(name)
        return [p.solution[name] if p.solution else None for p in self.positions]


_new = object.__new__


def converged_position(v: float, sol: dict[str, float], branch: str, iterations: int, det: float,
               transmission: float | None) -> Position:
    """``Position(v, "converged", ...)`` for the hot loop, without the frozen dataclass's
    ``__init__``, which sets each of its ten fields through ``object.__setattr__`` (1.5 us
    against 0.6 us; a sweep makes one per position). tests/test_compile.py checks that
    both give equal positions and that the fields are still these."""
    p = _new(Position)
    p.__dict__.update(input=v, status="converged", solution=sol, branch=branch, iterations=iterations,
                      det=det, transmission=transmission, substeps=0, note="", rates=None)
    return p


def with_position_rates(p: Position, rates: Any) -> Position:
    """``dataclasses.replace(p, rates=rates)`` without its ``__init__`` (as
    :func:`converged_position`; a sweep with rates makes one per position)."""
    out = _new(Position)
    out.__dict__.update(p.__dict__, rates=rates)
    return out


def sweep_result(mechanism: str, driver: str, driver_unit: str, names: tuple[str, ...],
                 units: tuple[str, ...], positions: Sequence[Position],
                 feasible_ranges: tuple[tuple[float, float], ...], toggles: tuple[float, ...],
                 branch: str | None, classification: dict[str, Any], method: str,
                 motion: tuple[float, float] | None, length_unit: str,
                 meetings: Sequence[float]) -> SweepResult:
    """``SweepResult(...)`` of these fields (no branch note, no forces) without the frozen
    dataclass's ``__init__``, which sets its sixteen fields through ``object.__setattr__``
    (as :func:`converged_position`; a closed-form sweep makes two per call, and
    ``benchmarks/sweep_floor.py --positions 3`` measures that fixed cost).
    tests/test_sweep_fixed_cost.py checks that both give equal results and that the fields are
    still these."""
    out = _new(SweepResult)
    out.__dict__.update(mechanism=mechanism, driver=driver, driver_unit=driver_unit, names=names, units=units,
                        positions=positions, feasible_ranges=feasible_ranges, toggles=toggles, branch=branch,
                        classification=classification, method=method, motion=motion,
                        length_unit=length_unit, meetings=meetings, branch_note="", forces=None)
    return out


MAX_POSITIONS = 2_000_000
"""The most positions one sweep may ask for (the batch engine holds them all in memory)."""


def check_driver_values(m: Mechanism, values: Sequence[float]) -> list[float]:
    """The values as floats, or InputError: too many, not finite, or beyond what the
    driver's kind can represent (see :func:`~linkage.problems.loops.magnitude_problem`)."""
    if len(values) > MAX_POSITIONS:
        raise InputError(f"{len(values):,} driver values is more than {MAX_POSITIONS:,}; sweep in parts")
    out = [float(v) for v in values]
    if not out:
        return out
    lo, hi = min(out), max(out)
    scale = RAD_PER_DEG if m.driver.kind == "angle" else 1.0
    for v in (lo, hi):
        why = magnitude_problem(v * scale, m.driver.kind, m.length_unit) if math.isfinite(v) else \
            "the driver values must be finite"
        if why:
            raise InputError(f"driver {m.driver.name}: {why}")
    return out


def driver_values(start: float, stop: float, step: float | None, points: int | None,
                  array_above: int | None = None) -> Any:
    """The driver values of a sweep: start, start + step, ... <= stop, or ``points`` evenly;
    a list, or a numpy array of the same values (each the same operations, IEEE-rounded
    alike) where there are more than ``array_above`` of them: a 360,001-position sweep,
    which runs on numpy anyway, then builds no list of floats to convert (about 25 ms).

    Refuses (InputError) more than MAX_POSITIONS values, and ranges whose values double
    precision cannot tell apart at that spacing (``--from 1e26 --step 1``)."""
    from ..errors import InputError

    for name, v in (("--from", start), ("--to", stop)):
        if not math.isfinite(v):
            raise InputError(f"{name} must be finite, got {v!r}")
    if points is not None:
        if points < 1:
            raise InputError(f"--points must be >= 1, got {points}")
        if points > MAX_POSITIONS:
            raise InputError(f"--points {points} is more than {MAX_POSITIONS:,} positions; "
                             "sweep in parts or use fewer points")
        spacing = (stop - start) / (points - 1) if points > 1 else math.inf
    else:
        assert step is not None
        if not (math.isfinite(step) and step > 0.0):
            raise InputError(f"--step must be > 0 and finite, got {step!r}")
        count = (stop - start) / step
        if count + 1 > MAX_POSITIONS:
            raise InputError(f"--from {start:g} --to {stop:g} --step {step:g} is more than "
                             f"{MAX_POSITIONS:,} positions; use a larger --step")
        spacing = step
    resolved, ulp = grid_resolved(start, stop, spacing)
    if points != 1 and not resolved:
        raise InputError(f"--from {start:g} and --to {stop:g} are too large for a spacing of "
                         f"{spacing:g}: it must be at least {GRID_RESOLUTION * ulp:.3g} there, "
                         f"{GRID_RESOLUTION:,.0f} times the {ulp:.3g} between doubles (so that rounding "
                         f"moves each value by at most 1/{GRID_RESOLUTION:,.0f} of the spacing)")
    if points is not None:
        if points == 1:
            return [start]
        if not math.isfinite((stop - start) * (points - 1)):  # a span near the largest double: the
            # usual order's product overflows; these values are refused by the driver's own bound next
            return [start * (1.0 - k / (points - 1)) + stop * (k / (points - 1)) for k in range(points)]
        if array_above is not None and points > array_above:
            import numpy as np

            return start + (stop - start) * np.arange(points, dtype=np.float64) / (points - 1)
        return [start + (stop - start) * k / (points - 1) for k in range(points)]
    n = math.floor((stop - start) / step + 1e-9)
    if array_above is not None and n + 1 > array_above:
        import numpy as np

        return start + np.arange(n + 1, dtype=np.float64) * step
    return [start + k * step for k in range(n + 1)]


def check_assembles_somewhere(summary: dict[str, int], what: str, span: Callable[[], str]) -> None:
    """InputError where no position of a sweep assembles, every one ``no_solution`` (the
    closed form has no real solution there, or least squares cannot close the loops:
    docs/sweeps.md, "Statuses"): a linkage that cannot be assembled anywhere in the range
    asked for is bad input, as ``centres`` and ``convert`` refuse it at one value. A sweep
    where some position assembles keeps its ``no_solution`` rows. ``summary``: the count
    of each status; ``what`` names the linkage, ``span()`` the driver range (text made
    only for a refusal: reading a batch sweep's inputs costs more than its count)."""
    if summary and set(summary) == {"no_solution"}:
        n = summary["no_solution"]
        raise InputError(f"{what}: cannot be assembled at any {span()} (no_solution at every one of "
                         f"its {n} position{'s' if n != 1 else ''})")


def driver_range_text(result: SweepResult) -> str:
    """The driver range of a sweep's positions, as a refusal names it (display units)."""
    inputs = result.inputs
    return span_text(result.driver, min(inputs), max(inputs), result.driver_unit)


def span_text(driver: str, low: float, high: float, unit: str) -> str:
    """A driver range as a refusal names it: "theta2 from 150 to 200 deg"."""
    return f"{driver} from {low:.12g} to {high:.12g}{f' {unit}' if unit else ''}"

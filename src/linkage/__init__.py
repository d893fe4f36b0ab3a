"""linkage: position analysis of planar mechanisms by numerical root finding.

The public API, in the order a reader meets it:

- :func:`solve_scalar` solves one equation in one unknown with a named method and
  returns a :class:`Result` (status, root, iterations, evaluations, history).
- :func:`fourbar_equation` and :func:`equation_problem` build the problems it solves.
- :func:`solve_system` solves loop-closure systems; :func:`load_mechanism` reads a
  mechanism file whose ``.problem()`` it takes.
- :func:`sweep` solves a mechanism over a range of its driver (a :class:`SweepResult`);
  :func:`position_rates` gives joints, velocities and accelerations at one solution.
- :func:`scan_designs` runs many designs of a mechanism over their cycles: one record each.
- :func:`synthesize_function` designs a four-bar function generator (Freudenstein).
- :func:`assemblies` finds every assembly of a mechanism at a driver value (homotopy continuation).
- :func:`forces` gives the input torque and joint forces of a joints-form mechanism at a position.
- :func:`instant_centres` gives every instant centre of a mechanism at a pose, :func:`centrodes`
  the fixed and moving centrodes of a body over a sweep.
- :func:`tolerance` spreads manufacturing tolerances through a mechanism over its cycle:
  linear worst-case and RSS bands beside a Monte Carlo (a :class:`ToleranceStudy`).
- :func:`simulate` integrates a mechanism's motion under a drive, its loads, gravity and friction.
- :func:`analyze` estimates convergence order and rate from a recorded history.
"""

from importlib import import_module
from typing import Any

from .version import __version__ as __version__

_EXPORTS = {
    "Convergence": ".analysis.convergence", "analyze": ".analysis.convergence",
    "InputError": ".errors", "LinkageError": ".errors", "NotConvergedError": ".errors",
    "ParseError": ".errors",
    "equation_problem": ".problems.expression",
    "coefficients_from_links": ".problems.freudenstein", "fourbar_equation": ".problems.freudenstein",
    "ScalarProblem": ".problems.scalar",
    "History": ".result", "IterationRecord": ".result", "Result": ".result", "Status": ".result",
    "Mechanism": ".problems.loops", "load_mechanism": ".kinematics.loading",
    "SystemProblem": ".problems.system",
    "solve_scalar": ".solve", "solve_system": ".solve",
    "sweep": ".kinematics.sweep", "SweepResult": ".kinematics.sweep", "Position": ".kinematics.sweep",
    "position_rates": ".kinematics.rates", "Rates": ".kinematics.rates",
    "scan_designs": ".scan",
    "synthesize_function": ".synthesis", "FunctionSynthesis": ".synthesis",
    "synthesize_motion": ".synthesis.motion", "MotionSynthesis": ".synthesis.motion",
    "synthesize_path": ".synthesis.path", "PathSynthesis": ".synthesis.path",
    "search_path": ".synthesis.path_search", "PathSearch": ".synthesis.path_search",
    "forces": ".kinematics.forces", "Forces": ".kinematics.forces",
    "assemblies": ".kinematics.assemblies", "Assemblies": ".kinematics.assemblies",
    "Loads": ".problems.loads", "Mass": ".problems.loads",
    "instant_centres": ".kinematics.centres", "InstantCentres": ".kinematics.centres",
    "centrodes": ".kinematics.centrodes", "Centrodes": ".kinematics.centrodes",
    "tolerance": ".scan.tolerance", "ToleranceStudy": ".scan.tolerance",
    "simulate": ".kinematics.simulation", "Simulation": ".kinematics.simulation",
}
_RENAMED = {"load_mechanism": "load", "sweep": "sweep_mechanism", "position_rates": "rates_at",
            "scan_designs": "scan", "forces": "forces_at", "assemblies": "every_assembly"}


def __getattr__(name: str) -> Any:
    """Import on first use, so a command pays only for the modules it runs (PEP 562)."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'linkage' has no attribute {name!r}")
    attr = _RENAMED.get(name, name)
    value = getattr(import_module(module, __name__), attr)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted([*globals(), *_EXPORTS])



__all__ = [
    "Assemblies",
    "Centrodes",
    "Convergence",
    "Forces",
    "FunctionSynthesis",
    "History",
    "InputError",
    "InstantCentres",
    "IterationRecord",
    "LinkageError",
    "Loads",
    "Mass",
    "Mechanism",
    "MotionSynthesis",
    "NotConvergedError",
    "ParseError",
    "PathSearch",
    "PathSynthesis",
    "Position",
    "Rates",
    "Result",
    "ScalarProblem",
    "Simulation",
    "Status",
    "SweepResult",
    "SystemProblem",
    "ToleranceStudy",
    "analyze",
    "assemblies",
    "centrodes",
    "coefficients_from_links",
    "equation_problem",
    "forces",
    "fourbar_equation",
    "instant_centres",
    "load_mechanism",
    "position_rates",
    "scan_designs",
    "search_path",
    "simulate",
    "solve_scalar",
    "solve_system",
    "sweep",
    "synthesize_function",
    "synthesize_motion",
    "synthesize_path",
    "tolerance",
]

"""The public API the bench measures, taken from the homes ``linkage/__init__.py`` names for
it (the package's top level is the layer above this one): when a home moves, this is the
one file to change."""

from __future__ import annotations

from ..kinematics.assemblies import every_assembly as assemblies
from ..kinematics.loading import load as load_mechanism
from ..kinematics.sweep import sweep_mechanism as sweep
from ..problems.loads import Loads
from ..scan import scan as scan_designs
from ..solve import solve_scalar, solve_system

__all__ = ["Loads", "assemblies", "load_mechanism", "scan_designs", "solve_scalar", "solve_system", "sweep"]

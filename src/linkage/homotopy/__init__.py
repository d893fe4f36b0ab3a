"""Every root of a polynomial system by homotopy continuation (numpy blocks of paths)."""

from .parameter import Family, Monodromy, monodromy, track_parameters
from .polynomials import PolySystem
from .solve import Endpoint, Solutions, condition, polish_real, solve

__all__ = ["Endpoint", "Family", "Monodromy", "PolySystem", "Solutions", "condition", "monodromy",
           "polish_real", "solve", "track_parameters"]

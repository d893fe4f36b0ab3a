"""Every root of a polynomial system by homotopy continuation (numpy blocks of paths)."""

from .polynomials import PolySystem
from .solve import Endpoint, Solutions, condition, polish_real, solve

__all__ = ["Endpoint", "PolySystem", "Solutions", "condition", "polish_real", "solve"]

"""Every root of a polynomial system by homotopy continuation (numpy blocks of paths)."""

from .polynomials import PolySystem
from .solve import Endpoint, Solutions, condition, solve

__all__ = ["Endpoint", "PolySystem", "Solutions", "condition", "solve"]

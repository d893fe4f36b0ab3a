"""Solving: one equation (:mod:`.scalar`) or a system (:mod:`.system`), each validated
once at its front door; the stopping criteria (:mod:`.criteria`), the root certificate
(:mod:`.certificate`) and the naming of a bad user function (:mod:`.diagnose`)."""

from .certificate import certify_root
from .criteria import MAX_RELATIVE_TOL, check_criteria
from .scalar import solve_scalar
from .system import SYSTEM_METHODS, nearest_branch, solve_system, system_verdict

__all__ = ["MAX_RELATIVE_TOL", "SYSTEM_METHODS", "certify_root", "check_criteria", "nearest_branch",
           "solve_scalar", "solve_system", "system_verdict"]

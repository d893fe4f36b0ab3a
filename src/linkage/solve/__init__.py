"""Solving: one equation (:mod:`.scalar`) or a system (:mod:`.system`), each validated
once at its front door; the stopping criteria (:mod:`.criteria`), the root certificate
(:mod:`.certificate`) and the naming of a bad user function (:mod:`.diagnose`)."""

from typing import Any

from .criteria import MAX_RELATIVE_TOL, check_criteria
from .system import SYSTEM_METHODS, nearest_branch, solve_system, system_verdict


def __getattr__(name: str) -> Any:
    """The scalar solve and its certificate, imported on first use: a sweep reads the
    criteria and the system solve, and a cold ``linkage sweep`` does not load them (nor
    the scalar problem type)."""
    if name == "solve_scalar":
        from .scalar import solve_scalar

        return solve_scalar
    if name == "certify_root":
        from .certificate import certify_root

        return certify_root
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    """The module's names with the two imported on first use (PEP 562), as ``dir`` and a
    completing shell list them."""
    return sorted({*globals(), *__all__})


__all__ = ["MAX_RELATIVE_TOL", "SYSTEM_METHODS", "certify_root", "check_criteria", "nearest_branch",
           "solve_scalar", "solve_system", "system_verdict"]

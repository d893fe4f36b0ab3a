"""The seed's equation from command-line values: the four-bar input-output equation with
R1, R2, R3 (or link lengths) given as text, or any equation in x; both roots in closed
form; which scalar methods a run can start."""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..numbers import parse_number


def fourbar_coefficients(r1: str | None, r2: str | None, r3: str | None,
                          links: tuple[str, ...] | None) -> tuple[tuple[float, float, float], Any]:
    """(R1, R2, R3) and the link lengths (given, or derived for a unit ground)."""
    from .freudenstein import SEED_R, coefficients_from_links, links_of

    if links is not None:
        if any(v is not None for v in (r1, r2, r3)):
            raise InputError("give either --links or --r1/--r2/--r3, not both")
        lengths = tuple(parse_number(f"link {n}", t) for n, t in zip("abcd", links))
        c = coefficients_from_links(*lengths)
        return (c.r1, c.r2, c.r3), lengths
    rs = tuple(parse_number(n, t) if t is not None else d
               for n, t, d in (("R1", r1, SEED_R[0]), ("R2", r2, SEED_R[1]), ("R3", r3, SEED_R[2])))
    return rs, links_of(*rs)  # type: ignore[arg-type]


def fourbar_info(alpha: float | None, r1: str | None, r2: str | None, r3: str | None,
                  links: tuple[str, ...] | None, result: Any) -> dict[str, Any]:
    """Both roots in closed form, and the answer in the mechanism-file convention."""
    from .freudenstein import equation_roots, file_convention

    a = 70.0 if alpha is None else alpha
    rs, lengths = fourbar_coefficients(r1, r2, r3, links)
    roots = equation_roots(a, *rs)
    info: dict[str, Any] = {"alpha": a, "R": list(rs), "roots": roots,
                            "links": list(lengths) if lengths else None, "file_convention": None}
    if lengths and result.converged:
        info["file_convention"] = file_convention(a, result.x, lengths)
        others = [r for r in roots if abs(((r - result.x) + 180.0) % 360.0 - 180.0) > 1e-6]
        info["other_assembly"] = file_convention(a, others[0], lengths) if others else None
    return info


def scalar_problem(equation: str | None, g: str | None, alpha: float | None, r1: str | None,
                    r2: str | None, r3: str | None, links: tuple[str, ...] | None,
                    refuse_unassembled: bool = False) -> Any:
    """The equation's problem, or the four-bar's at ``alpha``; ``refuse_unassembled``: an
    InputError where that four-bar cannot be assembled (:func:`check_assembles`; ``solve``
    refuses it, a sweep over alpha reports the position)."""
    if equation is not None:
        given = [n for n, v in (("--alpha", alpha), ("--r1", r1), ("--r2", r2), ("--r3", r3),
                                ("--links", links)) if v is not None]
        if given:
            raise InputError(f"{', '.join(given)} belong to the four-bar equation; "
                             "they cannot be combined with --equation")
        from .expression import equation_problem

        return equation_problem(equation, g)
    if g is not None:
        raise InputError("--g applies to --equation; the four-bar has its own g = acos(u)")
    from .freudenstein import fourbar_equation

    if refuse_unassembled:
        check_assembles(alpha, r1, r2, r3, links)
    rs, _ = fourbar_coefficients(r1, r2, r3, links)
    return fourbar_equation(70.0 if alpha is None else alpha, *rs)


def check_assembles(alpha: float | None, r1: str | None, r2: str | None, r3: str | None,
                    links: tuple[str, ...] | None) -> None:
    """InputError where the four-bar of these coefficients (or links) cannot be assembled at
    ``alpha`` (deg, default 70): its input-output equation has no real root there, by the
    closed form (:func:`~linkage.problems.freudenstein.equation_roots`)."""
    from .freudenstein import equation_roots

    rs, _ = fourbar_coefficients(r1, r2, r3, links)
    a = 70.0 if alpha is None else alpha
    if not equation_roots(a, *rs):
        given = (f"--links {' '.join(links)}" if links is not None
                 else f"R1 = {rs[0]:.10g}, R2 = {rs[1]:.10g}, R3 = {rs[2]:.10g}")
        raise InputError(f"{given}: the four-bar cannot be assembled at alpha = {a:g} deg (its "
                         "input-output equation has no real root there)")


def applicable(name: str, problem: Any, equation: str | None, x0: Any, x1: Any, bracket: Any) -> bool:
    if equation is None:
        return problem.guess is not None or x0 is not None or bracket is not None
    if name in ("bisection", "regula-falsi", "hybrid"):
        return bracket is not None
    if name == "secant":
        return x0 is not None and x1 is not None
    if name == "fixed-point":
        return x0 is not None and problem.g is not None
    return x0 is not None

"""A mechanism started on a named assembly: its guess replaced by the closed form's solution."""

from __future__ import annotations

from typing import Any

from ..errors import InputError


def start_on_branch(mechanism: Any, branch: str, guessed: bool) -> Any:
    """The mechanism with its guess replaced by the closed form's solution on ``branch``:
    a name at the driver's value (open, crossed, open/crossed, a rocker-driven four-bar's
    second assembly of one name 'open (mirror)') or the signs of the two-way steps (+-),
    as :meth:`~linkage.problems.derive.Derivation.branch_signs` reads them."""
    from .derive import Indeterminate, read_branch, sign_text
    from .loops import ANGLE_UNITS

    if guessed:
        raise InputError("give --branch or --guess, not both")
    derivation = mechanism.derivation
    refusal = derivation.branch_refusal(mechanism.source)
    if refusal:
        hint = "" if derivation.complete else "; choose its assembly with --guess"
        raise InputError(refusal + hint)
    driver = mechanism.driver.value
    at = f"{mechanism.driver.name} = {mechanism.problem().meta['driver_value']:g} {mechanism.driver.unit}"
    try:
        try:
            signs = derivation.branch_signs(branch, driver)
        except Indeterminate:
            raise
        except ValueError:
            signs = None
        q = derivation.solve(driver, signs) if signs is not None else None
        if q is None:
            named = derivation.named_solutions(driver)
    except Indeterminate as exc:
        raise InputError(f"--branch: the closed form is indeterminate at {at} (a change point: {exc}); "
                         "give --guess instead") from None
    if q is None:
        what = f"{branch!r}"
        if signs is not None and branch != sign_text(signs):
            what += f" ({sign_text(signs)})"
        there = (f"assemblies: {', '.join(named)}; or their signs, one per closed-form step with two roots: "
                 f"{', '.join(sign_text(s) for s, _ in named.values())}" if named else
                 "assemblies: none: it cannot be assembled there")
        try:
            read_branch(derivation, branch)
        except ValueError:
            # not a name or sign string of this mechanism at all: not "no such assembly here"
            raise InputError(f"--branch {what} is not a branch of this mechanism "
                             f"(at {at}, {there})") from None
        raise InputError(f"--branch {what}: no such assembly at {at} ({there})")
    return mechanism.with_values({}, {u.name: v / ANGLE_UNITS[u.unit] if u.kind == "angle" else v
                                      for u, v in zip(mechanism.unknowns, q)})

"""Whole-cycle sweeps, the public API (``linkage.sweep``): checks the arguments once,
chooses the engine (one at a time, :mod:`.stepwise`; or the numpy batch, :mod:`.batch`)
and adds joints and rates (:mod:`.rates`) where asked.

The layout: :mod:`.positions` (the result types and driver values), :mod:`.continuation`
(one position from the last), :mod:`.limits` (limits, toggles, solved ranges),
:mod:`.angles` (the range and unwrapping rule), :mod:`.stepwise` and :mod:`.batch` (the
engines), :mod:`.designs` (many designs at once, for scans).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..arguments import check_callable, check_flag, check_method, check_motion, check_reals, check_text
from ..errors import InputError
from ..problems.loops import Mechanism
from ..solve import SYSTEM_METHODS, check_criteria
from .pose import POSE_MEETS, file_branch, pose_meets, step_words
from .positions import MAX_POSITIONS, Position, SweepResult, check_driver_values, driver_values
from .stepwise import sweep

BATCH_ABOVE = 20_000
"""Sweeps of more positions than this run on the batch engine (numpy) by default."""


def sweep_mechanism(
    mechanism: Mechanism | str | Any,
    values: Sequence[float] | Any,
    *,
    branch: str | None = None,
    method: str = "newton",
    tol: float = 1e-12,
    max_iter: int = 50,
    batch: bool | None = None,
    progress: Callable[[int], None] | None = None,
    speed: float | None = None,
    accel: float = 0.0,
    joints: bool = False,
    loads: Any = None,
) -> SweepResult:
    """Solve a mechanism over driver values (display units: degrees for an angle), each
    position from the previous one; the public ``linkage.sweep``.

    ``mechanism``: a :class:`~linkage.problems.loops.Mechanism` or a path to a file.
    ``values``: a list or a numpy array. ``branch``: for a mechanism whose loops have a
    derived closed form, a branch name (``open``, ``crossed``; ``open/crossed`` for two
    four-bar loops; ``open (mirror)``) or its signs (``+-``: one per two-way step); else
    the assembly of the file's pose (its guesses solved at its driver value: a drawing's
    drawn pose, :func:`file_branch`), wherever the values start. More than
    ``BATCH_ABOVE`` values with Newton go
    through the numpy batch engine; fewer, of a mechanism whose loops solve stepwise in
    closed form, on one branch with no limit position inside, through the closed-form
    engine (:mod:`.closed`). Both results keep columns and build a position only when one
    is read. ``batch`` forces the choice: True the batch engine, False the one-at-a-time
    engine.

    Each position has ``.input``, ``.status`` ("converged", "no_solution", "off_branch",
    "failed"), ``.solution`` (unknown name -> value, display units), ``.branch``,
    ``.iterations`` and ``.det``; ``result.column(name)`` gives one unknown throughout.
    With a driver ``speed`` (rad/s, or length unit/s for a linear driver) and ``accel``, or
    with ``joints=True``, every solved position also has ``.rates``: its joints and named
    points and, with a speed, the velocity and acceleration of every unknown, joint and
    point (:class:`~linkage.kinematics.rates.Rates`; a batch sweep computes it as positions
    are read). Without them the sweep does not pay for it. ``speed`` and ``accel`` are
    numbers in those internal units; a unit string such as "10rpm" is the command line's,
    and is refused here. ``values`` must be finite reals in a sequence (not a generator).
    Every argument is checked first (:mod:`linkage.arguments`): a misuse raises
    :class:`~linkage.errors.InputError` naming the argument.

    ``loads``: a :class:`~linkage.Loads` (a joints-form mechanism; its own are
    ``mechanism.extra["loads"]``, which a Loads given replaces): every solved position's
    forces by the matrix method at the driver's ``speed`` and ``accel`` (static without
    them), as ``result.forces`` (a :class:`~linkage.Forces` or None per position) and
    ``result.force_columns()``.
    """
    # the front door: every argument checked once, InputError naming it
    if isinstance(mechanism, Mechanism):
        m = mechanism
    else:  # a path (or a misuse): loading's modules only then
        from .loading import mechanism_of

        m = mechanism_of("mechanism", mechanism)
    values = check_reals("values", values, most=MAX_POSITIONS, keep_array=True)
    check_criteria(tol, 0.0, None, max_iter)
    check_text("branch", branch)
    check_callable("progress", progress)
    check_flag("joints", joints)
    if batch is not None:
        check_flag("batch", batch)
    speed, accel = check_motion(speed, accel, m.driver.kind, m.length_unit)
    check_method("method", method, SYSTEM_METHODS, "for a mechanism")
    if loads is not None:  # the sweep, then its forces (kinematics.forces)
        from .bodies import checked_loads
        from .force_sweeps import with_forces

        loads = checked_loads(loads, m)
        return with_forces(m, sweep_mechanism(m, values, branch=branch, method=method, tol=tol,
                                              max_iter=max_iter, batch=batch, progress=progress,
                                              speed=speed, accel=accel, joints=joints), loads, speed, accel)
    if branch is not None:
        check_branch(m, branch)
    elif pose_meets(m):
        # the file's pose is where its assemblies meet: the branch its guesses solve to
        # there is a matter of rounding, followed, and said so
        from dataclasses import replace

        result = sweep_mechanism(m, values, branch=file_branch(m), method=method, tol=tol,
                                 max_iter=max_iter, batch=batch, progress=progress, speed=speed,
                                 accel=accel, joints=joints)
        return replace(result, branch_note=POSE_MEETS)
    else:
        branch = file_branch(m)
    n = len(values)
    use_batch = batch if batch is not None else (n > BATCH_ABOVE and method == "newton")
    if use_batch:
        if method != "newton":
            raise InputError("--batch runs Newton-Raphson; drop --method or --batch")
        from dataclasses import replace

        from .batch import batch_sweep
        from .closed import closed_sweep  # the coarse pass by the closed form, where it applies

        return replace(batch_sweep(m, values, branch=branch, tol=tol, max_iter=max_iter, speed=speed,
                                   accel=accel, joints=joints, coarse_engine=closed_sweep).to_sweep(),
                       method="newton (batch)")
    if batch is None and method == "newton" and n:
        # a dyadic mechanism on one branch: its closed form at every position at once
        # (kinematics/closed.py), where it applies; otherwise the engines below, unchanged
        from .closed import closed_sweep

        fast = closed_sweep(m, values, branch=branch, tol=tol, max_iter=max_iter, speed=speed,
                            accel=accel, joints=joints)
        if fast is not None:
            if progress is not None:
                progress(n)
            return fast.to_sweep()
    result = sweep(m, check_driver_values(m, values), method=method, branch=branch, tol=tol,
                   max_iter=max_iter, progress=progress)
    if speed is None and not joints:
        return result
    from .rate_blocks import with_rates  # here: a sweep without rates does not load them

    return with_rates(m, result, speed, accel)


def branch_choices(m: Mechanism) -> list[str]:
    """Every name a branch of ``m``'s derived closed form can carry: each two-way step's
    words (open/crossed for a four-bar or slider-crank loop, + or - otherwise) joined by
    "/", each also as its ``(mirror)``; and the sign strings."""
    import itertools

    from ..problems.derive import MIRROR, sign_text

    d = m.derivation
    names = ["/".join(w) for w in itertools.product(*step_words(m))]
    signs = [sign_text(b) for b in d.branches]
    return [*names, *(n + MIRROR for n in names), *(s for s in signs if s not in names)]


def check_branch(m: Mechanism, branch: str) -> None:
    """InputError naming ``branch`` unless it is a name or sign string of ``m``'s derived
    closed form (:func:`branch_choices`)."""
    from ..problems.derive import sign_text

    refusal = m.derivation.branch_refusal(m.source)
    if refusal:
        raise InputError(f"{refusal}; its sweep follows the assembly of the file's guesses "
                         "(change them under [unknowns] to follow another)")
    choices = branch_choices(m)
    if branch not in choices:
        names = choices[:len(m.derivation.branches)]
        main = ", ".join(names[:-1]) + " or " + names[-1] if len(names) > 1 else names[0]
        signs = [sign_text(b) for b in m.derivation.branches]
        # the signs and the (mirror) rule once each, not every name twice over
        also = ("" if signs == names else
                f", or their signs {', '.join(signs)} (one per closed-form step with two roots)")
        raise InputError(f"--branch must be {main}{also}; a second assembly of the same name "
                         f"is 'NAME (mirror)'; got {branch!r}")


def __getattr__(name: str) -> Any:
    if name == "with_rates":  # still importable from here, loaded when first asked for
        from .rate_blocks import with_rates

        return with_rates
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = ["BATCH_ABOVE", "MAX_POSITIONS", "POSE_MEETS", "Position", "SweepResult", "check_driver_values",
           "driver_values", "file_branch", "pose_meets", "sweep", "sweep_mechanism"]

"""The one-at-a-time sweep engine: the seed position, continuation both ways from it
(:mod:`.continuation`), the gaps, continuous angles (:mod:`.angles`), limits and toggles
(:mod:`.limits`). For a full turn, a backward pass from the start covers the end of the
cycle. The batch and design engines start from it and use the same rules."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from ..problems.closed_form import fourbar_class
from ..problems.loops import Mechanism
from .angles import anchor_index, closes_circle, continuous, driver_turn, turn_shift, unwrap_turns
from .continuation import Solver, classify_gap, follow, q_of, solve_position, solver_q
from .limits import closed_form_limits, solved_ranges, toggles
from .positions import Position, SweepResult, check_driver_values


def sweep(
    m: Mechanism,
    values: Sequence[float],
    *,
    method: str = "newton",
    branch: str | None = None,
    tol: float = 1e-12,
    max_iter: int = 50,
    progress: Callable[[int], None] | None = None,
) -> SweepResult:
    """Solve the mechanism at each driver value (display units), by continuation."""
    values = check_driver_values(m, values)
    solver = Solver(m, method, tol, max_iter)
    lo, hi = (min(values), max(values)) if values else (0.0, 0.0)
    have_closed = solver.derivation is not None
    guess0 = tuple(u.value for u in m.unknowns)
    full_turn = m.driver.kind == "angle" and bool(values) and values[-1] - values[0] >= 360.0 - 1e-9
    done: dict[int, Position] = {}
    target = follow_target(solver, values, branch)
    anchor_q = guess0
    # The seed: where the branch to follow is known. With a closed form, the first
    # position that can be assembled, on the requested branch (or the guess's);
    # otherwise the file's own driver value, whose guess names the assembly.
    seed: tuple[float, tuple[float, ...]] | None = None
    if have_closed:
        for i, v in enumerate(values):
            pos, q = solve_position(solver, v, None, None, guess0, target, True)
            done[i] = pos
            # not where two assemblies meet (a change point): no tangent there, and the
            # branch it would name is a matter of rounding
            if pos.status == "converged" and q is not None and not meets_here(solver, pos):
                seed, target = (v, q), target if target is not None else seed_target(solver, q, v)
                break
    else:
        v0 = m.driver.value / solver.scale
        p0, r0 = solver.solve(v0, guess0)
        if r0.converged:
            q0 = tuple(r0.x)
            seed = (v0, q0)
            target = solver.branch(q0, solver.det(p0, q0), v0)
    if seed is not None:
        anchor_q = seed[1]
        for i, pos in follow(solver, values, seed, target, full_turn, progress, done).items():
            done[i] = pos
    # The rest: re-entry on the same branch where a closed form names it; otherwise the
    # position is no_solution (no assembly at all) or off_branch (one not connected),
    # trying the last other assembly found first (continuation along it).
    other: tuple[float, ...] | None = None
    for j, v in enumerate(values):
        if j in done:
            continue
        prev = done.get(j - 1)
        if have_closed:
            last = (q_of(solver, prev), values[j - 1]) if prev else (None, None)
            pos, q = solve_position(solver, v, last[0], last[1], anchor_q, target, True)
        else:
            tries = [g for g in (other, anchor_q, guess0) if g is not None]
            pos, found = classify_gap(solver, v, tries)
            other = found or other
        if target is None and pos.status == "converged" and pos.solution is not None:
            target = seed_target(solver, solver_q(solver, pos), v) if have_closed else pos.branch
        done[j] = pos
        if progress is not None:
            progress(len(done))
    positions = [done[j] for j in range(len(values))]
    meetings: tuple[float, ...] = ()
    if have_closed:
        positions, meetings = _at_meetings(solver, positions, target)
    positions = _continuous_angles(solver, positions)
    limits, ranges = closed_form_limits(solver, positions, lo, hi, target) if have_closed else \
        ([], solved_ranges(positions))
    found = toggles(solver, positions, limits, lo, hi, have_closed)
    return SweepResult(m.name, m.driver.name, m.driver.unit, solver.names,
                       tuple("deg" if k == "angle" else m.length_unit for k in solver.kinds),
                       tuple(positions), ranges, tuple(found), target,
                       classification_of(m), method, length_unit=m.length_unit, meetings=meetings)


MEETS_NOTE = ("the assemblies meet here (to rounding: a change point or a limit): its branch is a "
              "matter of rounding")
EXACT_NOTE = "the closed form's configuration, on both"


def _at_meetings(solver: Solver, positions: list[Position], target: str | None
                 ) -> tuple[list[Position], tuple[float, ...]]:
    """Each solved position where two assemblies meet to rounding
    (:meth:`~linkage.problems.derive.Derivation.meets`) as the closed form gives it there,
    flagged (:data:`MEETS_NOTE`) and named by the followed branch where that is a name: at a
    double point J is singular and Newton settles only to about the square root of the
    tolerance (1e-7 deg), while the closed form's one configuration is the meeting itself
    to a few ulps; its det J is 0 (the meeting step's block is singular), not rounding's
    sign. The driver values flagged are returned with the positions."""
    from dataclasses import replace

    from ..methods.newton_system import max_abs
    from ..problems.derive import Indeterminate, parse_signs

    d = solver.derivation
    assert d is not None
    named = target is not None and parse_signs(target, solver.count) is None
    out, where = [], []
    for p in positions:
        if not meets_here(solver, p):
            out.append(p)
            continue
        drv = p.input * solver.scale
        q = solver_q(solver, p)
        # the step that meets gives one configuration for either sign; the others keep theirs
        signs = tuple(s if s != 0.0 else 1.0 for s in d.signs_of(q, drv))
        try:
            exact = d.solve(drv, signs)
        except Indeterminate:  # a change point: the step's two circles coincide, no one configuration
            exact = None
        F, _, _ = solver.compiled(p.input)
        note, det = "; ".join(n for n in (p.note, MEETS_NOTE) if n), p.det
        if exact is not None and max_abs(F(exact)) <= solver.gate:
            # the meeting step's 2 x 2 block is singular there, so J is, exactly
            q, det, note = tuple(exact), 0.0, f"{note}; {EXACT_NOTE}"
        out.append(replace(p, solution=solver.display(q), branch=target if named else p.branch, det=det,
                           transmission=solver.transmission(q, p.input), note=note))
        where.append(p.input)
    return out, tuple(where)


def follow_target(solver: Solver, values: Sequence[float], branch: str | None) -> str | None:
    """What the sweep follows for a ``branch`` text. A sweep follows signs: where each
    name is one sign branch (:attr:`~linkage.problems.derive.Derivation.names_are_signs`)
    a name and its signs are the same thing, and the branch is followed and reported by
    its name; otherwise a name (``open`` of a rocker-driven four-bar, ``open (mirror)``)
    is the signs of its assembly
    at the first driver value where the name appears (InputError where it appears nowhere)."""
    from ..errors import InputError
    from ..problems.derive import MIRROR, parse_signs, sign_text

    d = solver.derivation
    if branch is None or d is None:
        return branch
    if parse_signs(branch, solver.count) is not None and d.names_are_signs:
        # each name is one sign branch: follow (and report) it by its name
        for v in values:
            named = _named_apart(solver, v)
            if named is None:
                continue
            for name, (signs, _) in named.items():
                if sign_text(signs) == branch:
                    return name
        return branch
    if parse_signs(branch, solver.count) is not None or (
            not branch.endswith(MIRROR) and d.names_are_signs):
        return branch
    # a name that cuts across the signs (a four-bar driven by its rocker or coupler, or a
    # mirror key): the signs of its assembly where the name first appears, followed as
    # signs (the positions carry their own names); a name that appears nowhere is left as
    # it is, and every position is then off that branch
    first: tuple[float, list[str]] | None = None
    for v in values:
        named = _named_apart(solver, v)
        if named is None:
            continue
        if branch in named:
            return sign_text(named[branch][0])
        if first is None and named:
            first = (v, list(named))
    where = f"{solver.m.driver.name} = {min(values):g}..{max(values):g} {solver.m.driver.unit}"
    there = f"; at {first[0]:g}: {', '.join(first[1])}" if first else ": it assembles nowhere there"
    raise InputError(f"branch: no {branch!r} assembly anywhere in {where}{there} (or give the "
                     f"signs: one + or - per closed-form step with two roots, e.g. {'+' * solver.count})")


def _named_apart(solver: Solver, v: float) -> dict[str, Any] | None:
    """Every assembly at ``v`` (display units) keyed by its name, or None where the names
    say nothing: a change point (the closed form is indeterminate) or where two assemblies
    meet to rounding (:meth:`~linkage.problems.derive.Derivation.meets`: their one
    configuration's open/crossed is a matter of rounding)."""
    from ..problems.derive import Indeterminate

    d = solver.derivation
    assert d is not None
    drv = v * solver.scale
    try:
        named = d.named_solutions(drv)
    except Indeterminate:
        return None
    if any(any(d.meets(q, drv)) for _, q in named.values()):
        return None
    return named


def meets_here(solver: Solver, pos: Position) -> bool:
    """Whether a solved position is where two assemblies of a step meet, to rounding
    (:meth:`~linkage.problems.derive.Derivation.meets`): its branch is a matter of rounding."""
    d = solver.derivation
    return (d is not None and pos.solution is not None
            and any(d.meets(solver_q(solver, pos), pos.input * solver.scale)))


def seed_target(solver: Solver, q: Sequence[float], v: float) -> str:
    """The branch a sweep follows from its seed: the seed's name where each name is one
    sign branch, else its signs (a sweep follows signs; its positions carry their names)."""
    from ..problems.derive import sign_text

    d = solver.derivation
    assert d is not None
    if d.names_are_signs:
        return d.name_of(q, v * solver.scale)
    return sign_text(d.signs_of(q, v * solver.scale))


def classification_of(m: Mechanism) -> dict[str, Any]:
    """The Grashof class (Norton 2.8) of each loop that is a four-bar, read as written with
    the ground last: input, coupler, output (:func:`~linkage.problems.closed_form.fourbar_class`).
    One such loop: its class; several: the first's, with every loop's under ``loops``.
    Computed once per mechanism (:func:`~.pose.implied`); each caller gets its own copy."""
    from .pose import implied

    c = implied(m, "classification", _classification)
    return {k: [dict(x) for x in v] if k == "loops" else v for k, v in c.items()}


def _classification(m: Mechanism) -> dict[str, Any]:
    from ..problems.find_steps import loop_terms

    views = m.derivation.fourbars
    if not views:
        return {}
    terms = loop_terms(m)
    values = {k: q.value for k, q in m.parameters.items()}

    def length(term: Any) -> float:
        ref = term[1]
        return abs(values[ref] if isinstance(ref, str) else float(ref))

    out = []
    for view in views:
        t = terms[view.loop]
        c = fourbar_class(*(length(t[i]) for i in (view.ground, view.input, view.coupler, view.output)))
        out.append({"loop": m.loops[view.loop].name, **c})
    if len(out) == 1:  # named when the mechanism has other loops (a Stephenson six-bar)
        return {k: v for k, v in out[0].items() if k != "loop" or len(m.loops) > 1}
    return {**{k: v for k, v in out[0].items() if k != "loop"}, "loops": out}


def _continuous_angles(solver: Solver, positions: list[Position]) -> list[Position]:
    """Report each angle continuously along the cycle, in driver order around the circle
    (an arc across the grid's end is one piece), in the turn ``solve FILE`` gives at the
    file's driver value: the rule of :mod:`linkage.kinematics.angles`."""
    angles = [n for n, k in zip(solver.names, solver.kinds) if k == "angle"]
    if not angles:
        return positions
    closes = _closes(solver, positions)
    solved = {n: [p.solution[n] if p.solution else None for p in positions] for n in angles}
    turns = {n: unwrap_turns(solved[n], closes) for n in angles}
    shift = _anchor(solver, positions, angles, turns, closes)
    for i, p in enumerate(positions):
        sol = p.solution
        if sol is None:
            continue
        # in place: each position and its solution dict were made by this sweep and are
        # not yet anybody else's (a new Position per position cost 1.5 us each); from the
        # values as solved, so writing twice would write the same
        for n in angles:
            sol[n] = continuous(solved[n][i], turns[n][i] + shift[n])  # type: ignore[arg-type,operator]
    return positions


def _closes(solver: Solver, positions: Sequence[Position]) -> bool:
    """Whether the sweep's driver values close the circle (angles.closes_circle)."""
    if solver.m.driver.kind != "angle":
        return False
    return closes_circle([p.input for p in positions], driver_turn(solver.m.driver.unit))


def _anchor(solver: Solver, positions: list[Position], angles: list[str],
            turns: dict[str, list[int | None]], closes: bool) -> dict[str, int]:
    """Whole turns to add to each angle's curve so that at the position nearest the file's
    own driver value it reads as `solve FILE` reports it there (Newton from the file's
    guess): a sweep and a solve never disagree by a turn."""
    none = dict.fromkeys(angles, 0)
    m = solver.m
    v0 = m.driver.value / solver.scale
    near = anchor_index([p.input for p in positions], [p.solution is not None for p in positions], v0,
                        closes, driver_turn(m.driver.unit))
    if near is None:
        return none
    from .pose import FILE_POSE_TOL, file_pose

    # the file's pose as the sweep's default branch already solved it (solve FILE's own
    # solve: the file's guesses at its driver value, Newton to 1e-12), where it did
    x = file_pose(m) if solver.tol == FILE_POSE_TOL else None
    if x is None:
        from ..solve import solve_system

        r = solve_system(solver.problem(v0), tuple(u.value for u in m.unknowns), tol=solver.tol, record=False)
        if not r.converged:
            return none
        x = r.x
    ref = solver.display(x)
    sol = positions[near].solution
    assert sol is not None
    return {n: turn_shift(ref[n], continuous(sol[n], turns[n][near])) for n in angles}  # type: ignore[arg-type]

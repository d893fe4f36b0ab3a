"""The file's pose and the assembly it names: its guesses solved at its driver value (a
drawing's drawn pose). A sweep follows that assembly unless told (:mod:`.sweep`), and a
scan every design's (``linkage.scan.default_branch``): the one home of "the file's
branch". Where the pose is a change point (docs/change_points.md) it names none.

What a mechanism implies is computed once per mechanism (:func:`implied`): its pose, its
branch, whether the pose is a change point, and what the engines derive from it (the
closed-form engine's anchor, its Grashof class). A
:class:`~linkage.problems.loops.Mechanism` is frozen (``with_values`` gives a new one), so
what it implies cannot change while it lives. The cache is keyed by the mechanism's
``id`` and each entry dropped when the mechanism is collected (``weakref.finalize``): a
``WeakKeyDictionary`` needs a hashable key, and a Mechanism is not (its fields hold
dicts); and a cached property on the Mechanism would put kinematics (layer 4) into
problems/ (layer 1)."""

from __future__ import annotations

import weakref
from collections.abc import Callable, Hashable
from typing import Any, TypeVar

from ..problems.loops import Mechanism

T = TypeVar("T")

IMPLIED: dict[int, dict[Hashable, Any]] = {}
"""id(mechanism) -> {what: value}; an entry lives as long as its mechanism."""


def implied(m: Mechanism, what: Hashable, compute: Callable[[Mechanism], T]) -> T:
    """``compute(m)``, computed once per mechanism and ``what`` (a name, or a tuple of a
    name and the arguments it depends on) and kept while ``m`` lives. ``compute`` must
    depend on nothing but ``m`` and ``what``; the value is shared, so it must not be
    changed by a caller (a tuple, a frozen dataclass, or a copy handed out)."""
    table = _table(m)
    try:
        return table[what]  # type: ignore[no-any-return]
    except KeyError:
        value = table[what] = compute(m)
        return value


RECENT = 16
"""How many values of one ``what`` :func:`implied_recent` keeps per mechanism."""


def implied_recent(m: Mechanism, what: Hashable, args: Hashable, compute: Callable[[Mechanism], T],
                   keep: int = RECENT) -> T:
    """:func:`implied` for what depends on arguments that may take many values over a
    mechanism's life (a sweep's first driver value): ``compute(m)`` for ``what`` and
    ``args``, the ``keep`` most recently used of them kept while ``m`` lives (the least
    recently used dropped first), so a mechanism swept from a million first values holds
    ``keep`` entries, not a million. The same contract on ``compute`` as :func:`implied`."""
    table = _table(m)
    recent = table.get(what)
    if recent is None:
        recent = table[what] = {}
    try:
        value = recent.pop(args)  # (read again at the end: a dict keeps insertion order)
    except KeyError:
        value = compute(m)
        held = list(recent)  # (one step under the GIL, where another thread may add one)
        for old in held[:max(len(held) - keep + 1, 0)]:
            recent.pop(old, None)
    recent[args] = value
    return value  # type: ignore[no-any-return]


def _table(m: Mechanism) -> dict[Hashable, Any]:
    """``m``'s entry of :data:`IMPLIED`, made (with its finalizer) at the first read."""
    key = id(m)
    table = IMPLIED.get(key)
    if table is None:
        table = IMPLIED[key] = {}
        weakref.finalize(m, IMPLIED.pop, key, None)
    return table


def file_branch(m: Mechanism) -> str | None:
    """The branch a sweep follows unless told: the assembly of the file's own pose (its
    guesses solved at its driver value: a drawing's drawn pose), as signs, wherever the
    sweep starts; None where the loops have no derived closed form with two-way steps or
    the pose does not solve (the sweep then starts from the guesses at its first value).
    Computed once per mechanism (:func:`implied`)."""
    return implied(m, "file_branch", file_branch_uncached)


def file_branch_uncached(m: Mechanism) -> str | None:
    """:func:`file_branch` computed afresh (the pose through :func:`file_pose`)."""
    from ..problems.derive import sign_text

    pose = file_pose(m)
    if pose is None:
        return None
    signs = m.derivation.signs_of(list(pose), m.driver.value)
    return sign_text(signs) if all(signs) else None


FILE_POSE_TOL = 1e-12
"""The tolerance the file's pose is solved to (``linkage solve FILE``'s default)."""


def file_pose(m: Mechanism) -> tuple[float, ...] | None:
    """The file's pose (internal units): its guesses solved at its driver value, where the
    loops have a derived closed form with two-way steps; None otherwise or where it does
    not solve. What :func:`file_branch` and :func:`pose_meets` read; solved once per
    mechanism (:func:`implied`)."""
    return implied(m, "file_pose", file_pose_uncached)


def file_pose_uncached(m: Mechanism) -> tuple[float, ...] | None:
    """:func:`file_pose` solved afresh."""
    d = m.derivation
    if not d.complete or not d.two_way:
        return None
    from ..solve import solve_system

    r = solve_system(m.problem(), tol=FILE_POSE_TOL)
    return tuple(r.x) if r.converged else None


def step_words(m: Mechanism) -> list[tuple[str, str]]:
    """Each two-way step's two names, (the first: True in
    :meth:`~linkage.problems.derive.Derivation.words_of_np`, the second): open/crossed
    for a four-bar or slider-crank loop (the derivation's open/crossed rule), + or - for
    any other step (its sign). What the engines name a branch by."""
    d = m.derivation
    return [("open", "crossed") if d.steps[i].word_rule else ("+", "-") for i in d.two_way]


POSE_MEETS = ("the file's pose is where its assemblies meet (to rounding: a change point or a limit): "
              "the branch its guesses solve to there is a matter of rounding; give --branch to choose")


def pose_meets(m: Mechanism) -> bool:
    """Whether the file's pose (its guesses solved at its driver value, as
    :func:`file_branch` solves them) is where two assemblies of a step meet, to rounding
    (:meth:`~linkage.problems.derive.Derivation.meets`): then the file names no branch.
    Computed once per mechanism (:func:`implied`)."""
    return implied(m, "pose_meets", pose_meets_uncached)


def pose_meets_uncached(m: Mechanism) -> bool:
    """:func:`pose_meets` computed afresh (the pose through :func:`file_pose`)."""
    pose = file_pose(m)
    return pose is not None and any(m.derivation.meets(list(pose), m.driver.value))

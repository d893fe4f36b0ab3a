"""The file's pose and the assembly it names: its guesses solved at its driver value (a
drawing's drawn pose). A sweep follows that assembly unless told (:mod:`.sweep`), and a
scan every design's (``linkage.scan.default_branch``): the one home of "the file's
branch". Where the pose is a change point (docs/change_points.md) it names none."""

from __future__ import annotations

from ..problems.loops import Mechanism


def file_branch(m: Mechanism) -> str | None:
    """The branch a sweep follows unless told: the assembly of the file's own pose (its
    guesses solved at its driver value: a drawing's drawn pose), as signs, wherever the
    sweep starts; None where the loops have no derived closed form with two-way steps or
    the pose does not solve (the sweep then starts from the guesses at its first value)."""
    from ..problems.derive import sign_text

    pose = file_pose(m)
    if pose is None:
        return None
    signs = m.derivation.signs_of(pose, m.driver.value)
    return sign_text(signs) if all(signs) else None


def file_pose(m: Mechanism) -> list[float] | None:
    """The file's pose (internal units): its guesses solved at its driver value, where the
    loops have a derived closed form with two-way steps; None otherwise or where it does
    not solve. What :func:`file_branch` and :func:`pose_meets` read."""
    d = m.derivation
    if not d.complete or not d.two_way:
        return None
    from ..solve import solve_system

    r = solve_system(m.problem(), tol=1e-12)
    return list(r.x) if r.converged else None


POSE_MEETS = ("the file's pose is where its assemblies meet (to rounding: a change point or a limit): "
              "the branch its guesses solve to there is a matter of rounding; give --branch to choose")


def pose_meets(m: Mechanism) -> bool:
    """Whether the file's pose (its guesses solved at its driver value, as
    :func:`file_branch` solves them) is where two assemblies of a step meet, to rounding
    (:meth:`~linkage.problems.derive.Derivation.meets`): then the file names no branch."""
    pose = file_pose(m)
    return pose is not None and any(m.derivation.meets(pose, m.driver.value))

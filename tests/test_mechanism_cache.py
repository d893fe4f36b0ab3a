"""What a mechanism implies (its pose, its branch, whether its pose is a change point, the
closed-form engine's anchor, its Grashof class) is computed once per mechanism and kept
while it lives (kinematics/pose.py, ``implied``). References: the same values computed
without the cache, on random four-bars and the samples; and the 361-position closed-form
sweep, which solves nothing by Newton once its mechanism's pose is known."""

from __future__ import annotations

import gc
import random
from pathlib import Path

import pytest

import linkage
from linkage.kinematics import pose
from linkage.kinematics.closed import closed_sweep
from linkage.kinematics.loading import load
from linkage.kinematics.stepwise import classification_of
from linkage.units import degrees

SAMPLES = Path(__file__).resolve().parent.parent / "sample_inputs"
CRANK_ROCKER = SAMPLES / "crank_rocker.toml"


def _uncached_branch(m) -> str | None:
    """file_branch without the cache: the pose solved again, its signs named again (as
    the module's code before the cache wrote it)."""
    from linkage.problems.derive import sign_text

    got = pose.file_pose_uncached(m)
    if got is None:
        return None
    signs = m.derivation.signs_of(list(got), m.driver.value)
    return sign_text(signs) if all(signs) else None


def _random_four_bars(rng, count):
    """``count`` four-bars of crank_rocker.toml's loop: random lengths, drawn pose and
    guesses (both assemblies, and poses that do not assemble)."""
    base = load(CRANK_ROCKER)
    for _ in range(count):
        values = {k: rng.uniform(20.0, 160.0) for k in ("r2", "r3", "r4")}
        guesses = {"theta3": rng.uniform(-180.0, 180.0), "theta4": rng.uniform(-180.0, 180.0)}
        yield base.with_values({**values, "theta2": rng.uniform(0.0, 360.0)}, guesses)


def test_the_cached_branch_is_the_uncached_one_on_random_four_bars():
    rng = random.Random(33)
    seen = set()
    for m in _random_four_bars(rng, 60):
        first = pose.file_branch(m)
        assert first == _uncached_branch(m)
        assert pose.file_branch(m) == first  # the second read is the cache's
        assert pose.pose_meets(m) == pose.pose_meets_uncached(m)
        assert pose.file_pose(m) == pose.file_pose_uncached(m)
        seen.add(first)
    assert {"+", "-", None} <= seen  # both assemblies and poses that do not solve were met


def test_with_values_gives_a_mechanism_with_its_own_cache():
    m = load(CRANK_ROCKER)
    first = pose.file_pose(m)
    # the guesses of the other assembly: a new mechanism, a new pose, the other branch
    other = m.with_values({}, {"theta3": -degrees(first[0]), "theta4": -degrees(first[1])})
    assert pose.file_pose(other) == pose.file_pose_uncached(other) != first
    assert pose.file_branch(other) != pose.file_branch(m)
    assert pose.file_pose(m) == first  # the first mechanism's entry is untouched


def test_an_entry_goes_with_its_mechanism():
    m = load(CRANK_ROCKER).with_values({"r2": 41.0}, {})
    pose.file_branch(m)
    key = id(m)
    assert key in pose.IMPLIED
    del m
    gc.collect()
    assert key not in pose.IMPLIED


def test_a_callers_classification_is_its_own_copy():
    m = load(SAMPLES / "watt_sixbar.toml")  # two four-bar loops: a class per loop
    first = classification_of(m)
    first["changed"] = True
    for row in first.get("loops", []):
        row["changed"] = True
    again = classification_of(m)
    assert "changed" not in again and all("changed" not in r for r in again.get("loops", []))
    assert again == pose.IMPLIED[id(m)]["classification"] and len(again["loops"]) == 2


def test_a_closed_form_sweep_solves_nothing_by_newton_once_its_pose_is_known(monkeypatch):
    m = load(CRANK_ROCKER)
    values = [float(k) for k in range(361)]
    first = linkage.sweep(m, values)
    assert first.method == "newton (closed form)"
    import linkage.kinematics.continuation as continuation
    import linkage.solve as solve

    def refuse(*args, **kwargs):
        raise AssertionError("a Newton solve in a sweep whose mechanism is known")

    monkeypatch.setattr(solve, "solve_system", refuse)
    monkeypatch.setattr(continuation.Solver, "solve_lean", refuse)
    again = linkage.sweep(m, values)
    assert again.method == "newton (closed form)"
    assert [p.solution for p in again.positions] == [p.solution for p in first.positions]


@pytest.mark.parametrize("tol", [1e-12, 1e-9])
def test_the_closed_form_anchor_is_per_criteria(tol):
    m = load(CRANK_ROCKER)
    got = closed_sweep(m, [float(k) for k in range(0, 361, 10)], branch=pose.file_branch(m), tol=tol)
    assert got is not None
    assert ("closed_anchor", tol, 50) in pose.IMPLIED[id(m)]


def test_the_followed_branch_is_kept_per_first_value_and_is_the_uncached_one():
    """The closed-form engine's branch to follow (Newton from the file's guess at the first
    driver value, where no branch is given) is solved once per mechanism and arguments:
    the same signs as solved afresh, on random four-bars, first values and criteria."""
    from linkage.kinematics.closed import closed_plan, followed_signs, followed_signs_uncached

    rng = random.Random(40)
    seen = set()
    for m in _random_four_bars(rng, 40):
        scale = closed_plan(m).scale
        first = rng.choice([0.0, -0.0, rng.uniform(-360.0, 360.0)])
        for tol, branch in ((1e-12, None), (1e-9, None), (1e-12, "+"), (1e-12, "crossed")):
            want = followed_signs_uncached(m, tol, 50, first, scale, branch)
            assert followed_signs(m, tol, 50, first, scale, branch) == want
            assert followed_signs(m, tol, 50, first, scale, branch) == want  # the kept one
            seen.add(want)
    assert {(1.0,), (-1.0,), None} <= seen


def test_a_mechanism_swept_from_many_first_values_keeps_a_few_branches(monkeypatch):
    """The kept branches are bounded (pose.RECENT per mechanism, the least recently used
    dropped), and a sweep from a kept first value solves nothing by Newton."""
    import linkage.kinematics.continuation as continuation

    m = load(CRANK_ROCKER)
    for k in range(3 * pose.RECENT):
        assert closed_sweep(m, [float(k), k + 10.0, k + 20.0]) is not None
        if k == 2 * pose.RECENT:
            closed_sweep(m, [0.5 * pose.RECENT, 50.0])  # a recent use keeps it
    kept = pose.IMPLIED[id(m)]["closed_followed_signs"]
    assert len(kept) == pose.RECENT
    firsts = {key[0] for key in kept}
    assert firsts == {float(k) for k in range(2 * pose.RECENT + 1, 3 * pose.RECENT)} | {0.5 * pose.RECENT}

    def refuse(*args, **kwargs):
        raise AssertionError("a Newton solve for a branch already kept")

    monkeypatch.setattr(continuation.Solver, "solve_lean", refuse)
    assert closed_sweep(m, [float(3 * pose.RECENT - 1), 200.0]) is not None


def test_implied_recent_drops_the_least_recently_used():
    m = load(CRANK_ROCKER)
    calls = []

    def compute(args):
        return lambda m: calls.append(args) or args

    for k in range(5):
        assert pose.implied_recent(m, "probe", k, compute(k), keep=3) == k
    assert pose.implied_recent(m, "probe", 2, compute(2), keep=3) == 2  # kept: 2, 3, 4
    assert pose.implied_recent(m, "probe", 5, compute(5), keep=3) == 5  # drops 3
    assert pose.implied_recent(m, "probe", 3, compute(3), keep=3) == 3  # computed again
    assert calls == [0, 1, 2, 3, 4, 5, 3]
    assert list(pose.IMPLIED[id(m)]["probe"]) == [2, 5, 3]

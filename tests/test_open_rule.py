"""The open/crossed rule of a four-bar (problems.assembly.open_rule) is the sign of
sin(output - coupler), read as the sign of tan(turn / 2) for speed: here its verdicts are
held to the sine's, in math and numpy alike, where they are hardest to get right (next to
every multiple of pi, at huge and tiny angles), and at the one documented difference."""

from __future__ import annotations

import math

import numpy as np

from linkage.problems.assembly import open_rule


def hard_turns() -> np.ndarray:
    rng = np.random.default_rng(20261128)
    near_pi = []
    for k in range(-40, 41):
        x = k * math.pi
        for _ in range(4):
            near_pi += [x, -x]
            x = math.nextafter(x, math.inf)
        x = k * math.pi
        for _ in range(4):
            x = math.nextafter(x, -math.inf)
            near_pi += [x]
    tiny = [s * 2.0 ** -e for e in range(1000, 1074) for s in (1.0, -1.0)]
    huge = list(rng.uniform(1e5, 1e300, 2000) * rng.choice([-1.0, 1.0], 2000))
    return np.concatenate([rng.uniform(-4 * math.pi, 4 * math.pi, 200_000), near_pi, tiny, huge,
                           [0.0, -0.0, math.inf, -math.inf, math.nan]])


def test_the_four_bar_rule_gives_the_sines_verdict_in_numpy_and_math():
    turns = hard_turns()
    turns = turns[np.abs(turns) != 2.0 ** -1074]  # the documented difference: the next test
    coupler = np.full_like(turns, 0.0)
    for sign in (1.0, -1.0):
        with np.errstate(invalid="ignore"):
            want = sign * np.sin(turns) > 0.0
            got = open_rule("fourbar", sign, coupler, turns, np)
        assert np.array_equal(got, want)
        for x in turns[::50].tolist() + turns[200_000:-5].tolist():  # math.sin(inf) raises, as tan
            want_x = sign * math.sin(x) > 0.0
            assert open_rule("fourbar", sign, 0.0, x) == want_x


def test_a_turn_of_the_least_subnormal_is_called_crossed_as_documented():
    least = 2.0 ** -1074
    assert math.sin(least) > 0.0  # the sine says open; its half rounds to 0
    assert not open_rule("fourbar", 1.0, 0.0, least)
    assert not open_rule("fourbar", 1.0, np.zeros(1), np.array([least]), np)[0]

"""The pieces the two-unknown Newton loops are generated from, against the definitions
they stand for, and their compilation on first use (methods/newton_system.py)."""

from __future__ import annotations

import math
import random
import struct
import subprocess
import sys
from collections import Counter

from linkage.methods.newton_system import larger_of, max_abs

SPECIAL = (0.0, -0.0, 1.0, -1.0, 5e-324, -5e-324, 1e308, -1e308, math.inf, -math.inf, math.nan, 2.5, -2.5)


def _bits(v: float) -> bytes:
    return struct.pack("<d", v)


def test_larger_of_two_magnitudes_is_max_abs_bit_for_bit() -> None:
    """The generated max of two magnitudes (|v| written as the loops write it) equals
    max_abs, the one definition, bit for bit: NaN for a NaN in either place, +0.0 for
    signed zeros, ties and infinities included."""
    larger = eval(f"lambda a0, a1: {larger_of('a0', 'a1')}", {"_nan": math.nan})
    rng = random.Random(33)
    pairs = [(u, v) for u in SPECIAL for v in SPECIAL]
    pairs += [(rng.uniform(-4.0, 4.0), rng.uniform(-4.0, 4.0)) for _ in range(2_000)]
    pairs += [(u, u) for u, _ in pairs[-200:]] + [(u, -u) for u, _ in pairs[-200:]]
    for u, v in pairs:
        a0 = u if u > 0.0 else 0.0 - u
        a1 = v if v > 0.0 else 0.0 - v
        assert _bits(larger(a0, a1)) == _bits(max_abs([u, v])), (u, v)


def test_the_system_loops_compile_on_first_use_not_at_import() -> None:
    """Importing methods/newton_system compiles neither generated loop; the first use of
    each compiles it once, and importing it by name is that use."""
    code = (
        "import linkage.methods.newton_system as m\n"
        "before = ('newton_2x2' in vars(m), 'newton_system_lean' in vars(m))\n"
        "from linkage.methods.newton_system import newton_system_lean\n"
        "after = ('newton_2x2' in vars(m), 'newton_system_lean' in vars(m))\n"
        "assert m.newton_system_lean is newton_system_lean and m.newton_2x2 is m.newton_2x2\n"
        "try:\n"
        "    m.no_such_loop\n"
        "except AttributeError:\n"
        "    missing = True\n"
        "print(before, after, missing)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "(False, False) (True, True) True"


def test_the_two_unknown_quiet_path_tests_imply_the_rules_they_stand_for() -> None:
    """The 2x2 loop's quiet path reads, in place of max|Phi| and max|q|: the old Phi's sum of
    squares finite and positive, which implies max|Phi| finite and not zero; and |x0|, |x1|
    below tol / ROUNDING, which with the error above tol implies the error above rounding,
    err > ROUNDING max(|x0|, |x1|). Each may fail where the rule passes (a sum that under-
    or overflows, a large |x|): the tests then decide; they pass in the common case."""
    from linkage.iterate import ROUNDING
    from linkage.methods.newton_system import NEWTON_2X2_LOOP

    residual = eval(f"lambda fs: {NEWTON_2X2_LOOP.quiet_residual}", {"_inf": math.inf, "damped": True})
    rounding = eval(f"lambda x0, x1, low_x, high_x: {NEWTON_2X2_LOOP.quiet_rounding}")
    rng = random.Random(34)
    values = (*SPECIAL, 1e-170, -1e-170, 1e160, -1e160, 1e-300, 3e-155, -1e154, 1e-310, 2.0 ** 974)
    pairs = [(u, v) for u in values for v in values]
    pairs += [(rng.uniform(-4.0, 4.0) * 10.0 ** rng.randint(-200, 200),
               rng.uniform(-4.0, 4.0) * 10.0 ** rng.randint(-200, 200)) for _ in range(3_000)]
    passed = declined = quiet = 0
    for u, v in pairs:
        fx = max_abs([u, v])
        if residual(u * u + v * v):
            assert -math.inf < fx < math.inf and fx != 0.0, (u, v)
            passed += 1
        elif -math.inf < fx < math.inf and fx != 0.0:
            declined += 1
        for tol in (*values[:6], 1e-12, 1e-6, 1e293, 1e300, 5e-324, abs(u), abs(v) * ROUNDING):
            high_x = tol / ROUNDING  # as the loop's setup sets them
            for err in (math.nextafter(tol, math.inf), tol * 3.0, 1.0, math.inf, math.nan):
                if tol < err and rounding(u, v, -high_x, high_x):
                    assert err > ROUNDING * max_abs([u, v]), (err, u, v, tol)
                    quiet += 1
    assert passed > 1_000 and declined > 100 and quiet > 10_000


def _scaled_system(rng: random.Random, scale: float):  # type: ignore[no-untyped-def]
    """A random 2x2 system (linear plus a sine) scaled by ``scale``, so that the sum of
    squares of Phi under- or overflows where max|Phi| does not."""
    A = [[rng.uniform(-2, 2) for _ in range(2)] for _ in range(2)]
    c = [rng.uniform(-3, 3) for _ in range(2)]
    b = [rng.uniform(-4, 4) for _ in range(2)]

    def F(q):  # type: ignore[no-untyped-def]
        return [scale * (A[i][0] * q[0] + A[i][1] * q[1] + c[i] * math.sin(q[i]) - b[i]) for i in range(2)]

    def J(q):  # type: ignore[no-untyped-def]
        return [[scale * (A[i][j] + (c[i] * math.cos(q[i]) if i == j else 0.0)) for j in range(2)]
                for i in range(2)]
    return F, J, (rng.uniform(-4, 4), rng.uniform(-4, 4))


def test_two_unknown_loop_equals_the_generic_loop_where_the_sum_of_squares_under_or_overflows() -> None:
    """newton_2x2 against the generic loop stepping NewtonSystem, bit for bit (iterate,
    Phi, error, status, detail, iterations, counts), on systems scaled so that |Phi|^2
    underflows or overflows while max|Phi| is finite and not zero: the quiet path declines
    those steps and the tests decide, as they do in the generic loop."""
    from linkage.iterate import Criteria, run
    from linkage.methods.newton_system import NewtonSystem, newton_2x2
    from linkage.problems.system import generic_system
    from linkage.result import Status

    rng = random.Random(35)
    statuses: Counter[Status] = Counter()
    for case in range(240):
        scale = (1e-165, 1e-150, 1e155, 1e150, 1.0)[case % 5]
        F, J, q0 = _scaled_system(rng, scale)
        damped = case % 2 == 0
        tol = 10.0 ** rng.uniform(-14, -6)
        gate = tol * scale
        problem = generic_system(F, 2, J)
        phi0 = F(list(q0))
        got = newton_2x2(problem, q0, phi0, tol, 0.0, gate, 40, damped)
        m = NewtonSystem("analytic", None, damped, diagnostics=False)
        final, status, detail, k, _ = run(m, problem, m.init(problem, q0, phi0), Criteria(tol, 0.0, gate, 40),
                                          record=False, magnitude=max_abs)
        assert (got[3], got[4], got[5]) == (status, detail, k), case
        assert [_bits(v) for v in (*got[0], *got[1], got[2])] == \
            [_bits(v) for v in (*final.x, *final.phi_x, final.err)], case
        assert (got[6], got[7]) == (final.nfev, final.njev), case  # a step that raised too
        statuses[status] += 1
    assert statuses[Status.CONVERGED_STEP] > 50 and len(statuses) >= 3, statuses


def test_the_generated_system_convergence_test_is_the_rule() -> None:
    """rules.system_converged_source, which the generated loops read, gives
    rules.system_converged's verdict on special, boundary and random values."""
    from linkage.rules import system_converged, system_converged_source

    inline = eval(f"lambda err, fx, limit, gate: {system_converged_source('err', 'fx', 'limit', 'gate')}")
    rng = random.Random(36)
    values = (*SPECIAL, 1e-12, math.nextafter(1e-12, 0.0), math.nextafter(1e-12, 1.0))
    cases = [(e, f, lim, g) for e in values for f in values for lim in values[::3] for g in values[::4]]
    cases += [tuple(rng.choice((1e-12, rng.uniform(0.0, 2e-12))) for _ in range(4)) for _ in range(2_000)]
    for err, fx, limit, gate in cases:
        assert bool(inline(err, fx, limit, gate)) == system_converged(err, fx, limit, gate), (err, fx, limit)


def test_the_two_by_two_singularity_test_is_the_rules_verdict() -> None:
    """invertible_2x2_source (a finite det where ad and bc have opposite signs, else the
    rule's source) gives rules.invertible(det, |ad| + |bc|)'s verdict: every product of
    special values, and random ones of every sign and of wide exponents (overflow,
    underflow and cancellation included)."""
    from linkage.methods.newton_system import invertible_2x2_source
    from linkage.rules import invertible

    test = eval(f"lambda ad, bc, det: {invertible_2x2_source('ad', 'bc', 'det')}",
                {"_inf": math.inf, "_ninf": -math.inf})
    rng = random.Random(11)
    pairs = [(u, v) for u in SPECIAL for v in SPECIAL]
    for _ in range(20000):
        u = rng.choice((-1.0, 1.0)) * rng.random() * 10.0 ** rng.randint(-320, 308)
        v = u * (1.0 + rng.choice((0.0, 1e-13, 1e-12, 1e-11, 1e-3, -1.0, -2.0))) if rng.random() < 0.3 \
            else rng.choice((-1.0, 1.0)) * rng.random() * 10.0 ** rng.randint(-320, 308)
        pairs.append((u, v))
    opposite = 0
    for ad, bc in pairs:
        det = ad - bc
        assert test(ad, bc, det) is invertible(det, abs(ad) + abs(bc)), (ad, bc)
        opposite += ad * bc < 0.0
    assert opposite > 5000

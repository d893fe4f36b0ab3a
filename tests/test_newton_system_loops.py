"""The pieces the two-unknown Newton loops are generated from, against the definitions
they stand for, and their compilation on first use (methods/newton_system.py)."""

from __future__ import annotations

import math
import random
import struct
import subprocess
import sys

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

"""A second opinion on every assembly: Bertini 2 (the ``bertini`` extra, skipped where it is
not installed) solves the same polynomial systems as ``linkage assemblies`` with its own
total-degree homotopy in adaptive precision, and its finite solutions must be ours, real and
complex alike (Bates, Hauenstein, Sommese and Wampler, *Numerically Solving Polynomial
Systems with Bertini*, SIAM 2013). Coefficients pass to it as exact decimal strings of the
doubles (it refuses floats); it records nothing (recording off, BERTINI_RECORDS_DIR=none)
and runs on one thread."""

from __future__ import annotations

from decimal import Decimal
from pathlib import Path

import numpy as np
import pytest

import linkage
from linkage.kinematics.assemblies import assembly_system, encode
from linkage.kinematics.loading import load

SAMPLES = Path(__file__).resolve().parents[1] / "sample_inputs"


@pytest.fixture
def bertini(monkeypatch, tmp_path):
    monkeypatch.setenv("BERTINI_RECORDS_DIR", "none")
    monkeypatch.setenv("BERTINI_NUM_THREADS", "1")
    monkeypatch.chdir(tmp_path)
    module = pytest.importorskip("bertini")
    module.recording(False)
    yield module
    assert not any(tmp_path.iterdir()), "bertini wrote records"


def _bertini_roots(bertini, system) -> list[np.ndarray]:
    """Every finite solution Bertini finds, by its total-degree homotopy (one variable group)."""
    from bertini import multiprec

    def coefficient(c: complex):
        return bertini.coefficient(multiprec.complex_mp(str(Decimal(c.real)), str(Decimal(c.imag))))

    xs = bertini.variables("x", system.n)
    b = bertini.System()
    for p in system.polynomials:
        expr = None
        for e, c in p.items():
            term = coefficient(complex(c))
            for v, k in enumerate(e):
                for _ in range(k):
                    term = term * xs[v]
            expr = term if expr is None else expr + term
        b.add_function(expr)
    b.add_variable_group(bertini.VariableGroup(xs))
    result = bertini.solve(b, seed=1, show_progress=False)
    return [np.array([complex(z) for z in s]) for s in result.solutions]


def _matched(ours: list[np.ndarray], theirs: list[np.ndarray], tol: float = 1e-8) -> bool:
    left = list(theirs)
    for x in ours:
        size = max(1.0, float(np.linalg.norm(x)))
        k = next((i for i, y in enumerate(left) if np.linalg.norm(x - y) <= tol * size), None)
        if k is None:
            return False
        left.pop(k)
    return not left


@pytest.mark.parametrize("name,driver", [
    ("fourbar_me581.toml", None), ("watt_sixbar.toml", None), ("stephenson_sixbar.toml", None),
    ("stephenson_sixbar.toml", 200.0), ("rapier_drive.toml", None), ("rapier_drive.toml", 200.0),
])
def test_bertini_finds_the_same_assemblies_real_and_complex(bertini, name, driver):
    m = load(SAMPLES / name)
    a = linkage.assemblies(m, driver)
    system = assembly_system(m, a.driver)
    theirs = _bertini_roots(bertini, system)
    ours = [e.x for e in a.solutions.endpoints if e.kind in ("finite", "singular")]
    assert a.failed == 0 and a.unresolved == 0 and sum(a.multiplicity) == len(a.real)
    assert len(theirs) == len(ours) == len(a.real) + a.complex_count
    assert _matched(ours, theirs)
    real = [x for x in theirs if system.realness(x) <= 1e-9]
    assert _matched([np.array(encode(m, s.q)) for s in a.real], real)

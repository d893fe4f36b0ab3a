"""A scan's joints and points (kinematics.designs.design_paths) are placed by the one placing
rule a sweep uses (kinematics.placing.place_np on the design's own parameters): the same
numbers, bit for bit, design by design, and NaN where a position is not solved."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from linkage.kinematics.designs import design_paths, solve_designs
from linkage.kinematics.loading import load
from linkage.kinematics.placing import place_np
from linkage.problems.loops import LoopModel
from linkage.units import radians

ROOT = Path(__file__).resolve().parents[1]


def test_a_scan_places_joints_and_points_by_the_sweeps_rule_bit_for_bit() -> None:
    m = load(ROOT / "sample_inputs" / "crank_rocker.toml")
    r1 = np.array([92.5, 100.0, 107.25])
    vals = np.arange(0.0, 360.0, 7.5)
    k = len(vals)
    rng = np.random.default_rng(11)
    # any unknowns: the placing rule is defined for every value, solved or not
    q = [rng.uniform(-np.pi, np.pi, size=len(r1) * k) for _ in m.unknowns]
    solved = rng.random(len(r1) * k) < 0.9
    got = design_paths(m, {"r1": r1}, vals, q, solved)
    assert set(got) >= {"A", "B", "P"}
    for i, length in enumerate(r1):
        rows = slice(i * k, (i + 1) * k)
        want = place_np(LoopModel.compile(m, {"r1": float(length)}), [c[rows] for c in q], radians(vals))
        for name, (x, y) in want.items():
            z = got[name][rows]
            here = solved[rows]
            assert np.array_equal(z.real[here].view(np.int64), x[here].view(np.int64)), name
            assert np.array_equal(z.imag[here].view(np.int64), y[here].view(np.int64)), name
            assert np.isnan(z[~here]).all()


def test_a_scan_s_point_path_is_the_sweep_s_to_rounding() -> None:
    """End to end: solve_designs' point P of a design against linkage.sweep's P (joints=True)
    of the same design: the two engines' unknowns differ in the last bits at most, so P
    agrees within a few ulps of the mechanism's size."""
    import linkage

    m = load(ROOT / "sample_inputs" / "crank_rocker.toml")
    vals = np.arange(0.0, 360.0, 10.0)
    sol = solve_designs(m, {"r1": np.array([100.0])}, vals, branch="open", paths=True)
    swept = linkage.sweep(m, [float(v) for v in vals], joints=True)
    px = np.array([p.rates.joints["P"][0] for p in swept.positions])
    py = np.array([p.rates.joints["P"][1] for p in swept.positions])
    assert np.allclose(sol.paths["P"][0].real, px, rtol=0.0, atol=1e-11 * 120.0)
    assert np.allclose(sol.paths["P"][0].imag, py, rtol=0.0, atol=1e-11 * 120.0)

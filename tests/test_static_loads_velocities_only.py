"""A static load's scan reads positions and the unit speed's velocities only, so
kinematics.rates.motions_rates_np and kinematics.placing.place_motion_np skip the
accelerations there (about a tenth of a loaded scan). What they still compute must be the
very numbers of the full computation."""

from __future__ import annotations

import numpy as np

import linkage
from linkage.kinematics.placing import place_motion_np
from linkage.kinematics.rates import motions_rates_np
from linkage.problems.loops import LoopModel
from linkage.samples import sample_path
from linkage.units import radians


def test_velocities_only_are_the_full_computations_velocities_bit_for_bit():
    m = linkage.load_mechanism(sample_path("crank_rocker_joints.toml"))
    model = LoopModel.compile(m, {})
    grid = [float(v) for v in range(0, 360, 7)]
    r = linkage.sweep(m, grid)
    d = radians(np.asarray(grid))
    q = [radians(np.asarray(r.column(n), float)) for n in r.names]
    assert r.units == ("deg", "deg")
    full, ok_full = motions_rates_np(model, q, d, ((1.0, 0.0),))
    vel, ok_vel = motions_rates_np(model, q, d, ((1.0, 0.0),), accelerations=False)
    assert np.array_equal(ok_full, ok_vel)
    (qd_f, qdd_f), (qd_v, qdd_v) = full[0], vel[0]
    assert qdd_v is None and qdd_f is not None
    for a, b in zip(qd_f, qd_v):
        assert np.array_equal(a, b)
    placed_full = place_motion_np(model, q, d, qd_f, 1.0, qdd_f, 0.0)
    placed_vel = place_motion_np(model, q, d, qd_v, 1.0, None, 0.0)
    assert placed_full.keys() == placed_vel.keys()
    for k in placed_full:
        assert np.array_equal(placed_full[k][0], placed_vel[k][0])
        assert np.array_equal(placed_full[k][1], placed_vel[k][1])
        assert placed_vel[k][2] is None

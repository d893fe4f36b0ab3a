"""Kinematics of mechanisms: sweeps over the driver (continuation, assembly branches,
limit positions, the numpy batch engine) and, at each position, velocities and
accelerations of the unknowns, the joints and the named points (:mod:`.rates`).
:mod:`linkage.analysis` keeps post-processing of solver runs (convergence order)."""

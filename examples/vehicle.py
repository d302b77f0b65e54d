"""A non-holonomic vehicle: Bremer's car (scene ``car``, B(5)-(12) of Bremer (2009)).

The rear axle cannot slide sideways: q = (x, y, γ) has three coordinates but only two
minimal velocities ṡ = (forward speed, yaw rate), q̇ = K(q) ṡ. Without driving forces the
ideal constraint does no work, so the kinetic energy is conserved (a conservation law),
and the velocity of the rear-axle point stays along the car's axis (the constraint itself).

Run: python examples/vehicle.py  (PROJEQ_QUICK=1 shortens the run, as the tests do)
"""

import os

import numpy as np

import projeq as pq
from projeq import plots

t_end = 2.0 if os.environ.get("PROJEQ_QUICK") else 20.0
result = pq.simulate(pq.scenes.car(), t_end, method="DOP853", rtol=1e-10, atol=1e-12)
x, y, gamma = result.q[-1]
print(f"after {t_end:g} s: x = {x:.3f} m, y = {y:.3f} m, heading {gamma:.4f} rad")
print(f"energy drift {result.energy_drift:.1e}, largest constraint residual {np.abs(result.constraint_residual).max():.1e}")
# rtol 1e-10: both are at the level of the requested tolerance, far below 1e-6
assert result.energy_drift < 1e-6 and np.abs(result.constraint_residual).max() < 1e-6
plots.planar_trajectory(result, 0, 1).savefig("vehicle_path.png")

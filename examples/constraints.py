"""Constraint equations: a closed loop (scene ``four_bar``) and the Whipple bicycle (``whipple_bicycle``).

A :class:`projeq.ConstrainedSystem` is a tree plus constraint equations Φ(q, t) = 0 and
A(q, t) q̇ = b; coordinate partitioning inserts them before the projection (docs/theory.md §7).

1. The four-bar linkage swings under gravity from the crank turning at 3 rad/s. The ideal
   loop closure does no work, so the energy is conserved (a conservation law), and the
   loop stays closed (|Φ| at round-off, Gauss–Newton projection at every output). The
   closure's multipliers λ are the forces the cut joint transmits (``pq.reactions``).
2. A flexible loop (scene ``flexible_four_bar``): the same four-bar with its coupler a RitzBeam
   (two bending functions), the beam's tip held on the rocker's by a cut joint (``pq.PinClosure``
   at the beam's station x = L, which bends with it): compiled like the rigid loop, its energy
   conserved and the loop closed.
3. The bicycle's upright straight running at 5 m/s, linearised: its four eigenvalues equal
   those of Meijaard, Papadopoulos, Ruina & Schwab (2007), Proc. R. Soc. A 463, Table 2,
   v = 5 m/s. Without PROJEQ_QUICK also the weave and capsize speeds, MJPR's 4.292 382 536 341 11
   and 6.024 262 015 388 37 m/s (Table 2(a)).

Run: python examples/constraints.py  (PROJEQ_QUICK=1 shortens it, as the tests do)
"""

import os

import numpy as np
from scipy.optimize import brentq

import projeq as pq
from projeq.scenes import whipple_eigenvalues

QUICK = bool(os.environ.get("PROJEQ_QUICK"))

four_bar = pq.scenes.four_bar()
result = pq.simulate(four_bar, 0.2 if QUICK else 5.0, rtol=1e-10, atol=1e-12)
closure = np.abs(result.constraint_residual).max()
forces = pq.reactions(four_bar, result)  # λ of the two closure rows, N
print(f"four-bar: energy drift {result.energy_drift:.1e}, largest |Φ| or velocity residual {closure:.1e}, "
      f"largest cut-joint force {np.abs(forces).max():.3g} N")
assert closure < 1e-8  # Gauss–Newton projection to round-off; 1e-8 allows the velocity rows' rtol-level error

flexible_loop = pq.scenes.flexible_four_bar()  # the coupler a RitzBeam, pinned at its tip to the rocker
flexible = pq.simulate(flexible_loop, 0.2 if QUICK else 1.0)
print(f"flexible four-bar: energy drift {flexible.energy_drift:.1e}, largest |Φ| "
      f"{np.abs(flexible.constraint_residual).max():.1e}, largest tip deflection amplitude "
      f"{np.abs(flexible.q[:, 3:]).max():.2e}")
# the loop's forces do no work, strain and gravity are conservative: drift 3e-11 achieved (RK45 defaults)
assert flexible.energy_drift < 1e-8 and np.abs(flexible.constraint_residual).max() < 1e-10

# MJPR (2007) Table 2, v = 5 m/s: castering, weave pair, capsize
MJPR_5 = np.array([-14.0783896927982, -0.775341882195845 + 4.46486771378823j,
                   -0.775341882195845 - 4.46486771378823j, -0.322866429004087])
lam = whipple_eigenvalues(5.0)
error = max(np.abs(lam - reference).min() for reference in MJPR_5)
print(f"bicycle at 5 m/s: eigenvalues {np.array2string(lam, precision=6)}, largest difference to MJPR {error:.1e}")
# the linearisation's Jacobian is exact (complex step through the compiled model): round-off, 9e-14 achieved
assert error < 1e-12 * np.abs(MJPR_5).max()

if not QUICK:
    def largest_real_part(v, oscillatory):
        lam = whipple_eigenvalues(v)
        return lam[(np.abs(lam.imag) > 1e-6) == oscillatory].real.max()

    v_w = brentq(largest_real_part, 4.0, 4.5, args=(True,), xtol=1e-12)  # the weave pair turns stable
    v_c = brentq(largest_real_part, 5.8, 6.2, args=(False,), xtol=1e-12)  # the capsize mode turns unstable
    print(f"self-stable from {v_w:.14f} to {v_c:.14f} m/s (MJPR: 4.29238253634111 to 6.02426201538837 m/s)")
    # the eigenvalues' round-off moves a root by ~1e-13 / |dRe λ/dv| (slopes ~1 and ~0.1 per m/s): 3e-14 achieved
    assert abs(v_w - 4.29238253634111) < 1e-11 and abs(v_c - 6.02426201538837) < 1e-11

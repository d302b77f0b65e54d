"""Comparing derivations: recursive order-n, compiled order-n ("fast"), dense Gauss form, sympy.

All evaluate the Projection Equation Σ (∂ẏ_n/∂ṡ)ᵀ(M_n ÿ_n + G_n ẏ_n − Q_n) = 0 for the
same chain: by the O(n) recursion (docs/theory.md §6) in numpy and compiled, by assembling M(q)
and solving (docs/theory.md §5), and symbolically (``projeq.symbolic.gauss_form``: M(q) s̈ = rhs
in sympy, lambdified). Formulations of the same equations must give the same
accelerations to round-off, and trajectories that agree to the integration tolerance.

Run: python examples/derivations.py
"""

import os

import numpy as np

import projeq as pq
from projeq.symbolic import gauss_form

system = pq.scenes.chain(4)
rng = np.random.default_rng(1)
q, s_dot = rng.normal(size=4), rng.normal(size=4)
recursive = system.accelerations(q, s_dot, method="recursive")
dense = system.accelerations(q, s_dot, method="dense")
difference = np.abs(recursive - dense).max() / np.abs(dense).max()
print(f"accelerations at a random state: relative difference {difference:.1e}")
assert difference < 1e-12  # a 4x4 solve: round-off is ~1e-15; 1e-12 leaves a factor 1000
fast = system.accelerations(q, s_dot, method="auto")  # the compiled kernel with numba, else the recursive evaluator
symbolic = gauss_form(system).evaluator().accelerations(q, s_dot)
for name, value in (("fast", fast), ("symbolic", symbolic)):
    print(f"{name}: relative difference to dense {np.abs(value - dense).max() / np.abs(dense).max():.1e}")
    assert np.abs(value - dense).max() < 1e-12 * np.abs(dense).max()  # the same round-off argument

t_end = 0.2 if os.environ.get("PROJEQ_QUICK") else 5.0
runs = {name: pq.simulate(system, t_end, rtol=1e-10, atol=1e-12, evaluator=name) for name in ("recursive", "dense")}
gap = np.abs(runs["recursive"].q[-1] - runs["dense"].q[-1]).max()
print(f"final angles differ by {gap:.1e} rad after {t_end:g} s")
assert gap < 1e-7  # two integrations at rtol 1e-10 of a chaotic chain: tolerance times growth

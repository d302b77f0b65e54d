"""A hanging chain of five links: simulate, check energy, save the result.

Run: python examples/chain.py  (PROJEQ_QUICK=1 shortens the run, as the tests do)
"""

import os

import projeq as pq

t_end = 1.0 if os.environ.get("PROJEQ_QUICK") else 10.0
system = pq.scenes.chain(5)
result = pq.simulate(system, t_end, method="DOP853", rtol=1e-10, atol=1e-12)
print(f"{len(result.t)} output times, {result.nfev} evaluations, energy drift {result.energy_drift:.1e}")
print("final joint angles:", result.q[-1].round(4))
result.save("chain.npz")

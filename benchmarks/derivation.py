"""Derivation effort of the symbolic Projection Equation vs sympy.physics.mechanics (issue 5 item 7).

The N-link pendulum (links of mass m, length l, inertia diag(J, J, J_a), gravity g; the
system of ``projeq.scenes.chain(N)``), N = 1…10 by default, all in one run:

* ``projeq``: ``gauss_form(scenes.chain(N), chain_parameters(N))`` — the recursive chain in
  body coordinates with composite inertias (THEORY §4, §6), scene construction included;
* ``velocities``: ``projection_equation`` from the inertial velocity expressions of
  ``n_link_pendulum(N)`` (B(10) as written; differentiates the velocities);
* ``kane``: ``KanesMethod`` (frames, points, ``kanes_equations``);
* ``lagrange``: ``LagrangesMethod`` (``Lagrangian``, ``form_lagranges_equations``).

sympy's cache is cleared before each derivation. Columns: derivation time (s), operation
count of [M, rhs] after ``sympy.cse`` (``count_ops`` over replacements and reduced
expressions, the same function for every method), the ratio kane/projeq of the times, and
``max_rel_diff``: the largest difference of M and rhs between all methods at 3 random
states and parameter sets, relative to the largest entry (round-off: ≲ 1e-12). Issue 5's
target: at N = 6, projeq ≥ 5× faster than KanesMethod with no larger operation count.

Run: ``python benchmarks/derivation.py [--json] [--no-lagrange] [N ...]`` (LagrangesMethod
dominates the run time from N ≈ 7).
"""

import json
import sys

import numpy as np
import sympy as sp

import projeq as pq
from projeq.studies.compare import _cse_ops, _timed
from projeq.symbolic import gauss_form, projection_equation
from projeq.symbolic.examples import (
    PENDULUM_PARAMETERS, chain_parameters, kane_pendulum, lagrange_pendulum, n_link_pendulum,
)


def timed(derive):
    """(q, speeds, M, rhs) of ``derive()`` and its wall time (s), sympy's cache cleared first."""
    sp.core.cache.clear_cache()
    return _timed(derive)


def projeq_system(n):
    gauss = gauss_form(pq.scenes.chain(n), chain_parameters(n))
    return gauss.q, gauss.s, gauss.M, gauss.rhs


def projeq_velocities(n):
    bodies, q, s, parameters = n_link_pendulum(n)
    gauss = projection_equation(bodies, q, s, parameters=parameters)
    return gauss.q, gauss.s, gauss.M, gauss.rhs


METHODS = {"projeq": projeq_system, "velocities": projeq_velocities, "kane": kane_pendulum,
           "lagrange": lagrange_pendulum}


def max_relative_difference(results: dict, n: int, rng) -> float:
    """Largest |M − M_ref|, |rhs − rhs_ref| over 3 random states, relative to the largest entry."""
    functions = {name: sp.lambdify([q, u, PENDULUM_PARAMETERS], [M, rhs], cse=True)
                 for name, (q, u, M, rhs) in results.items()}
    worst = 0.0
    for _ in range(3):
        state = rng.uniform(-np.pi, np.pi, n), rng.uniform(-3, 3, n), rng.uniform(0.5, 3.0, 5)
        values = [np.concatenate([np.ravel(np.asarray(x, float)) for x in f(*state)]) for f in functions.values()]
        scale = np.abs(values[0]).max()
        worst = max(worst, max(np.abs(v - values[0]).max() / scale for v in values[1:]))
    return float(worst)


def row(n, methods, rng):
    out = {"N": n}
    results = {}
    for name in methods:
        results[name], out[f"{name}_s"] = timed(lambda: METHODS[name](n))
    for name, (_, _, M, rhs) in results.items():
        out[f"{name}_ops"] = _cse_ops([M, rhs])
    out["kane/projeq"] = out["kane_s"] / out["projeq_s"]
    out["max_rel_diff"] = max_relative_difference(results, n, rng)
    return out


def main(sizes=tuple(range(1, 11)), as_json=False, lagrange=True):
    rng = np.random.default_rng(0)
    methods = [m for m in METHODS if lagrange or m != "lagrange"]
    for name in methods:  # warm-up: first-call imports and sympy's lazy set-up are not derivation time
        METHODS[name](1)
    rows = []
    for n in sizes:
        rows.append(row(n, methods, rng))
        if not as_json:
            if len(rows) == 1:
                print(" | ".join(f"{h:>14}" for h in rows[0]))
            print(" | ".join(f"{v:>14.4g}" if isinstance(v, float) else f"{v:>14}" for v in rows[-1].values()),
                  flush=True)
    if as_json:
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    args = sys.argv[1:]
    main(tuple(int(a) for a in args if not a.startswith("--")) or tuple(range(1, 11)), "--json" in args,
         "--no-lagrange" not in args)

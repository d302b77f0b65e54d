"""Derivation effort of the symbolic Projection Equation vs sympy.physics.mechanics
(``benchmarks/derivation.py``; ``projeq bench`` runs it for N = 2 and 4).

The N-link pendulum (links of mass m, length l, inertia diag(J, J, J_a), gravity g; the
system of ``projeq.scenes.chain(N)``):

* ``projeq``: ``gauss_form(scenes.chain(N), chain_parameters(N))`` — the recursive chain in
  body coordinates with composite inertias (docs/theory.md, the recursive pass), scene
  construction included;
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
"""

from __future__ import annotations

import math
import time

import numpy as np
import sympy as sp

from projeq import scenes
from projeq.symbolic import gauss_form, projection_equation
from projeq.symbolic.examples import (
    PENDULUM_PARAMETERS, chain_parameters, kane_pendulum, lagrange_pendulum, n_link_pendulum,
)
from projeq.symbolic.projection import operation_count


def projeq_system(n):
    gauss = gauss_form(scenes.chain(n), chain_parameters(n))
    return gauss.q, gauss.s, gauss.M, gauss.rhs


def projeq_velocities(n):
    bodies, q, s, parameters = n_link_pendulum(n)
    gauss = projection_equation(bodies, q, s, parameters=parameters)
    return gauss.q, gauss.s, gauss.M, gauss.rhs


METHODS = {"projeq": projeq_system, "velocities": projeq_velocities, "kane": kane_pendulum,
           "lagrange": lagrange_pendulum}


def timed(derive):
    """(q, speeds, M, rhs) of ``derive()`` and its wall time (s), sympy's cache cleared first."""
    sp.core.cache.clear_cache()
    started = time.perf_counter()
    out = derive()
    return out, time.perf_counter() - started


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


def row(n: int, methods, rng) -> dict:
    """Times, operation counts, kane/projeq and max_rel_diff of the N = n pendulum."""
    out = {"N": n}
    results = {}
    for name in methods:
        results[name], out[f"{name}_s"] = timed(lambda: METHODS[name](n))
    for name, (_, _, M, rhs) in results.items():
        out[f"{name}_ops"] = operation_count(*sp.cse([M, rhs]))
    out["kane/projeq"] = out["kane_s"] / out["projeq_s"]
    out["max_rel_diff"] = max_relative_difference(results, n, rng)
    return out


def derivation_effort(sizes=tuple(range(1, 11)), lagrange: bool = True, deadline: float = math.inf,
                      show=None) -> list[dict]:
    """One :func:`row` per N in ``sizes`` (``lagrange=False`` leaves LagrangesMethod out: it
    dominates the run time from N ≈ 7). ``deadline`` (a ``time.perf_counter()`` value) stops
    before the next N once passed; ``show``, e.g. ``print``, receives the table line by line."""
    rng = np.random.default_rng(0)
    methods = [m for m in METHODS if lagrange or m != "lagrange"]
    for name in methods:  # warm-up: first-call imports and sympy's lazy set-up are not derivation time
        METHODS[name](1)
    rows = []
    for n in sizes:
        if time.perf_counter() > deadline:
            break
        rows.append(row(n, methods, rng))
        if show is not None:
            if len(rows) == 1:
                show(" | ".join(f"{h:>14}" for h in rows[0]))
            show(" | ".join(f"{v:>14.4g}" if isinstance(v, float) else f"{v:>14}" for v in rows[-1].values()))
    return rows

"""Derivation effort of the symbolic Projection Equation and evaluation cost of its compiled form.

For the n-link pendulum (``projeq.symbolic.examples.n_link_pendulum``, the same system as
``projeq.scenes.chain(n)``), n = 2, 4, 8: derivation time of ``projection_equation``,
compile time and operation count after CSE of the evaluator, and the time per
``accelerations`` call of the compiled symbolic evaluator vs the numeric recursive one,
measured in one run. Prints a table, or JSON with ``--json``.

Run: ``python benchmarks/derivation.py [--json] [n ...]``
"""

import json
import sys
import time

import numpy as np

import projeq as pq
from projeq import inertia
from projeq.symbolic import projection_equation
from projeq.symbolic.examples import n_link_pendulum


def per_call(f, repeat=200):
    """Mean wall time of one call (s) over ``repeat`` calls."""
    start = time.perf_counter()
    for _ in range(repeat):
        f()
    return (time.perf_counter() - start) / repeat


def row(n, rng):
    bodies, q, s, parameters = n_link_pendulum(n)
    start = time.perf_counter()
    gauss = projection_equation(bodies, q, s, parameters=parameters)
    derive = time.perf_counter() - start
    I_c = inertia.cylinder(m=1.0, radius=0.01, length=1.0, axis="z")
    start = time.perf_counter()
    evaluator = gauss.evaluator(dict(zip(parameters, (1.0, 1.0, I_c[0, 0], I_c[2, 2], 9.81))))
    compile_time = time.perf_counter() - start
    system = pq.scenes.chain(n)
    q_n, s_n = rng.uniform(-np.pi, np.pi, n), rng.uniform(-3, 3, n)
    symbolic = per_call(lambda: evaluator.accelerations(q_n, s_n, 0.0))
    recursive_evaluator = system.evaluator("recursive")
    recursive = per_call(lambda: recursive_evaluator.accelerations(q_n, s_n, 0.0))
    error = float(np.abs(evaluator.accelerations(q_n, s_n, 0.0) - recursive_evaluator.accelerations(q_n, s_n, 0.0)).max())
    return {"n": n, "derive_s": derive, "compile_s": compile_time, "ops_after_cse": evaluator.n_ops,
            "symbolic_call_us": symbolic * 1e6, "recursive_call_us": recursive * 1e6,
            "symbolic/recursive": symbolic / recursive, "max_abs_diff": error}


def main(sizes=(2, 4, 8), as_json=False):
    rng = np.random.default_rng(0)
    rows = [row(n, rng) for n in sizes]
    if as_json:
        print(json.dumps(rows, indent=1))
        return
    header = list(rows[0])
    print(" | ".join(f"{h:>18}" for h in header))
    for r in rows:
        print(" | ".join(f"{v:>18.4g}" if isinstance(v, float) else f"{v:>18}" for v in r.values()))


if __name__ == "__main__":
    args = sys.argv[1:]
    main(tuple(int(a) for a in args if a != "--json") or (2, 4, 8), "--json" in args)

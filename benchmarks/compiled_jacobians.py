"""Exact Jacobians ∂ẋ/∂x by the complex step through the compiled kernels (issue 16): cost per
Jacobian, in ms and in units of one real compiled evaluation of ẋ, against the complex step
through the interpreted reference evaluators (projeq before the kernels took complex
arguments) and forward differences on the compiled path; and the agreement of the two complex
steps (largest difference / largest entry).

Columns: ``ẋ`` one real evaluation through the compiled evaluator (the unit), ``ẋ(z)`` one
complex evaluation through it (the complex128 specialization of the same kernels, a Python
call each); then per Jacobian: ``interpreted`` (the complex step through the numpy recursive evaluator, or the hub
beam's interpreted path), ``compiled`` (:func:`projeq.analysis.jacobians.state_jacobian`, the
default), ``per column`` (the complex step column by column through the compiled evaluator's
``accelerations``, a Python call per column), ``forward diff.`` (n + 1 real compiled
evaluations, for scale: not exact). CPU time, the best of ``--repeat`` batches of each, all in one
run.

    python benchmarks/compiled_jacobians.py [--repeat 7]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import projeq as pq
from projeq.analysis.differentiation import COMPLEX_STEP, exact_jacobian
from projeq.analysis.jacobians import state_jacobian
from projeq.assembly.beam_fast import HubBeamEvaluator


def models():
    return {
        "chain(10)": pq.scenes.chain(10),
        "flexible arm": pq.scenes.flexible_arm(),
        "spin-up beam": pq.scenes.spin_up_beam(),
        "flyball governor": pq.scenes.flyball_governor(),
    }


def state(system):
    rng = np.random.default_rng(0)
    q = np.asarray(system.q0, dtype=float) + 0.01 * rng.standard_normal(system.n_q)
    return np.concatenate((q, rng.standard_normal(system.n_s)))


def rhs(system, evaluator, t):
    n_q = system.n_q
    return lambda x: np.concatenate((system.q_dot(x[:n_q], x[n_q:], t), evaluator.accelerations(x[:n_q], x[n_q:], t)))


def best(f, repeat):
    """The least CPU time (process time: the other processes on a shared machine do not count)
    of one call of f, over ``repeat`` batches of calls that take at least 20 ms each."""
    f()
    calls = 1
    while True:
        start = time.process_time()
        for _ in range(calls):
            f()
        if time.process_time() - start >= 0.02:
            break
        calls *= 2
    times = []
    for _ in range(repeat):
        start = time.process_time()
        for _ in range(calls):
            f()
        times.append((time.process_time() - start) / calls)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()
    t = 0.3
    print(f"{'model':18} {'n_x':>4} {'ẋ µs':>7} {'ẋ(z) µs':>7} | {'interpreted':>17} | {'compiled':>17} | {'per column':>17} | "
          f"{'forward diff.':>17} | {'agree':>8}")
    for name, system in models().items():
        x = state(system)
        compiled = system.evaluator()
        reference = HubBeamEvaluator(system, compiled=False) if compiled.name == "hub_beam" \
            else system.evaluator("dense" if system.coupled else "recursive")
        f, f_reference = rhs(system, compiled, t), rhs(system, reference, t)
        unit = best(lambda: f(x), args.repeat)
        z = x + 1j * COMPLEX_STEP * np.eye(len(x))[0]
        complex_call = best(lambda: f(z), args.repeat)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            J_reference = exact_jacobian(f_reference, x)
        J = state_jacobian(system, x, t)[0]
        rows = {
            "interpreted": lambda: exact_jacobian(f_reference, x),
            "compiled": lambda: state_jacobian(system, x, t),
            "per column": lambda: exact_jacobian(f, x),
            "forward diff.": lambda: forward(f, x),
        }
        costs = {label: best(run, args.repeat) for label, run in rows.items()}
        unit = min(unit, best(lambda: f(x), args.repeat))  # measured again: the least of both, as each row
        cells = [f"{cost * 1e3:8.3f} ms {cost / unit:5.0f}×" for cost in costs.values()]
        agree = np.abs(J - J_reference).max() / np.abs(J_reference).max()
        print(f"{name:18} {len(x):4d} {unit * 1e6:7.1f} {complex_call * 1e6:7.1f} | " + " | ".join(cells)
              + f" | {agree:8.1e}")


def forward(f, x):
    f0, h = f(x), 1.5e-8
    return np.column_stack([(f(x + h * max(1.0, abs(x[k])) * e) - f0) / (h * max(1.0, abs(x[k])))
                            for k, e in enumerate(np.eye(len(x)))])


if __name__ == "__main__":
    main()

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
run. "chain(10) + laws" is chain(10) with every force law kind that has a compiled row (a
damped joint spring on each joint, a joint force, a body force and torque, spring-dampers to the
ground and between links): with the flyball governor (two SpringDampers), one compiled call
since the loads loop runs inside kernels.tree_jacobian.

``--flyball``: IFToMM A05, the flyball governor over 10 s with simulate's default (Radau,
jac="exact", rtol 1e-8), its Jacobians in one compiled call and, in the same process, column
by column (the evaluator's one-call Jacobian switched off: what projeq did before the loads
loop ran inside the Jacobian kernel), each the best CPU time of ``--runs`` alternating runs.

    python benchmarks/compiled_jacobians.py [--repeat 7] [--flyball [--runs 2]]
    python benchmarks/compiled_jacobians.py --quick   # chain(10) and the spin-up beam, then A05 over 0.1 s
"""

from __future__ import annotations

import os
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
        "chain(10) + laws": chain_with_laws(10),
        "flexible arm": pq.scenes.flexible_arm(),
        "spin-up beam": pq.scenes.spin_up_beam(),
        "flyball governor": pq.scenes.flyball_governor(),
    }


def chain_with_laws(n: int) -> pq.System:
    """chain(n) with every force law kind that has a compiled row (module docstring)."""
    chain = pq.scenes.chain(n)
    names = list(chain.names)
    laws = [pq.JointSpring(name, stiffness=50.0, damping=2.0, q_ref=0.1) for name in names]
    laws += [pq.JointForce(names[0], [1.5]), pq.Force(names[-1], (0.0, 2.0, 1.0), point=(0.0, 0.0, -0.5)),
             pq.Torque(names[1], (0.3, 0.0, 0.1), frame="body"),
             pq.SpringDamper(None, (0.5, 0.3, 0.0), names[-1], (0.0, 0.0, -1.0), 400.0, 5.0, 1.0),
             pq.SpringDamper(names[1], (0.0, 0.0, -1.0), names[-2], (0.0, 0.0, -0.5), 200.0, 3.0, 1.5)]
    return pq.System(dict(zip(names, chain.subsystems)), dict(zip(names, chain.joints)),
                     gravity=chain.gravity, q0=chain.q0, forces=laws)


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


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--flyball", action="store_true", help="A05 over 10 s: one-call vs per-column Jacobians")
    parser.add_argument("--runs", type=int, default=2)
    parser.add_argument("--quick", action="store_true",
                        help="the table for chain(10) and the spin-up beam, then A05 over 0.1 s, once each")
    args = parser.parse_args(argv)
    if args.quick:
        table({k: v for k, v in models().items() if k in ("chain(10)", "spin-up beam")}, 1)
        return flyball(1, 0.1)
    if args.flyball:
        return flyball(args.runs)
    table(models(), args.repeat)


def table(systems: dict, repeat: int) -> None:
    """The Jacobians' costs of each model (module docstring), ``repeat`` batches each."""
    t = 0.3
    print(f"{'model':18} {'n_x':>4} {'ẋ µs':>7} {'ẋ(z) µs':>7} | {'interpreted':>17} | {'compiled':>17} | {'per column':>17} | "
          f"{'forward diff.':>17} | {'agree':>8}")
    for name, system in systems.items():
        x = state(system)
        compiled = system.evaluator()
        reference = HubBeamEvaluator(system, compiled=False) if compiled.name == "hub_beam" \
            else system.evaluator("dense" if system.coupled else "recursive")
        f, f_reference = rhs(system, compiled, t), rhs(system, reference, t)
        unit = best(lambda: f(x), repeat)
        z = x + 1j * COMPLEX_STEP * np.eye(len(x))[0]
        complex_call = best(lambda: f(z), repeat)
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
        costs = {label: best(run, repeat) for label, run in rows.items()}
        unit = min(unit, best(lambda: f(x), repeat))  # measured again: the least of both, as each row
        cells = [f"{cost * 1e3:8.3f} ms {cost / unit:5.0f}×" for cost in costs.values()]
        agree = np.abs(J - J_reference).max() / np.abs(J_reference).max()
        print(f"{name:18} {len(x):4d} {unit * 1e6:7.1f} {complex_call * 1e6:7.1f} | " + " | ".join(cells)
              + f" | {agree:8.1e}")


def flyball(runs: int, t_end: float = 10.0) -> None:
    """The flyball governor's default run (module docstring) to ``t_end`` stepped by solve_ivp with the exact
    Jacobians this study times (the compiled loop switched off here: its Radau forms ∂ẋ/∂x by differences
    inside the loop), one-call vs per-column Jacobians: the CPU time of the whole run and of its
    Jacobians (simulate's ``_Run.jacobian``, timed)."""
    from projeq.simulation import driver

    system = pq.scenes.flyball_governor()
    evaluator = system.evaluator()
    one_call, jacobian = evaluator.state_jacobian, driver._Run.jacobian
    spent = [0.0]

    def timed(run, t, x):
        start = time.process_time()
        J = jacobian(run, t, x)
        spent[0] += time.process_time() - start
        return J

    driver._Run.jacobian = timed
    compiled_loop, driver._Run.compiled_loop = driver._Run.compiled_loop, lambda run: None
    results = {}
    for _ in range(runs):
        for label, way in (("one call", one_call), ("per column", lambda t, x: None)):
            evaluator.state_jacobian, spent[0] = way, 0.0
            start = time.process_time()
            r = pq.simulate(system, t_end)
            cpu = time.process_time() - start
            if label not in results or cpu < results[label][0]:
                results[label] = (cpu, spent[0], r)
    evaluator.state_jacobian, driver._Run.jacobian, driver._Run.compiled_loop = one_call, jacobian, compiled_loop
    print(f"{'Jacobians':12} {'method':>7} {'CPU s':>7} {'of which ∂ẋ/∂x':>15} {'nfev':>7} {'njev':>6}  final state")
    for label, (cpu, in_jacobians, r) in results.items():
        print(f"{label:12} {r.method:>7} {cpu:7.2f} {in_jacobians:15.2f} {r.nfev:7d} {r.njev:6d}  "
              f"{np.r_[r.q[-1], r.s_dot[-1]]}")
    (one, one_J, _), (column, column_J, _) = results["one call"], results["per column"]
    print(f"per column / one call: run {column / one:.2f}, Jacobians {column_J / one_J:.2f}")


def forward(f, x):
    f0, h = f(x), 1.5e-8
    return np.column_stack([(f(x + h * max(1.0, abs(x[k])) * e) - f0) / (h * max(1.0, abs(x[k])))
                            for k, e in enumerate(np.eye(len(x)))])


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

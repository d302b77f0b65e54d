"""The flexible arm of the compiled-by-default issue against its rigid twin, both by
``simulate(system, 5.0)`` with no knobs (``scenes.flexible_arm``: three links turning about z
under gravity, the last a 0.8 m RitzBeam with four bending functions and a 0.3 kg tip mass, or
a rigid rod of the same mass). Prints, from one run: the evaluator and integrator each
default picked, CPU seconds, evaluations of s̈, their ratio, and the flexible arm's final
state error against a converged reference (DOP853 at rtol 1e-11, atol 1e-13: its own error
is checked by the difference to a run at rtol 1e-10).

    python benchmarks/flexible_arm.py             # 5 s, as in the issue
    python benchmarks/flexible_arm.py --t-end 1   # shorter
    python benchmarks/flexible_arm.py --quick     # 10 ms, and Radau besides (a test runs it)
    python benchmarks/flexible_arm.py --methods RK45 Radau BDF   # and the flexible arm by these
                                                                  # methods (implicit: exact Jacobian)
"""

from __future__ import annotations

import os
import argparse
import time
import warnings

import numpy as np

import projeq as pq
from projeq.studies.table import Table


def run(system, t_end: float, **options) -> tuple:
    """(final state x = (q, ṡ), CPU seconds, Result) of one simulate call."""
    started = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("error", pq.assembly.InterpretedWarning)  # the default must be compiled
        result = pq.simulate(system, t_end, n_points=2, **options)
    return np.concatenate((result.q[-1], result.s_dot[-1])), time.process_time() - started, result


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--t-end", type=float, default=5.0, help="simulated seconds (default 5)")
    parser.add_argument("--methods", nargs="*", default=(), help="further methods for the flexible arm, same tolerances")
    parser.add_argument("--quick", action="store_true", help="10 ms (--t-end 0.01 --methods Radau)")
    args = parser.parse_args(argv)
    if args.quick:
        args.t_end, args.methods = 0.01, ("Radau",)
    rigid, flexible = pq.scenes.flexible_arm(rigid_last_link=True), pq.scenes.flexible_arm()
    for system in (rigid, flexible):  # compile (or load) the kernels simulate calls outside the timings
        run(system, 1e-3)
    _, rigid_cpu, rigid_result = run(rigid, args.t_end)
    x, cpu, result = run(flexible, args.t_end)
    reference = run(flexible, args.t_end, method="DOP853", rtol=1e-11, atol=1e-13)[0]
    coarser = run(flexible, args.t_end, method="DOP853", rtol=1e-10, atol=1e-12)[0]
    rows = [
        ("rigid last link", rigid.evaluator().name, rigid_result.method, rigid_cpu, rigid_result.nfev, rigid_result.njev,
         1.0, float("nan")),
        ("RitzBeam, 4 functions", flexible.evaluator().name, result.method, cpu, result.nfev, result.njev, cpu / rigid_cpu,
         float(np.abs(x - reference).max())),
    ]
    for method in args.methods:
        x, cpu, result = run(flexible, args.t_end, method=method)
        rows.append(("RitzBeam, 4 functions", flexible.evaluator().name, method, cpu, result.nfev, result.njev,
                     cpu / rigid_cpu, float(np.abs(x - reference).max())))
    table = Table(("arm", "evaluator", "method", "cpu", "nfev", "njev", "cpu ratio", "error"), rows, units={"cpu": "s"},
                  formats={"cpu": ".2f", "cpu ratio": ".1f", "error": ".1e"},
                  title=(f"flexible arm vs rigid twin, simulate(system, {args.t_end:g}) defaults; error = max |x(t_end) − "
                         f"x_ref| (reference's own: {np.abs(coarser - reference).max():.1e})"))
    print(table.to_text())
    return table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

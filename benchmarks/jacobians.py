"""Implicit integrators with exact Jacobians (issue 16): evaluation counts and wall time of
Radau and BDF on stiff elastic models with scipy's finite-difference Jacobian
(``jac="differences"``) and with the complex step through the model (``jac="exact"``, the
default of :func:`projeq.simulate` for the implicit methods).

Counted: real evaluations of s̈ (the integrator's right-hand sides plus scipy's difference
Jacobians, which solve_ivp's ``nfev`` leaves out), the complex evaluations of the exact
Jacobians (n_x per Jacobian), and the wall time, all in one run. The end states of both
runs are compared (they must agree to the tolerance).

    python benchmarks/jacobians.py [--t-end 0.2] [--rtol 1e-6]
    python benchmarks/jacobians.py --quick     # the elastic arm with 3 shapes over 10 ms (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import time

import numpy as np

import projeq as pq


def models():
    """Stiff elastic models: the flexible arm (a RitzBeam on a revolute hub with a tip mass)
    and a clamped beam spun up about its hub, each with more Ritz functions than by default."""
    return {
        "elastic_arm (3 shapes)": pq.scenes.elastic_arm(),
        "elastic_arm (5 shapes)": pq.scenes.elastic_arm(n_shapes=5),
        "spin_up_beam": pq.scenes.spin_up_beam(),
    }


def run(system, method, jac, t_end, rtol):
    evaluator = system.evaluator().evaluator  # the one "auto" picked: it counts its calls, complex ones too
    before = evaluator.n_calls
    start = time.perf_counter()
    try:
        result = pq.simulate(system, t_end, method=method, jac=jac, rtol=rtol, atol=rtol * 1e-3, n_points=3,
                             n_segments=1)
    except pq.SimulationError as exc:  # e.g. scipy's difference Jacobian overflowing on a stiff beam
        result = exc.result
    wall = time.perf_counter() - start
    n_x = system.n_q + system.n_s
    complex_calls = result.njev * n_x if jac == "exact" else 0
    return evaluator.n_calls - before - complex_calls, complex_calls, wall, result


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=0.2)
    parser.add_argument("--rtol", type=float, default=1e-6)
    parser.add_argument("--quick", action="store_true", help="the elastic arm with 3 shapes over 10 ms")
    args = parser.parse_args(argv)
    systems = models()
    if args.quick:
        args.t_end, systems = 0.01, {"elastic_arm (3 shapes)": systems["elastic_arm (3 shapes)"]}
    print(f"t_end = {args.t_end} s, rtol = {args.rtol}; real / complex evaluations of s̈, wall time")
    print(f"{'model':24} {'method':6} {'jac':12} {'real':>8} {'complex':>8} {'wall s':>8} {'Δq_end':>9}  reached")
    for name, system in systems.items():
        for method in ("Radau", "BDF"):
            ends = []
            for jac in ("differences", "exact"):
                real, cplx, wall, result = run(system, method, jac, args.t_end, args.rtol)
                ends.append(result.q[-1] if result.status == 0 else np.full(system.n_q, np.nan))
                diff = np.abs(ends[-1] - ends[0]).max()
                t_reached = result.t[-1] if len(result.t) else 0.0
                reached = "t_end" if result.status == 0 else f"failed at t = {t_reached:.3g} s: {result.message[:40]}"
                print(f"{name:24} {method:6} {jac:12} {real:8d} {cplx:8d} {wall:8.2f} {diff:9.1e}  {reached}")


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

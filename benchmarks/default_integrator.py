"""Which integrator should ``simulate``'s default be for a stiff elastic model? The
spin-up beam (``projeq run``'s default scene, ``scenes.spin_up_beam()``) over ``--t-end``
seconds with explicit and implicit methods of solve_ivp at several tolerances: CPU time,
evaluations of s̈, and the largest deviation of the final state (q, ṡ) from a DOP853 run
at rtol 1e-11, all in one run (compare the ratios; absolute seconds are this machine's).

    python benchmarks/default_integrator.py               # 5 s of the spin-up
    python benchmarks/default_integrator.py --t-end 20    # the scene's full 20 s (minutes)
    python benchmarks/default_integrator.py --scene chain5 --runs default RK45 DOP853   # another model,
                                                          # at simulate's default tolerances

``--runs default RK45 ...`` runs each named method at simulate's default tolerances (rtol 1e-8,
atol 1e-10; "default": no method given, the row names the one ``default_method`` chose)
instead of the table of tolerances.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import projeq as pq
from projeq.studies.table import Table

SCENES = {
    "spin_up_beam": pq.scenes.spin_up_beam, "chain5": lambda: pq.scenes.chain(5), "elastic_arm": pq.scenes.elastic_arm,
    "rigid_arm": lambda: pq.scenes.flexible_arm(rigid_last_link=True), "flexible_arm": pq.scenes.flexible_arm,
}
RUNS = (("RK45", 1e-6, 1e-9), ("DOP853", 1e-6, 1e-9), ("Radau", 1e-6, 1e-9), ("BDF", 1e-6, 1e-9),
        ("RK45", 1e-8, 1e-10), ("DOP853", 1e-9, 1e-11), ("Radau", 1e-8, 1e-10))


def final_state(system, t_end: float, method: str | None, rtol: float = 1e-8, atol: float = 1e-10) -> tuple:
    """(x(t_end), CPU seconds, evaluations, Result) of one run."""
    started = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the StiffnessWarning of the explicit methods: measured here instead
        result = pq.simulate(system, t_end, method=method, rtol=rtol, atol=atol, n_points=2)
    return np.concatenate((result.q[-1], result.s_dot[-1])), time.process_time() - started, result.nfev, result


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--t-end", type=float, default=5.0, help="simulated seconds (default 5)")
    parser.add_argument("--scene", choices=sorted(SCENES), default="spin_up_beam", help="the model (default spin_up_beam)")
    parser.add_argument("--runs", nargs="*", help="methods at the default tolerances ('default': simulate's choice)")
    args = parser.parse_args(argv)
    system = SCENES[args.scene]()
    system.accelerations(system.q0, system.s_dot0)  # compile (or load the compiled kernel) outside the timings
    reference = final_state(system, args.t_end, "DOP853", 1e-11, 1e-13)[0]
    runs = [(None if m == "default" else m, 1e-8, 1e-10) for m in args.runs] if args.runs else RUNS
    rows = []
    for method, rtol, atol in runs:
        x, cpu, nfev, result = final_state(system, args.t_end, method, rtol, atol)
        rows.append((result.method + " (default)" * (method is None), rtol, cpu, nfev, result.njev,
                     float(np.abs(x - reference).max())))
    table = Table(("method", "rtol", "cpu", "nfev", "njev", "error"), rows, units={"cpu": "s"},
                  formats={"rtol": ".0e", "cpu": ".2f", "error": ".1e"},
                  title=f"{args.scene}, {args.t_end:g} s: error = max |x(t_end) − x_ref| (DOP853, rtol 1e-11)")
    print(table.to_text())
    return table


if __name__ == "__main__":
    main()

"""Where ``simulate`` spends its CPU on a long chain: the share of the right-hand side ẋ (the
compiled model's evaluations) against the rest (the integrator's Python stepping, the output rows'
energies and residuals, the per-segment checks), warm (compilation excluded).

``simulate(scenes.chain(n), t_end)`` at its defaults; the ẋ share is the number of evaluations
times the CPU of one compiled ẋ of the same model called alone in a loop, over the CPU of the run;
the rows' share is the CPU of the Result's rows formed together as simulate forms them
(:meth:`projeq.System.output_rows`: the compiled kinematics of all rows, the energies, residuals). Issue 34's bound: ≥ 70 % in model evaluations for chain(5000)
over 0.01 s (before: 2.2 of 20.8 s, the default choice formed a dense ∂ẋ/∂x).

    PYTHONPATH=. python benchmarks/simulate_share.py [--n 5000] [--t-end 0.01]
    PYTHONPATH=. python benchmarks/simulate_share.py --quick     # chain(200) over 1 ms
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from projeq import scenes, simulate
from projeq.studies.table import Table


def per_call(f, repeats: int) -> float:
    """CPU seconds of one call of f, the mean of ``repeats`` calls after one."""
    f()
    started = time.process_time()
    for _ in range(repeats):
        f()
    return (time.process_time() - started) / repeats


def share(n: int, t_end: float) -> list:
    """[n, t_end, method, evaluations, rows, run CPU, ẋ CPU, ẋ share, rows CPU, rows share]."""
    system = scenes.chain(n)
    simulate(system, t_end / 10)  # compiled, or loaded from the cache
    started = time.process_time()
    result = simulate(system, t_end)
    run = time.process_time() - started
    evaluator, x = system.evaluator(), np.concatenate((system.q0, system.s_dot0))
    x_dot = per_call(lambda: evaluator.state_derivative(0.0, x), 20)
    rows = len(result.t)
    together = per_call(lambda: system.output_rows(result.q, result.s_dot, result.t), 1)  # as simulate forms them
    return [n, t_end, result.method, result.nfev, rows, run, result.nfev * x_dot, result.nfev * x_dot / run,
            together, together / run]


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=5000, help="bodies of the chain (default 5000)")
    parser.add_argument("--t-end", type=float, default=0.01, help="simulated seconds (default 0.01)")
    parser.add_argument("--quick", action="store_true", help="chain(200) over 1 ms")
    args = parser.parse_args(argv)
    n, t_end = (200, 1e-3) if args.quick else (args.n, args.t_end)
    columns = ["n", "t_end", "method", "evaluations", "rows", "run CPU", "ẋ CPU", "ẋ share", "rows CPU", "rows share"]
    table = Table(columns, [share(n, t_end)], units={"t_end": "s", "run CPU": "s", "ẋ CPU": "s", "rows CPU": "s"},
                  formats={"ẋ share": ".0%", "rows share": ".0%", "run CPU": ".2f", "ẋ CPU": ".2f", "rows CPU": ".2f"},
                  title="simulate(scenes.chain(n), t_end) at its defaults, warm: where the CPU goes")
    print(table.to_text())
    return table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

"""CPU per evaluation of ``simulate``: what the integration loop costs around the model, per scene.

For each scene of issue 34's list, ``simulate(scene, t_end)`` at its defaults (the method it
chooses, 501 output rows with their energies and residuals), warm (compilation excluded), twice
alternately: as it runs by default (the compiled integration loop, :mod:`projeq.simulation.loop`,
where the model has a compiled one-call ẋ; Radau's Jacobian columns, n_x evaluations each, counted as
evaluations) and with scipy's ``solve_ivp`` stepping the same method
(``method=`` the scipy class). *CPU per evaluation* = the run's CPU ÷ its ẋ evaluations ÷ the CPU
of one compiled ẋ of the same model called alone in a loop (issue 34's definition; its bound 1.5);
"without rows" the same of a run with two output rows (``n_points=2``: the same steps and evaluations,
the output rows' energies, residuals and projections left out), to tell the loop's share from the rows'.
Each run's CPU is the least of ``--repeats`` alternating rounds.

    PYTHONPATH=. python benchmarks/loop_overhead.py [--t-end 2] [--repeats 3] [--scenes flyball_governor]
    PYTHONPATH=. python benchmarks/loop_overhead.py --quick     # chain and rolling disk, 0.2 s, one round
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
import scipy.integrate

from projeq import scenes, simulate
from projeq.studies.table import Table

SCENES = ("four_bar", "car", "flyball_governor", "chain", "double_pendulum", "rolling_disk", "whipple_bicycle")


def x_dot_cpu(system, seconds: float = 0.3) -> float:
    """CPU seconds of one compiled ẋ of ``system`` at its initial state, called alone in a loop."""
    evaluator, x = system.evaluator(), np.concatenate((system.q0, system.s_dot0))
    f = getattr(evaluator, "state_derivative", None)
    call = (lambda: f(0.0, x)) if f is not None else (lambda: evaluator.accelerations(system.q0, system.s_dot0, 0.0))
    call()
    repeats, started = 1, time.process_time()
    while time.process_time() - started < 0.02:
        call()
        repeats += 1
    repeats = max(1, int(repeats * seconds / 0.02))
    started = time.process_time()
    for _ in range(repeats):
        call()
    return (time.process_time() - started) / repeats


def run_cpu(system, t_end: float, method, **options) -> tuple[float, object]:
    """(CPU seconds, Result) of one run."""
    started = time.process_time()
    result = simulate(system, t_end, method=method, **options)
    return time.process_time() - started, result


def row(name: str, t_end: float, repeats: int) -> list:
    """[scene, method, evaluations, ẋ µs, per evaluation (default), the same without its output rows,
    per evaluation (scipy), scipy / default]."""
    system = getattr(scenes, name)()
    chosen = simulate(system, t_end).method  # warm: compiles (or loads) the model and the loop
    scipy_method = getattr(scipy.integrate, chosen.split(",")[0])
    best = {"default": np.inf, "scipy": np.inf, "no rows": np.inf}
    nfev = {}
    for _ in range(repeats):
        for label, method, options in (("default", None, {}), ("scipy", scipy_method, {}),
                                       ("no rows", None, {"n_points": 2})):
            cpu, result = run_cpu(system, t_end, method, **options)
            best[label], nfev[label] = min(best[label], cpu), result.nfev
    x_dot = x_dot_cpu(system)
    default, scipy_ = best["default"] / nfev["default"] / x_dot, best["scipy"] / nfev["scipy"] / x_dot
    return [name, chosen, nfev["default"], x_dot * 1e6, default, best["no rows"] / nfev["no rows"] / x_dot, scipy_,
            scipy_ / default]


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=2.0, help="simulated seconds (default 2)")
    parser.add_argument("--repeats", type=int, default=3, help="alternating rounds per scene (default 3)")
    parser.add_argument("--scenes", nargs="+", choices=SCENES, default=SCENES, help="the scenes (default all)")
    parser.add_argument("--quick", action="store_true", help="chain and rolling disk, 0.2 s, one round")
    args = parser.parse_args(argv)
    names, t_end, repeats = ((("chain", "rolling_disk"), 0.2, 1) if args.quick
                             else (tuple(args.scenes), args.t_end, args.repeats))
    rows = [row(name, t_end, repeats) for name in names]
    table = Table(["scene", "method", "evaluations", "ẋ", "per evaluation", "without rows", "scipy's loop",
                   "scipy / default"], rows,
                  units={"ẋ": "µs"}, formats={"ẋ": ".1f", "per evaluation": ".2f", "without rows": ".2f",
                                              "scipy's loop": ".2f", "scipy / default": ".2f"},
                  title=f"simulate(scene, {t_end:g}) at its defaults, warm: CPU per evaluation (run CPU / evaluations / "
                        "one compiled ẋ alone; issue 34's bound 1.5), by default and with scipy's solve_ivp stepping")
    print(table.to_text())
    return table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

"""projeq's compiled integration loop against CyRK's numba Runge–Kutta solver (``CyRK.nbsolve_ivp``), the
well-kept library issue 34 names, on the same compiled ẋ kernel, side by side in one run.

For each model (trees: the ẋ kernel of :meth:`projeq.assembly.fast.FastEvaluator.loop_model`), over
``--t-end`` at rtol 1e-8, atol 1e-10 with 501 output times, RK45 and DOP853:

- CPU of one warm run: projeq's loop (:class:`projeq.simulation.loop.CompiledLoop`, one segment, the
  rows at the output times) and CyRK's ``nbsolve_ivp`` (the same kernel wrapped in a numba function
  ``diffeq(t, y, *args)`` that returns a new array per call, as CyRK asks);
- the largest difference of their final states (both follow scipy's algorithm);
- the CPU of the first call of each for a model of the same kernel signature: what a new model costs
  (CyRK is compiled once per ``diffeq`` function and argument types, projeq's loop once per kernel
  signature; both read the model's arrays as data).

Compilation: the first model of each kind is run once before the timings (its CPU in "first call").

    pip install cyrk                                   # the peer (not a dependency of projeq)
    PYTHONPATH=. python benchmarks/loop_vs_cyrk.py [--t-end 2]
    PYTHONPATH=. python benchmarks/loop_vs_cyrk.py --quick   # chain(3) over 0.05 s

CyRK's solver is compiled in every process (about 25 s of CPU: numba does not keep it on disk), so the
quick mode takes that long where CyRK is installed, and a second without it (CI).
"""

from __future__ import annotations

import argparse
import functools
import os
import time

import numpy as np

from projeq import scenes
from projeq.assembly import kernels
from projeq.simulation import loop
from projeq.studies.table import Table

METHODS = {"RK45": 1, "DOP853": 2}  # CyRK's rk_method numbers
RTOL, ATOL = 1e-8, 1e-10


def cyrk():
    """CyRK's ``nbsolve_ivp``, or None where CyRK is not installed."""
    try:
        from CyRK import nbsolve_ivp
    except ImportError:
        return None
    return nbsolve_ivp


@functools.cache
def diffeq(kernel):
    """The ẋ kernel as CyRK's ``diffeq(t, y, pre, tree, post, n_q) -> ẏ`` (one per kernel: CyRK is
    compiled for it once, as projeq's loop is)."""
    numba = kernels.numba_module()

    @numba.njit
    def f(t, y, pre, tree, post, n_q):
        out = np.empty_like(y)
        kernel(*pre, t, *tree, y, n_q, *post, out)
        return out

    return f


def timed(call) -> tuple[float, object]:
    """(CPU seconds, value) of ``call()``."""
    started = time.process_time()
    value = call()
    return time.process_time() - started, value


def runs(system, t_end: float, method: str, solver):
    """(projeq's call, CyRK's call or None) of one run of ``system``'s ẋ, each returning the final state."""
    model = system.evaluator("fast").loop_model()
    x0 = np.concatenate((system.q0, system.s_dot0))
    t_eval = np.linspace(0.0, t_end, 501)
    compiled = loop.CompiledLoop(model, method)

    def projeq_run():
        return compiled.run(system.n_q, 0.0, x0, t_end, 0.0, np.inf, RTOL, ATOL, t_eval).state

    if solver is None:
        return projeq_run, None

    def cyrk_run():
        result = solver(diffeq(model.kernel), (0.0, t_end), x0, args=(model.pre, model.tree, model.post, system.n_q),
                        rtol=RTOL, atol=ATOL, rk_method=METHODS[method], t_eval=t_eval, warnings=False)
        assert result.success, result.message
        return result.y[:, -1]

    return projeq_run, cyrk_run


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=2.0, help="simulated seconds (default 2)")
    parser.add_argument("--quick", action="store_true", help="chain(3) over 0.05 s")
    args = parser.parse_args(argv)
    solver = cyrk()
    if solver is None:
        print("CyRK is not installed (pip install cyrk): projeq's loop alone")
    models = {"chain(3)": (lambda: scenes.chain(3), lambda: scenes.chain(4))} if args.quick else {
        "chain(5)": (lambda: scenes.chain(5), lambda: scenes.chain(7)),
        "double_pendulum": (scenes.double_pendulum, lambda: scenes.double_pendulum(m1=2.0)),
        "rolling_disk": (scenes.rolling_disk, lambda: scenes.rolling_disk(inertia="hoop"))}
    t_end = 0.05 if args.quick else args.t_end
    rows = []
    for name, (build, other) in models.items():
        for method in METHODS:
            firsts = [timed(call)[0] if call else float("nan") for call in runs(build(), t_end, method, solver)]
            news = [timed(call)[0] if call else float("nan") for call in runs(other(), t_end, method, solver)]
            calls = runs(build(), t_end, method, solver)
            (mine, x_mine), (theirs, x_theirs) = (timed(c) if c else (float("nan"), None) for c in calls)
            difference = float(np.abs(x_mine - x_theirs).max()) if x_theirs is not None else float("nan")
            rows.append([name, method, mine * 1e3, theirs * 1e3, theirs / mine, difference, *firsts, *news])
    table = Table(["model", "method", "projeq run", "CyRK run", "CyRK/projeq", "final-state difference",
                   "projeq first call", "CyRK first call", "projeq new model", "CyRK new model"], rows,
                  units={"projeq run": "ms", "CyRK run": "ms", "projeq first call": "s", "CyRK first call": "s",
                         "projeq new model": "s", "CyRK new model": "s"},
                  formats={"projeq run": ".2f", "CyRK run": ".2f", "CyRK/projeq": ".2f", "final-state difference": ".1e",
                           "projeq first call": ".2f", "CyRK first call": ".2f", "projeq new model": ".3f",
                           "CyRK new model": ".3f"},
                  title=f"one compiled ẋ kernel, two loops: {t_end:g} s, rtol {RTOL:g}, atol {ATOL:g}, 501 output "
                        "times, CPU (warm runs; first call: compilation or disk cache)")
    print(table.to_text())
    return table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path

if __name__ == "__main__":
    main()

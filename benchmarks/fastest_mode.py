"""simulate's default integrator check (:func:`projeq.simulation.driver.default_method`): the
fastest mode of ∂ẋ/∂x at each registered scene's initial state, before and after it became
exact (issue 16), its CPU cost and the integrator each gives over the scene's own run (t_end of
the registry, simulate's default rtol 1e-8).

Columns: ``ρ fd`` power iteration on forward-difference products (before: the right-hand side
wrapped so that it takes no complex state, which is also the fall-back of
:func:`projeq.simulation.integrators.fastest_mode` now), ``ρ exact`` fastest_mode as
default_method calls it now, by ``way``: "one call" the eigenvalues of the evaluator's one-call
exact Jacobian (``state_jacobian``), "columns" the eigenvalues of the complex-step Jacobian
taken column by column (n_x ≤ 32), "power" power iteration on complex-step products; a "d"
marks a fastest mode that decays (a real eigenvalue −ρ). ``fd``, ``default``: the method
default_method picks before and now; then the cost of each check in ms (CPU, the best of
``--repeat``) and in real evaluations of ẋ, and after/before.

    python benchmarks/fastest_mode.py [--repeat 5]
    python benchmarks/fastest_mode.py --quick   # the double pendulum and the four-bar, once (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import time
import warnings

import numpy as np

from projeq import scenes
from projeq.simulation import driver
from projeq.simulation.integrators import fastest_mode


def best(f, repeat: int) -> float:
    """The least CPU time of one call of f over ``repeat`` calls (after one to warm up)."""
    f()
    times = []
    for _ in range(repeat):
        start = time.process_time()
        f()
        times.append(time.process_time() - start)
    return min(times)


def real_only(fun):
    """fun, refusing complex states (as a user callable that casts to float would)."""
    def f(t, x):
        if np.iscomplexobj(x):
            raise TypeError("real states only")
        return fun(t, x)
    return f


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--quick", action="store_true", help="the double pendulum and the four-bar, once")
    args = parser.parse_args(argv)
    names, repeat = (("double_pendulum", "four_bar"), 1) if args.quick else (list(scenes.SCENES), args.repeat)
    print(f"{'scene':22} {'n_x':>4} {'t_end':>6} | {'ρ fd':>11} {'ρ exact':>11} {'way':>8} | {'fd':>6} "
          f"{'default':>7} | {'fd ms':>7} {'exact ms':>8} | {'ẋ µs':>7} {'fd/ẋ':>5} {'exact/ẋ':>7} {'ratio':>5}")
    for name in names:
        scene = scenes.get_scene(name)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            system = scene.build()
            evaluator = system.evaluator()
            q0, s_dot0 = np.asarray(system.q0, dtype=float), np.asarray(system.s_dot0, dtype=float)
            x0, t_end = np.concatenate((q0, s_dot0)), scene.t_end

            def rhs(t, x, system=system, evaluator=evaluator):
                q, s_dot = x[: system.n_q], x[system.n_q:]
                return np.concatenate((system.q_dot(q, s_dot, t), evaluator.accelerations(q, s_dot, t)))

            one_call = getattr(evaluator, "state_jacobian", None)
            way = "one call" if one_call is not None and one_call(0.0, x0) is not None \
                else "columns" if len(x0) <= 32 else "power"
            before, after = (lambda: fastest_mode(real_only(rhs), 0.0, x0)), \
                (lambda: fastest_mode(rhs, 0.0, x0, jacobian=one_call))
            (rho_fd, decays_fd), (rho, decays) = before(), after()
            cost_fd, cost = best(before, repeat), best(after, repeat)
            unit = best(lambda: rhs(0.0, x0), 50)
            chosen = driver.default_method(evaluator, system, q0, s_dot0, 0.0, t_end)
            chosen_fd = driver.default_method(_Real(evaluator), system, q0, s_dot0, 0.0, t_end)
        print(f"{name:22} {len(x0):4d} {t_end:6.3g} | {rho_fd:10.5g}{'d' if decays_fd else ' '} "
              f"{rho:10.5g}{'d' if decays else ' '} {way:>8} | {chosen_fd:>6} {chosen:>7} | {cost_fd * 1e3:7.3f} "
              f"{cost * 1e3:8.3f} | {unit * 1e6:7.1f} {cost_fd / unit:5.0f} {cost / unit:7.0f} {cost / cost_fd:5.2f}")


class _Real:
    """An evaluator's s̈ for real states only, without its one-call Jacobian: default_method's
    check by forward differences, as before."""

    def __init__(self, evaluator):
        self._evaluator = evaluator

    def accelerations(self, q, s_dot, t):
        if np.iscomplexobj(q) or np.iscomplexobj(s_dot):
            raise TypeError("real states only")
        return self._evaluator.accelerations(q, s_dot, t)


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

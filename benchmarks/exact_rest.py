"""The last finite differences in derivative paths, before and after they became exact (issue 16),
measured in one run:

1. TangentSystem.singular_positions on IFToMM A02 (the double four-bar, 10 s, rtol 1e-9): the
   event dρ/dt by the central difference along q̇ it had ("fd": (ρ(q + h q̇, t + h) −
   ρ(q − h q̇, t − h)) / 2h, h = 1e-10 / |q̇|_max) against the exact rate now (σ̇_i = u_iᵀ Ȧ_s v_i, Ȧ_s
   by the complex step); both against Richardson's difference of ρ (h = 1e-4) at the outputs of
   the first 0.7 s, the event times found, their distance to the parallelogram motion's
   horizontal cranks, the CPU per event call and of the whole run (the run without the event too).
2. simulate's stiffness check (stiff_steps) on the four-bar and A02 at t = 1 s: ρ by the
   power iteration on forward differences of the fused real-only right-hand side it used
   against ρ now (the model's complex-safe ẋ) and the eigenvalues of the exact Jacobian.

    PYTHONPATH=. python benchmarks/exact_rest.py [--quick]   # --quick: A02 over 1 s, 5 event calls
"""

from __future__ import annotations

import os
import argparse
import time
import warnings

import numpy as np
from scipy.optimize import brentq

import projeq as pq
from projeq.analysis.differentiation import richardson
from projeq.analysis.jacobians import state_derivative, state_jacobian
from projeq.scenes.iftomm import n_four_bar, parallelogram_motion
from projeq.simulation.integrators import spectral_radius


def central_event(system):
    """The event as it was: dρ/dt by the central difference along q̇."""
    acting = system.tree.n_s - system.n_s

    def ratio(q, t):
        sigma = np.linalg.svd(system.constraint_matrix(q, t)[0], compute_uv=False)
        return sigma[acting - 1] / sigma[0]

    def singular_position(t, q, s_dot):
        q_dot = system.q_dot(q, s_dot, t)
        h = 1e-10 / max(np.abs(q_dot).max(), 1e-300)
        return (ratio(q + h * q_dot, t + h) - ratio(q - h * q_dot, t - h)) / (2 * h)

    singular_position.terminal, singular_position.direction = False, 1
    return singular_position, ratio


def events(t_end: float = 10.0, calls: int = 200) -> None:
    """Table 1 of the module docstring: the runs over ``t_end`` s, ``calls`` event calls timed."""
    system = n_four_bar(2)
    fd, ratio = central_event(system)
    exact = system.singular_positions()
    r = pq.simulate(system, 0.7, n_points=8, rtol=1e-9, atol=1e-11)
    errors = {"fd": [], "exact": []}
    for q, s_dot, t in zip(r.q[1:], r.s_dot[1:], r.t[1:]):
        q_dot = system.q_dot(q, s_dot, t)
        reference = richardson(lambda e: ratio(q + e * q_dot, t + e), 1e-4)
        for name, event in (("fd", fd), ("exact", exact)):
            errors[name].append(abs(event(t, q, s_dot) / reference - 1))
    print("event dρ/dt vs Richardson (max rel. error over 7 states):",
          {k: f"{max(v):.1e}" for k, v in errors.items()})
    q, s_dot, t = r.q[4], r.s_dot[4], r.t[4]
    runs = {}
    for name, event in (("none", None), ("fd", fd), ("exact", exact)):
        start = time.process_time()
        for _ in range(calls if event else 0):
            event(t, q, s_dot)
        per_call = (time.process_time() - start) / calls * 1e6
        start = time.process_time()
        run = pq.simulate(system, t_end, n_points=201, rtol=1e-9, atol=1e-11,
                          events=[event] if event else None)
        runs[name] = time.process_time() - start
        if event is not None and not len(run.t_events[0]):
            print(f"{name:5s}: no event in {t_end:g} s, {per_call:.0f} µs per event call, "
                  f"run {runs[name]:.2f} s CPU")
        elif event:
            found = run.t_events[0]
            horizontal = [brentq(lambda s: parallelogram_motion([0.0, s], 2)[-1, 1], a - 0.05, a + 0.05, xtol=1e-14)
                          for a in found]
            print(f"{name:5s}: {len(found)} events, first {found[0]:.12f} s, max |t − t_horizontal| "
                  f"{np.abs(found - horizontal).max():.2e} s, {per_call:.0f} µs per event call, run {runs[name]:.2f} s CPU")
        else:
            print(f"none : run {runs[name]:.2f} s CPU")
    print(f"run time exact/fd {runs['exact'] / runs['fd']:.2f}, exact/none {runs['exact'] / runs['none']:.2f}")


def stiffness() -> None:
    for name, system in (("four_bar", pq.scenes.four_bar()), ("A02 N=2", n_four_bar(2))):
        r = pq.simulate(system, 1.0, method="RK45", rtol=1e-6)
        x, t = np.concatenate((r.q[-1], r.s_dot[-1])), r.t[-1]
        evaluator = system.evaluator(None)
        eig = np.abs(np.linalg.eigvals(state_jacobian(system, x, t)[0])).max()
        now = spectral_radius(lambda s, z: state_derivative(system, z, s), t, x,
                              jacobian=getattr(evaluator, "state_jacobian", None))
        before = spectral_radius(evaluator.state_derivative, t, x)
        print(f"{name}: n_x = {len(x)}, ρ exact eigenvalues {eig:.12g}, now {now:.12g} (rel {abs(now / eig - 1):.1e}), "
              f"before (forward differences) {before:.12g} (rel {abs(before / eig - 1):.1e})")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="A02 runs of 1 s and 5 event calls")
    args = parser.parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        events(*((1.0, 5) if args.quick else ()))
        stiffness()


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

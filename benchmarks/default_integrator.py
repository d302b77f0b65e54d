"""Which integrator should ``simulate``'s default be for a stiff elastic model? Explicit and
implicit methods of solve_ivp on the elastic scenes, each over its own span (``--t-end``
overrides it): CPU time, evaluations of s̈, Jacobians, the largest deviation of the final
state (q, ṡ) from a DOP853 run at rtol 1e-11, and whether a StiffnessWarning fired, all in
one run (compare the ratios; absolute seconds are this machine's and include no compilation:
each method's kernels are compiled, or loaded from disk, by a short run first).

    python benchmarks/default_integrator.py               # 5 s of the spin-up, a table of tolerances
    python benchmarks/default_integrator.py --t-end 20    # the scene's full 20 s (minutes)
    python benchmarks/default_integrator.py --quick       # 10 ms of the spin-up (a test runs it)
    python benchmarks/default_integrator.py --scene chain5 --runs default RK45 DOP853   # another model,
                                                          # at simulate's default tolerances
    python benchmarks/default_integrator.py --scene spinning_beam spinning_beam_1cm axial_beam \\
        elastic_arm flexible_arm rigid_arm --runs default DOP853 Radau BDF RK45      # the default's choice
    python benchmarks/default_integrator.py --scene two_masses --runs default Radau BDF   # stiffness ratio 1e10

``--runs default RK45 ...`` runs each named method at simulate's default tolerances (rtol 1e-8,
atol 1e-10; "default": no method given, the row names the one simulate chose, "DOP853, Radau
from t = …" where its explicit steps crawled at their stability limit and it went on with Radau)
instead of the table of tolerances.
"""

from __future__ import annotations

import os
import argparse
import time
import warnings

import numpy as np

import projeq as pq
from projeq.studies.table import Table


def spinning_beam_1cm() -> pq.System:
    """The spinning beam scene bent by its first v function to 1 cm at the tip (the scene
    itself rests: q = 0 is its solution for all t)."""
    beam = pq.scenes.spinning_beam()
    q0 = np.zeros(beam.n_q)
    q0[0] = 0.01
    return pq.System(dict(zip(beam.names, beam.subsystems)), dict(zip(beam.names, beam.joints)), q0=q0)


def axial_beam() -> pq.System:
    """A 1 m cantilever with one bending and one axial function whose axial mode is 10³ times
    faster than its bending one, spun up to 1 rad/s (the stiff beam of tests/simulation)."""
    return pq.scenes.spin_up_beam(omega_s=1.0, t_s=1.0, length=1.0, EI=1.0, rho_A=1.0, EA=1e6 * 1.875104068711961**4 / (np.pi / 2) ** 2,
                                  n_shapes=1, n_axial=1)


def two_masses(k_fast: float = 1e10) -> pq.System:
    """Two unit masses on a line (issue 34's stiff oscillator): the first on a spring k = 1 to the ground
    (its prismatic joint's q₁), the second on a spring k_fast to the first (q₂ relative to it); at rest,
    q₁ = 0.1 with q₂ the slow mode's own ratio k₁ q₁ / (2 k_fast), which leaves the fast mode unexcited."""
    x = (1.0, 0.0, 0.0)
    return pq.System({"first": pq.PointMass(1.0), "second": pq.PointMass(1.0)},
                     {"first": pq.Prismatic(axis=x), "second": pq.Prismatic(parent="first", axis=x)},
                     forces=[pq.JointSpring("first", 1.0), pq.JointSpring("second", k_fast)],
                     q0=[0.1, 0.1 / (2 * k_fast)])


SCENES = {  # name: (model, its span in s)
    "spin_up_beam": (pq.scenes.spin_up_beam, 5.0), "chain5": (lambda: pq.scenes.chain(5), 5.0),
    "elastic_arm": (pq.scenes.elastic_arm, 5.0), "spinning_beam": (pq.scenes.spinning_beam, 10.0),
    "spinning_beam_1cm": (spinning_beam_1cm, 10.0), "axial_beam": (axial_beam, 1.0),
    "rigid_arm": (lambda: pq.scenes.flexible_arm(rigid_last_link=True), 1.0), "flexible_arm": (pq.scenes.flexible_arm, 1.0),
    "two_masses": (two_masses, 10.0),
}
RUNS = (("RK45", 1e-6, 1e-9), ("DOP853", 1e-6, 1e-9), ("Radau", 1e-6, 1e-9), ("BDF", 1e-6, 1e-9),
        ("RK45", 1e-8, 1e-10), ("DOP853", 1e-9, 1e-11), ("Radau", 1e-8, 1e-10))


def final_state(system, t_end: float, method: str | None, rtol: float = 1e-8, atol: float = 1e-10) -> tuple:
    """(x(t_end), CPU seconds, evaluations, Result, whether a StiffnessWarning fired) of one run."""
    started = time.process_time()
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")  # the StiffnessWarning of the explicit methods: counted here
        result = pq.simulate(system, t_end, method=method, rtol=rtol, atol=atol, n_points=2)
    cpu = time.process_time() - started
    stiff = any(issubclass(w.category, pq.StiffnessWarning) for w in said)
    return np.concatenate((result.q[-1], result.s_dot[-1])), cpu, result.nfev, result, stiff


def scene_rows(name: str, t_end: float | None, runs) -> list:
    """The rows of one scene: each run against the reference."""
    build, span = SCENES[name]
    system, t_end = build(), span if t_end is None else t_end
    for method, rtol, atol in runs:  # compile (or load) each method's kernels outside the timings
        final_state(system, 1e-3, method, rtol, atol)
    reference = final_state(system, t_end, "DOP853", 1e-11, 1e-13)[0]
    rows = []
    for method, rtol, atol in runs:
        x, cpu, nfev, result, stiff = final_state(system, t_end, method, rtol, atol)
        rows.append((name, t_end, result.method + " (default)" * (method is None), rtol, cpu, nfev, result.njev,
                     float(np.abs(x - reference).max()), "yes" if stiff else "no"))
    return rows


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--t-end", type=float, help="simulated seconds (default: each model's span in SCENES)")
    parser.add_argument("--scene", nargs="+", choices=sorted(SCENES), default=["spin_up_beam"],
                        help="the models (default spin_up_beam)")
    parser.add_argument("--runs", nargs="*", help="methods at the default tolerances ('default': simulate's choice)")
    parser.add_argument("--quick", action="store_true", help="10 ms of each scene (--t-end 0.01)")
    args = parser.parse_args(argv)
    if args.quick:
        args.t_end = 0.01
    runs = [(None if m == "default" else m, 1e-8, 1e-10) for m in args.runs] if args.runs else RUNS
    rows = [row for name in args.scene for row in scene_rows(name, args.t_end, runs)]
    table = Table(("scene", "t_end", "method", "rtol", "cpu", "nfev", "njev", "error", "StiffnessWarning"), rows,
                  units={"t_end": "s", "cpu": "s"}, formats={"rtol": ".0e", "cpu": ".2f", "error": ".1e"},
                  title="error = max |x(t_end) − x_ref| (DOP853, rtol 1e-11)")
    print(table.to_text())
    return table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

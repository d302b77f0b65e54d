"""Elastic models that the compiled paths took on this stop, against the reference evaluators, in
one run: s̈ per call (µs, mean over repeated calls at one moving, deformed state) by the default
evaluator and by the interpreted reference ("recursive"; "dense" where joints are coupled), and a
whole 2 s `simulate` by each (CPU s, fresh results compared). Models: the spinning beam with
rotary inertia (a RitzBeam on a prescribed hub: `method="hub_beam"`), a link carrying a RitzBeam
with rotary inertia (the order-n kernel's elastic block with `kernels.rotary_body`), and a beam
beside a coupled joint (the compiled Gauss form with each body's n_y, projected).

    PYTHONPATH=. python benchmarks/elastic_compiled.py [--quick]   # --quick: 0.05 s runs, few calls (a test)
"""

from __future__ import annotations

import os
import argparse
import time
import warnings

import numpy as np

import projeq as pq
from projeq.studies.table import Table


def rotary_arm() -> pq.System:
    """A link turning about z carrying a RitzBeam with rotary inertia that turns about y."""
    beam = pq.RitzBeam(1.0, 2.0, 50.0, rho_I=(1e-3, 1e-3), n_v=3, n_w=3)
    return pq.System({"link": pq.RigidBody(1.0, (0.25, 0, 0), np.diag([1e-3, 0.02, 0.02])), "beam": beam},
                     {"link": pq.Revolute(axis="z"), "beam": pq.Revolute(parent="link", axis="y", r_pn=(0.5, 0, 0))},
                     gravity=(0, 0, -9.81))


def coupled_beam() -> pq.System:
    """Two bodies on revolute joints, the second geared to the first (ratio 2), and a RitzBeam on
    the first."""
    rod = pq.RigidBody(1.0, (0.2, 0, 0), 0.01 * np.eye(3))
    return pq.System({"a": rod, "b": rod, "beam": pq.RitzBeam(1.0, 2.0, 50.0, n_v=2, n_w=1)},
                     {"a": pq.Revolute(axis="z"), "b": pq.Revolute(axis="z", r_pn=(0, 1, 0), coupling={"a": 2.0}),
                      "beam": pq.Revolute("a", axis="y", r_pn=(0.4, 0, 0))}, gravity=(0, 0, -9.81))


MODELS = {
    "spinning beam, ρI": lambda: pq.scenes.spinning_beam(omega=2.0, rho_I=0.05, n_shapes=3, family="clamped_free"),
    "link + rotary beam": rotary_arm,
    "coupled joint + beam": coupled_beam,
}


def per_call(f, calls: int) -> float:
    """Mean µs of ``f()`` over ``calls`` calls after one warm-up call."""
    f()
    started = time.perf_counter()
    for _ in range(calls):
        f()
    return (time.perf_counter() - started) / calls * 1e6


def row(name: str, build, t_end: float = 2.0, calls: int = 2000) -> tuple:
    """The model's row of the table (module docstring): runs of ``t_end`` s, s̈ timed over ``calls`` calls
    (a tenth of them by the reference)."""
    system = build()
    reference = "dense" if system.coupled else "recursive"
    rng = np.random.default_rng(0)
    q, s_dot = 0.02 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s)
    default = system.evaluator().name
    with warnings.catch_warnings():
        warnings.simplefilter("error", pq.assembly.InterpretedWarning)  # the default must be compiled
        fast = per_call(lambda: system.accelerations(q, s_dot, 0.3), calls)
        pq.simulate(system, 0.01)  # the kernels from numba's cache, outside the timings
        started = time.process_time()
        compiled_run = pq.simulate(system, t_end)
        compiled_cpu = time.process_time() - started
    slow = per_call(lambda: system.accelerations(q, s_dot, 0.3, method=reference), calls // 10)
    started = time.process_time()
    reference_run = pq.simulate(system, t_end, evaluator=reference)
    reference_cpu = time.process_time() - started
    difference = float(np.abs(compiled_run.q[-1] - reference_run.q[-1]).max())
    return (name, default, fast, reference, slow, slow / fast, compiled_cpu, reference_cpu,
            reference_cpu / compiled_cpu, difference)


def main(argv=None) -> Table:
    """Print and return the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="runs of 0.05 s, 50 calls timed")
    args = parser.parse_args(argv)
    t_end, calls = (0.05, 50) if args.quick else (2.0, 2000)
    rows = [row(name, build, t_end, calls) for name, build in MODELS.items()]
    table = Table(("model", "default", "s̈ µs", "reference", "ref s̈ µs", "s̈ ratio", "run s", "ref run s",
                   "run ratio", "|Δq(t_end)|"), rows,
                  formats={"s̈ µs": ".1f", "ref s̈ µs": ".1f", "s̈ ratio": ".1f", "run s": ".2f", "ref run s": ".2f",
                           "run ratio": ".1f", "|Δq(t_end)|": ".1e"},
                  title=f"elastic models on the compiled paths vs the reference evaluators (one run; "
                        f"simulate defaults, {t_end:g} s)")
    print(table.to_text())
    return table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

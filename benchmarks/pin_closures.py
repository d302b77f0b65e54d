"""The four-bar closed by a cut joint (PinClosure: coupler tip pinned to rocker tip along x and y) on
the compiled closure kernel (projeq.constraints.compiled evaluates the cut joint itself: A_s from
the chain's body Jacobians, γ from the points' accelerations) against the same model on the numpy
path (the kernel switched off: Φ's complex-step derivatives through the tree's poses, the
partition and the projection by numpy on the compiled tree's Gauss form — the default for a
PinClosure before) and against the scene's four-bar with its hand-written Φ
(``projeq.scenes.mechanisms.four_bar()``, numba-compiled Φ, derivatives by the complex step in
the kernel). Same tree, same states.

s̈ per call: CPU time (``time.process_time``), the three alternated in batches of repeated calls
at eight moving states near q0, the median of the batches' means (ratios from one run hold on a
loaded machine, absolute times less so). ``simulate(system, 2.0)``: the CPU time of one run each
(median of ``--runs``), from the scene's initial state (crank at 3 rad/s), with the default 501
output rows and with 2 (``run_2_rows``: the integration alone, nearly — each output row evaluates
Φ, its Jacobian and the projection onto Φ = 0 outside the accelerations: for a PinClosure by the
kernel's own cut-joint rows (``CutJointRows``; on the numpy path pointwise complex steps through
the tree's poses in Python), for the hand-written Φ one batched call).

A second table: the same four-bar driven by a Prescribed crank, θ1(t) = 0.5 + 3t + 0.4 sin 2t
(Φ(q, t): no minimal velocity left), with the motion in sympy (the closure kernel: the crank's
relative motion a compiled callback, b_s = −∂Φ/∂t and γ from the chain) and as a Python callable
(the numpy path: complex steps through the poses, stencils for Φ″'s rheonomic parts).

    PYTHONPATH=. python benchmarks/pin_closures.py [--budget 3] [--runs 3]
    PYTHONPATH=. python benchmarks/pin_closures.py --quick   # 0.03 s of timing, one 50 ms run each, 21 rows

Measured 2026-11-28 (2 shared cores, load ~1): s̈ 33.7 µs compiled, 2810 µs numpy path (83×),
22.1 µs hand-written Φ (0.66×: the cut joints' kernel passes the chain three times — at rest for A_s,
at ṡ_tree for γ, then for the Gauss form —, the hand-written Φ's once); simulate 2 s: 0.49 s CPU
compiled, 6.71 s numpy path (13.6×), 0.53 s hand-written Φ (1.09×); with 2 output rows 0.20, 5.55
and 0.23 s; 1311 s̈ evaluations each. (Earlier the same day, before the cut-joint rows outside the
accelerations were compiled: simulate 2.84 s compiled vs 0.51 s hand-written.) The driven four-bar,
later the same day (load ~1): s̈ 53.3 µs compiled vs 7736 µs numpy path (145×), simulate 2 s 0.64
vs 4.20 s CPU (6.5×), 255 evaluations each (no minimal velocity: the run integrates q alone).
"""

from __future__ import annotations

import os
import argparse
import itertools
import time
import warnings

import numpy as np

import projeq as pq
from projeq.constraints.cut_joints import PinClosure
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.scenes.mechanisms import four_bar
from projeq.studies.bench_scenes import STATES, moving_states
from projeq.studies.table import Table


def models() -> dict:
    """{label: ConstrainedSystem}: the pinned four-bar twice (compiled, numpy path) and the scene's."""
    scene = four_bar()
    tree = scene.tree
    pin = PinClosure(tree, "coupler", (1.0, 0, 0), "rocker", (0.8, 0, 0), axes="xy")  # the scene's b, c

    def pinned():
        return ConstrainedSystem(tree, phi=pin, independent=[0], q0=scene.q0, s_dot0=scene.s_dot0)

    compiled, numpy_path = pinned(), pinned()
    assert compiled.compiled_kernel() is not None and scene.compiled_kernel() is not None
    numpy_path._compiled = None  # the kernel "does not apply": every call takes the numpy path,
    numpy_path._cut_rows = None  # and the cut joints' rows the complex steps through the poses
    assert numpy_path.compiled_kernel() is None and numpy_path.evaluator().accelerations.__name__ == "accelerations"
    assert compiled.evaluator().accelerations.__name__ == "_compiled_accelerations"
    return {"PinClosure, compiled kernel": compiled, "PinClosure, numpy path": numpy_path,
            "hand-written Φ (scenes four_bar)": scene}


def driven_models() -> dict:
    """{label: ConstrainedSystem}: the four-bar driven by its crank, the motion in sympy (compiled)
    and as a callable (numpy path)."""
    import sympy as sp

    t = sp.Symbol("t")
    motions = {"driven, sympy motion (compiled kernel)": 0.5 + 3 * t + 0.4 * sp.sin(2 * t),
               "driven, callable motion (numpy path)": lambda t: (0.5 + 3 * t + 0.4 * np.sin(2 * t),
                                                                  3 + 0.8 * np.cos(2 * t), -1.6 * np.sin(2 * t))}
    scene = four_bar()
    systems = {}
    for label, motion in motions.items():
        joints = dict(zip(scene.tree.names, scene.tree.joints))
        joints["crank"] = pq.Prescribed(joints["crank"], motion)
        tree = pq.System(dict(zip(scene.tree.names, scene.tree.subsystems)), joints, gravity=(0.0, -9.81, 0.0))
        pin = PinClosure(tree, "coupler", (1.0, 0, 0), "rocker", (0.8, 0, 0), axes="xy")
        systems[label] = ConstrainedSystem(tree, phi=pin, q0=scene.q0[1:])
    compiled, numpy_path = systems.values()
    assert compiled.compiled_kernel() is not None and numpy_path.compiled_kernel() is None
    return systems


def per_call(systems: dict, budget: float, batch: float = 2e-3) -> dict:
    """{label: median CPU seconds per s̈}: the evaluators alternated in batches of ~``batch`` s."""
    rng = np.random.default_rng(1)
    states = moving_states(next(iter(systems.values())), STATES, rng)  # one tree: the same states for all
    calls = {}
    for label, system in systems.items():
        ev, cycle = system.evaluator(), itertools.cycle(states)
        calls[label] = (lambda ev=ev, cycle=cycle: ev.accelerations(*next(cycle), 0.0))
    repeats = {}
    for label, f in calls.items():  # warm up, then size the batches
        f()
        t0, n = time.process_time(), 0
        while time.process_time() - t0 < batch:
            f()
            n += 1
        repeats[label] = max(n, 1)
    means = {label: [] for label in calls}
    started = time.perf_counter()
    while len(means[next(iter(calls))]) < 5 or time.perf_counter() - started < budget:
        for label, f in calls.items():
            t0 = time.process_time()
            for _ in range(repeats[label]):
                f()
            means[label].append((time.process_time() - t0) / repeats[label])
    return {label: float(np.median(values)) for label, values in means.items()}


def run_seconds(system, t_end: float, runs: int, n_points: int = 501) -> tuple[float, int, float]:
    """(median CPU seconds of simulate(system, t_end, n_points=n_points), its s̈ evaluations, max |Φ|)."""
    pq.simulate(system, 0.05, n_points=3)  # warm up
    seconds, result = [], None
    for _ in range(runs):
        t0 = time.process_time()
        result = pq.simulate(system, t_end, n_points=n_points)
        seconds.append(time.process_time() - t0)
    return float(np.median(seconds)), int(result.nfev), float(np.abs(result.constraint_residual).max())


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--budget", type=float, default=3.0, help="seconds of s̈ timing in all (default 3)")
    parser.add_argument("--runs", type=int, default=3, help="simulate runs per model (default 3)")
    parser.add_argument("--t-end", type=float, default=2.0, help="simulated seconds (default 2)")
    parser.add_argument("--quick", action="store_true", help="--budget 0.03 --runs 1 --t-end 0.05, 21 rows")
    args = parser.parse_args(argv)
    rows_out = 21 if args.quick else 501
    if args.quick:
        args.budget, args.runs, args.t_end = 0.03, 1, 0.05
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the numpy path's model says once that it is not compiled
        systems = models()
        us = {label: s * 1e6 for label, s in per_call(systems, args.budget).items()}
        runs = {label: run_seconds(s, args.t_end, args.runs, rows_out) for label, s in systems.items()}
        bare = {label: run_seconds(system, args.t_end, args.runs, 2)[0] for label, system in systems.items()}
        driven = driven_models()
        driven_us = {label: s * 1e6 for label, s in per_call(driven, args.budget / 3).items()}
        driven_runs = {label: run_seconds(s, args.t_end, args.runs, rows_out) for label, s in driven.items()}
    base_us = us["PinClosure, compiled kernel"]
    base_run = runs["PinClosure, compiled kernel"][0]
    run = f"simulate_{args.t_end:g}s_cpu"
    rows = [(label, us[label], us[label] / base_us, runs[label][0], runs[label][0] / base_run, bare[label],
             runs[label][1], runs[label][2]) for label in systems]
    print(Table(("model", "s_ddot_us", "s_ddot / pin compiled", run, "run / pin compiled", "run_2_rows_cpu", "nfev",
                 "max |Φ|"), rows,
                units={"s_ddot_us": "µs", run: "s", "run_2_rows_cpu": "s"},
                formats={"s_ddot_us": ".1f", "s_ddot / pin compiled": ".2f", run: ".3f", "run / pin compiled": ".2f",
                         "run_2_rows_cpu": ".3f", "max |Φ|": ".1e"}).to_text())
    base_us, base_run = (values[next(iter(driven))] for values in (driven_us, driven_runs))
    driven_rows = [(label, driven_us[label], driven_us[label] / base_us, driven_runs[label][0],
                    driven_runs[label][0] / base_run[0], driven_runs[label][1], driven_runs[label][2]) for label in driven]
    print(Table(("model", "s_ddot_us", "s_ddot / compiled", run, "run / compiled", "nfev", "max |Φ|"), driven_rows,
                units={"s_ddot_us": "µs", run: "s"},
                formats={"s_ddot_us": ".1f", "s_ddot / compiled": ".2f", run: ".3f", "run / compiled": ".2f",
                         "max |Φ|": ".1e"}).to_text())
    return rows + driven_rows


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

"""Effort and drift of the non-holonomic scenes: Bremer's car, the knife-edge disc and
Barhorst's rolling disk (issue "non-holonomic", item 3).

For each scene: the number of minimal velocities n_s, the time to build the System from
scratch (sympy derivation, lambdify, checks; the symbolic part is cleared first), the
minimum time of one evaluation of s̈ by the recursive and the dense evaluator, and, for a
long run at two tolerances, the relative energy drift (``Result.energy_drift``), the
largest constraint residual, the number of right-hand-side evaluations and wall time.

    python benchmarks/nonholonomic_effort.py            # the full table (~2 min)
    python benchmarks/nonholonomic_effort.py --quick    # runs 1000× shorter, 0.02 s of timing
    python benchmarks/nonholonomic_effort.py --json

Runs: the car without loads (v_x = 10 m/s, ω_z = 0.2 rad/s) for 200 s; the knife-edge
disc (m = g = r = 1, μ = ¼, ν = ½) from a generic state (tilt 0.2, θ̇ = −3, ψ̇ = 0.4)
for 200 time units; the rolling disk with Barhorst's parameters and start for his 10 s.
Absolute times are this machine's only.
"""

from __future__ import annotations

import os
import argparse
import json
import time

import numpy as np

import projeq as pq
from projeq.scenes import nonholonomic as nh

TOLERANCES = (1e-6, 1e-10)


def _cold(build):
    def run():
        nh._disc_joint_lecture.cache_clear()
        nh._rolling_disk_joint.cache_clear()
        return build()
    return run


CASES = {
    "car": (_cold(lambda: nh.car()), 200.0, None),
    "knife_edge_disc": (_cold(lambda: nh.knife_edge_disc(s_dot0=(0.4, 0.0, -3.0))), 200.0, None),
    "rolling_disk": (_cold(lambda: nh.rolling_disk()), 10.0, None),
}


def time_per_call(system, method: str, budget: float = 0.5) -> float:
    ev = system.evaluator(method)
    q, s = system.q0, system.s_dot0
    ev.accelerations(q, s, 0.0)
    best, started, n = np.inf, time.perf_counter(), 0
    while n < 5 or time.perf_counter() - started < budget:
        t0 = time.perf_counter()
        ev.accelerations(q, s, 0.0)
        best = min(best, time.perf_counter() - t0)
        n += 1
    return best


def measure(name: str, quick: bool) -> dict:
    build, t_end, _ = CASES[name]
    t0 = time.perf_counter()
    system = build()
    build_time = time.perf_counter() - t0
    budget = 0.02 if quick else 0.5
    row = {
        "scene": name, "n_q": system.n_q, "n_s": system.n_s, "n_c": system.n_c,
        "build_s": build_time,
        "recursive_us": 1e6 * time_per_call(system, "recursive", budget),
        "dense_us": 1e6 * time_per_call(system, "dense", budget),
        "runs": [],
    }
    t_end = t_end / 1000 if quick else t_end
    for rtol in TOLERANCES:
        res = pq.simulate(system, t_end, method="DOP853", rtol=rtol, atol=rtol * 1e-2, n_points=1001)
        row["runs"].append({
            "rtol": rtol, "t_end": t_end, "energy_drift": res.energy_drift,
            "constraint_residual": float(np.abs(res.constraint_residual).max()),
            "nfev": res.nfev, "wall_s": res.wall_time,
        })
    return row


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--quick", action="store_true", help="runs 1000× shorter, 0.02 s of timing")
    parser.add_argument("--json", action="store_true", help="print JSON")
    args = parser.parse_args(argv)
    rows = [measure(name, args.quick) for name in CASES]
    if args.json:
        print(json.dumps(rows, indent=1))
        return rows
    print("| scene | n_q | n_s | build (s) | recursive (µs/eval) | dense (µs/eval) | run | rtol | energy drift | max constraint residual | nfev | wall (s) |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
    for row in rows:
        for k, run in enumerate(row["runs"]):
            head = (f"| {row['scene']} | {row['n_q']} | {row['n_s']} | {row['build_s']:.2f} | {row['recursive_us']:.0f} "
                    f"| {row['dense_us']:.0f} ") if k == 0 else "| | | | | | "
            print(head + f"| {run['t_end']:g} | {run['rtol']:.0e} | {run['energy_drift']:.2e} | "
                  f"{run['constraint_residual']:.1e} | {run['nfev']} | {run['wall_s']:.1f} |")
    return rows


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

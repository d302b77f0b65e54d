"""CPU per point of a local sweep (issue 34, "sweeps"): the double pendulum over 0.5 s at its defaults,
one parameter (m1) varied, serially in this process — ``sweep`` with a one-thread executor — beside the
pieces of one point: building the System, and ``simulate`` on a new System and on the same one (where
the evaluator, its compiled loop and its rows' kernels are already found). Warm: the first points run
before the timings (compilation excluded). The issue's bound is 2 ms of CPU per point.

    PYTHONPATH=. python benchmarks/sweep_points.py [--points 200]
    PYTHONPATH=. python benchmarks/sweep_points.py --quick      # 5 points
"""

from __future__ import annotations

import argparse
import concurrent.futures
import os
import time

import numpy as np

from projeq import scenes, simulate
from projeq.simulation.sweep import sweep
from projeq.studies.table import Table

T_END = 0.5


def per_point(work, points: int) -> float:
    """CPU milliseconds per point of ``work(masses)`` over ``points`` masses."""
    masses = np.linspace(0.5, 2.0, points)
    started = time.process_time()
    work(masses)
    return (time.process_time() - started) / points * 1e3


def main(argv=None) -> Table:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=200, help="points per measurement (default 200)")
    parser.add_argument("--quick", action="store_true", help="5 points")
    args = parser.parse_args(argv)
    points = 5 if args.quick else args.points
    one_thread = concurrent.futures.ThreadPoolExecutor(1)

    def swept(masses):
        sweep("double_pendulum", grid={"m1": masses}, executor=one_thread, t_end=T_END, progress=False)

    same = scenes.double_pendulum()
    pieces = {
        "sweep (one thread)": swept,
        "build the System": lambda masses: [scenes.double_pendulum(m1=m) for m in masses],
        "simulate, a new System": lambda masses: [simulate(scenes.double_pendulum(m1=m), T_END) for m in masses],
        "simulate, the same System": lambda masses: [simulate(same, T_END) for _ in masses],
    }
    for work in pieces.values():  # compiled (or found) before the timings
        work(np.linspace(0.5, 2.0, 2))
    rows = [[name, points, per_point(work, points)] for name, work in pieces.items()]
    table = Table(["piece", "points", "CPU per point"], rows, units={"CPU per point": "ms"},
                  formats={"CPU per point": ".2f"},
                  title=f"double pendulum over {T_END} s at its defaults, warm; issue 34's bound for a sweep: 2 ms per point")
    print(table.to_text())
    return table


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path

if __name__ == "__main__":
    main()

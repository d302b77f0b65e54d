"""A whole default ``simulate`` of constrained scenes (the scene's t_end and settings) with the
constrained s̈ in one compiled call (:mod:`projeq.constraints.compiled`) against the same run on
the numpy path it replaces (Φ's batched derivatives and the projection by numpy on the compiled
tree's Gauss form), in one process, alternately: CPU seconds of each run (best of ``--repeat``),
their ratio, the right-hand-side calls, and the largest difference of the two runs' q and ṡ
(relative to the largest |q|, |ṡ|: the runs differ by round-off per call, amplified by the
integrator's step selection).

    python benchmarks/closure_runs.py                     # Andrews' squeezer (0.05 s)
    python benchmarks/closure_runs.py four_bar bricard    # others
    python benchmarks/closure_runs.py --quick             # Andrews' squeezer over 5 ms, once (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import time

import numpy as np

import projeq as pq
from projeq import scenes
from projeq.studies.table import Table


def run(name: str, compiled: bool, t_end: float):
    """(CPU s, Result) of the scene's default run up to ``t_end``, by the compiled call or the numpy path."""
    scene = scenes.SCENES[name]
    system = scene.build()
    if not compiled:
        system._compiled = None  # the numpy path, as for a Φ numba cannot compile
    system.evaluator()
    start = time.process_time()
    result = pq.simulate(system, t_end, **(scene.settings or {}))
    return time.process_time() - start, result


def row(name: str, repeat: int, t_end: float | None = None) -> dict:
    t_end = scenes.SCENES[name].t_end if t_end is None else t_end
    run(name, True, t_end)  # compile and load the kernels once
    seconds, results = {True: np.inf, False: np.inf}, {}
    for _ in range(repeat):
        for compiled in (True, False):
            cpu, results[compiled] = run(name, compiled, t_end)
            seconds[compiled] = min(seconds[compiled], cpu)
    fast, slow = results[True], results[False]
    same_grid = fast.t.shape == slow.t.shape and np.array_equal(fast.t, slow.t)
    dq = np.abs(fast.q[-1] - slow.q[-1]).max() / np.abs(slow.q[-1]).max()
    ds = np.abs(fast.s_dot[-1] - slow.s_dot[-1]).max() / max(np.abs(slow.s_dot[-1]).max(), 1e-300)
    return {"scene": name, "t_end": t_end, "compiled_s": seconds[True], "numpy_s": seconds[False],
            "ratio": seconds[False] / seconds[True], "evaluations": (fast.nfev, slow.nfev),
            "same_grid": same_grid, "q_end": dq, "s_dot_end": ds}


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scenes", nargs="*", default=["andrews_squeezer"], help="scene names")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each path, best CPU time (default 3)")
    parser.add_argument("--quick", action="store_true", help="each scene over 1/10 of its span, once")
    args = parser.parse_args(argv)
    rows = [row(name, 1, scenes.SCENES[name].t_end / 10) if args.quick else row(name, args.repeat)
            for name in args.scenes]
    print(Table(("scene", "t_end", "compiled", "numpy", "numpy/compiled", "rhs calls (c, n)", "Δq_end rel",
                 "Δṡ_end rel"),
                [(r["scene"], r["t_end"], r["compiled_s"], r["numpy_s"], r["ratio"], str(r["evaluations"]), r["q_end"],
                  r["s_dot_end"]) for r in rows],
                units={"t_end": "s", "compiled": "s", "numpy": "s"},
                formats={"compiled": ".3f", "numpy": ".3f", "numpy/compiled": ".1f", "Δq_end rel": ".1e",
                         "Δṡ_end rel": ".1e"}).to_text())
    return rows


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

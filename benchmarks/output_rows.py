"""The whole default ``simulate`` of a scene (its t_end and settings) in this tree against another
checkout (before/after a change: of the output rows, of the right-hand side), in fresh processes, alternately: CPU
seconds of each (median of ``--repeat`` processes, the numba kernels loaded from the disk cache
by a warm-up run first), their ratio, and whether the two Results' arrays are bit-identical
(t, q, s_dot, kinetic, potential, constraint_residual, rank, mobility), else the largest
difference of each array that is not, relative to its largest entry.

    git -C /work/main archive HEAD | tar -x -C /tmp/out_old
    PYTHONPATH=. python benchmarks/output_rows.py /tmp/out_old [--repeat 3] [SCENE[:t_end] ...]
    PYTHONPATH=. python benchmarks/output_rows.py --quick   # this tree against itself, one 0.1 s run each
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

CHILD = """
import sys, time, json, numpy as np
import projeq as pq
from projeq import scenes
name, t_end, out = sys.argv[1], float(sys.argv[2]), sys.argv[3]
scene = scenes.SCENES[name]
system = scene.build()
pq.simulate(system, t_end / 50, **(scene.settings or {}))  # the kernels from numba's disk cache
started = time.process_time()
result = pq.simulate(system, t_end, **(scene.settings or {}))
cpu = time.process_time() - started
np.savez(out, **{k: getattr(result, k) for k in ("t", "q", "s_dot", "kinetic", "potential",
                                                  "constraint_residual", "rank", "mobility")})
print(json.dumps({"cpu": cpu, "rows": len(result.t), "nfev": result.nfev}))
"""

SCENES = ("andrews_squeezer", "four_bar", "whipple_bicycle:2", "simple_pendulum")


def run(tree: Path, name: str, t_end: float, out: str) -> dict:
    """One fresh process of ``tree``: the CPU seconds of the default simulate, its rows and nfev."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    done = subprocess.run([sys.executable, "-c", CHILD, name, repr(t_end), out], env=env, cwd=tree,
                          capture_output=True, text=True, check=True)
    return json.loads(done.stdout.strip().splitlines()[-1])


def differences(a: str, b: str) -> str:
    """"identical" if the two saved Results hold the same arrays, bit for bit, else the arrays
    that differ with the largest difference relative to the array's largest entry."""
    with np.load(a) as x, np.load(b) as y:
        differ = []
        for k in x.files:
            if x[k].shape != y[k].shape:
                differ.append(f"{k}: shape {x[k].shape} vs {y[k].shape}")
            elif not np.array_equal(x[k], y[k]):
                scale = max(np.abs(x[k]).max(), np.finfo(float).tiny)
                differ.append(f"{k} {np.abs(x[k] - y[k]).max() / scale:.1e}")
        return "identical" if not differ else "; ".join(differ)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("other", type=Path, nargs="?", help="the other checkout (before the change)")
    parser.add_argument("scenes", nargs="*", default=list(SCENES), help="scene names, optionally name:t_end")
    parser.add_argument("--repeat", type=int, default=3, help="processes of each tree per scene (median CPU)")
    parser.add_argument("--quick", action="store_true",
                        help="simple_pendulum:0.1, one process each (the other checkout: this tree if none)")
    args = parser.parse_intermixed_args(argv)
    from projeq import scenes

    here = Path(__file__).resolve().parent.parent
    if args.quick:
        args.other, args.scenes, args.repeat = args.other or here, ["simple_pendulum:0.1"], 1
    if args.other is None:
        parser.error("the other checkout is required (except with --quick)")
    print(f"{'scene':18s} {'t_end':>6s} {'rows':>5s} {'nfev':>6s} {'before s':>9s} {'after s':>8s} "
          f"{'before/after':>12s} arrays (identical, or max |difference| / max |entry|)")
    with tempfile.TemporaryDirectory() as tmp:
        for spec in args.scenes:
            name, _, t = spec.partition(":")
            t_end = float(t) if t else scenes.SCENES[name].t_end
            cpu = {"before": [], "after": []}
            for i in range(args.repeat):
                for label, tree in (("before", args.other.resolve()), ("after", here)):
                    r = run(tree, name, t_end, f"{tmp}/{label}.npz")
                    cpu[label].append(r["cpu"])
            same = differences(f"{tmp}/before.npz", f"{tmp}/after.npz")
            b, a = statistics.median(cpu["before"]), statistics.median(cpu["after"])
            print(f"{name:18s} {t_end:6.3g} {r['rows']:5d} {r['nfev']:6d} {b:9.3f} {a:8.3f} {b / a:12.2f} "
                  f"{same}", flush=True)


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

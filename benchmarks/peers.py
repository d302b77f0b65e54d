"""projeq's defaults against its peers on the same models, in one run
(:mod:`projeq.studies.bench_peers`, whose docstring says what is compared and how):

- s̈ of ``scenes.chain(n)``, n = 10, 100, 200, 1000, by the default evaluator against
  Pinocchio's ABA (n ≤ 300: its Data grows as n², 0.7 GB at n = 200), MuJoCo's
  ``mj_forward`` and MuJoCo's smooth dynamics alone; each peer's s̈ checked against projeq's
  first; the growth exponent over the sizes;
- the uniform rolling disk against sympy's KanesMethod rolling disc, lambdified (M, F)
  and solved, the body-frame angular accelerations checked first;
- the spin-up beam (Ωs = 4 rad/s, 20 s), ``simulate(system, 20.0)`` with no knobs, against
  Exudyn's nonlinear ANCF cable: CPU time and the in-plane tip at 7, 10, 20 s;
- the first-call latency of the compiled kernel in a fresh process (empty and filled numba cache).

    pip install 'projeq[bench]'                  # pin, mujoco, exudyn
    python benchmarks/peers.py                   # lines as measured, then the JSON file
    python benchmarks/peers.py --quick           # n = 10, 100, 0.05 s each; no spin-up, no latency (a test)
    python benchmarks/peers.py --save benchmarks/results/2026-11-27/peers.json
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # single-threaded CPU times, comparable between codes
import argparse
import json
from pathlib import Path

from projeq.studies.bench_peers import CHAIN_SIZES, peers_report


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true",
                        help="chain n = 10, 100 only, 0.05 s each; no spin-up, no cold-cache latency")
    parser.add_argument("--budget", type=float, default=1.0, help="seconds of timing per comparison (default 1)")
    parser.add_argument("--save", type=Path, default=None, help="write the report as JSON to this file")
    args = parser.parse_args(argv)
    report = peers_report((10, 100) if args.quick else CHAIN_SIZES, 0.05 if args.quick else args.budget,
                          spin_up=not args.quick, latency=not args.quick,
                          show=lambda line: print(line, flush=True))
    if args.save is not None:
        args.save.parent.mkdir(parents=True, exist_ok=True)
        args.save.write_text(json.dumps(report, indent=2) + "\n")
        print(f"wrote {args.save}")
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

"""Cost of one evaluation of s̈ for ``projeq.scenes.chain(n)``: projeq's evaluators
(recursive, fast, dense up to n = 300) against Pinocchio's ABA and MuJoCo's ``mj_forward``
on the same chain when installed (``pip install 'projeq[bench]'``).

Prints a table (µs per call; fast/Pinocchio and fast/MuJoCo time ratios; the fast
evaluator's and the largest deviation of any evaluator from the dense s̈; the fast and the
dense evaluator's deviation from the exact s̈ of projeq.studies.bench_exact (Lagrange's equations
in absolute angles at 40 digits, n ≤ 300) — deviations relative to max(1, |s̈|∞)) and the
fitted log-log slope of each evaluator over n = 10 … 1000; ``--json`` prints the same as
JSON, with every evaluator's deviation from the exact s̈. The deviation from the dense s̈
includes the dense evaluator's own error, about κ(M) ε; the one from the exact s̈ is each
evaluator's own.
All evaluators are timed alternately in one run and each entry is the minimum over
repeats (projeq.studies.bench.time_per_call), so the ratios are robust on a noisy machine;
absolute times are this machine's only. Targets of issue 7: fast ≤ 5× Pinocchio at
n = 100, faster than MuJoCo for n ≥ 200, slope ≤ 1.1.

    python benchmarks/chain_scaling.py            # n = 10, 30, 100, 200, 300, 1000
    python benchmarks/chain_scaling.py --quick    # n = 10, 30, 100, 0.05 s each, exact s̈ to n = 30
"""

from __future__ import annotations

import os
import argparse

from projeq.cli.bench import exact_option
from projeq.studies.bench import QUICK_SIZES, chain_scaling

SIZES = (10, 30, 100, 200, 300, 1000)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="n = 10, 30, 100, 0.05 s each, exact to n = 30")
    parser.add_argument("--budget", type=float, default=1.0, help="seconds of timing per size (default 1)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--no-peers", action="store_true", help="skip Pinocchio and MuJoCo")
    exact_option(parser)
    args = parser.parse_args(argv)
    if args.quick:
        args.budget, args.exact_up_to = 0.05, min(args.exact_up_to, 30)
    return chain_scaling(QUICK_SIZES if args.quick else SIZES, args.budget, args.json, not args.no_peers, args.exact_up_to)


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

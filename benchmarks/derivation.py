"""Derivation effort of the symbolic Projection Equation vs sympy.physics.mechanics (issue 5 item 7).

The study is :func:`projeq.studies.bench_derivation.derivation_effort` (its module docstring
says what is measured); ``projeq bench`` runs it for N = 2 and 4. N = 1…10 by default, all in
one run.

Run: ``python benchmarks/derivation.py [--json] [--no-lagrange] [--quick] [N ...]`` (LagrangesMethod
dominates the run time from N ≈ 7; ``--quick``: N = 1, what a test runs).
"""

import os
import argparse
import json

from projeq.studies.bench_derivation import derivation_effort


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sizes", nargs="*", type=int, help="numbers of bodies N (default 1 … 10)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of the rows")
    parser.add_argument("--no-lagrange", action="store_true", help="leave LagrangesMethod out")
    parser.add_argument("--quick", action="store_true", help="N = 1 only")
    args = parser.parse_args(argv)
    sizes = (1,) if args.quick else tuple(args.sizes) or tuple(range(1, 11))
    show = None if args.json else lambda line: print(line, flush=True)
    rows = derivation_effort(sizes, not args.no_lagrange, show=show)
    if args.json:
        print(json.dumps(rows, indent=1))
    return rows


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

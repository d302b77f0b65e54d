"""Derivation effort of the symbolic Projection Equation vs sympy.physics.mechanics (issue 5 item 7).

The study is :func:`projeq.studies.bench_derivation.derivation_effort` (its module docstring
says what is measured); ``projeq bench`` runs it for N = 2 and 4. N = 1…10 by default, all in
one run.

Run: ``python benchmarks/derivation.py [--json] [--no-lagrange] [N ...]`` (LagrangesMethod
dominates the run time from N ≈ 7).
"""

import json
import sys

from projeq.studies.bench_derivation import derivation_effort


def main(sizes=tuple(range(1, 11)), as_json=False, lagrange=True):
    rows = derivation_effort(sizes, lagrange, show=None if as_json else lambda line: print(line, flush=True))
    if as_json:
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    args = sys.argv[1:]
    main(tuple(int(a) for a in args if not a.startswith("--")) or tuple(range(1, 11)), "--json" in args,
         "--no-lagrange" not in args)

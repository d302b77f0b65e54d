"""Speed vs accuracy of the spin-up beam: tip deflection against a converged reference.

The study is :func:`projeq.studies.bench_beam.convergence` (its docstring says what is
measured); ``projeq bench`` runs its quick mode. Prints a table row by row, then the
cheapest setting within 1e-4 m (``--json``: JSON).

    python benchmarks/beam_convergence.py            # full study (several minutes)
    python benchmarks/beam_convergence.py --quick    # a few settings (PROJEQ_QUICK=1 too)
"""

from __future__ import annotations

import os

# one BLAS thread: CPU times of single-threaded runs, comparable between codes; with OpenBLAS's
# threads the matrix–vector products of the precomputed mode at n ≥ 10 (n_z ≥ 221) spin on a
# shared machine and cost 10–20× the CPU time
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import argparse
import json

from projeq.studies.bench_beam import (  # noqa: F401  (FASTEST ... tip_deflection: for exudyn_spin_up.py)
    FASTEST, QUICK_REFERENCE, REFERENCE, TIMES, convergence, tip_deflection,
)


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", default=os.environ.get("PROJEQ_QUICK") == "1")
    parser.add_argument("--omega", type=float, default=4.0, help="final spin Ωs in rad/s (default 4)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    report = convergence(args.omega, args.quick, show=None if args.json else lambda line: print(line, flush=True))
    if args.json:
        print(json.dumps(report, indent=2, default=str))
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

"""Bremer's effort claims measured as derivation effort, growing with the Ritz functions and the bodies.

H. Bremer, "Problems in fast moving non-holonomic elastic systems": the Projection Equation gives the
spinning beam's B(23) "along with much less effort in calculation" than Hamilton's principle gives B(18)
(§4.2), and for rigid multibody systems "minimum effort when compared to the analytical procedures" (§3).
Measured by :mod:`projeq.studies.effort_growth`: the operations after ``sympy.cse`` of every expression each
method forms (Hamilton/Lagrange: T − V, its integrations by parts or ∫ dx, ∂L/∂q̇, d/dt ∂L/∂q̇, ∂L/∂q;
Projection Equation: the Newton–Euler residuals, their projections, the equations) and the CPU time of the
derivation from a cold start, for the beam's field equations, its Ritz model with n = 1 … 4 functions per
plane and the planar n-link pendulum with 1 … 3 links; the claim and a plain verdict below the numbers.

    python benchmarks/effort_growth.py           # n = 1 … 4, links 1 … 3 (a few minutes: Hamilton's n = 4)
    python benchmarks/effort_growth.py --quick   # the beam's field equations and one link (≤ 3 s)
"""

from __future__ import annotations

import argparse
import os

from projeq.studies.effort_growth import CASES, effort_rows, verdict

CLAIMS = ("H. Bremer, §4.2: B(23) \"along with much less effort in calculation\" than Hamilton's "
          "principle's B(18); §3: the Projection Equation \"leads to minimum effort when compared to the "
          "analytical procedures\".")


def main(argv=None) -> list:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", default=os.environ.get("PROJEQ_QUICK") == "1")
    args = parser.parse_args(argv)
    sizes = {"beam field equations": (0,), "pendulum": (1,)} if args.quick else CASES
    rows = effort_rows(sizes)
    print(f"{'case':22} {'size':>4} {'method':10} {'ops':>6} {'cpu_s':>7}  operations per step")
    for row in rows:
        print(f"{row['case']:22} {row['size']:4d} {row['method']:10} {row['total_ops']:6d} "
              f"{row['cpu_s']:7.3f}  "
              + ", ".join(f"{name} {ops}" for name, ops in row["ops"].items()))
    print(CLAIMS)
    print(verdict(rows))
    return rows


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

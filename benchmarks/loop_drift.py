"""Loop-closure drift of Barhorst's quick-return mechanism versus the correction method.

``scenes.mechanisms.quick_return`` (seed 000 §3.3) runs 10 s with zero drive, once per
position correction of :class:`projeq.constrained.ConstrainedSystem`:

- ``none``: q̇ = K (F ṡ + f) only; the velocity constraint holds exactly, so Φ drifts by
  the integration error of q alone;
- ``baumgarte``: q̇ −= β C_Φ⁺ Φ (Φ̇ = −β Φ), for two rates β;
- ``projection``: Gauss–Newton onto Φ = 0 at segment ends (``n_segments``) and outputs;
  the column "max |Φ| before" is the drift found at the segment ends before projecting.

Prints max |c1|, |c2| of (107) along the Result, the energy drift, right-hand-side
evaluations and the wall time, all measured in this one run.

    python benchmarks/loop_drift.py [--t-end 10] [--rtol 1e-8]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import projeq as pq
from projeq.scenes.mechanisms import quick_return


def run(correction: str, t_end: float, rtol: float, beta: float = 10.0, n_segments: int = 20) -> dict:
    """One simulation; the drift seen by the projection is recorded before it acts."""
    system = quick_return(correction=correction, beta=beta)
    before = [0.0]
    if correction == "projection":
        project = system.project

        def recording(q, t=0.0, max_iter=20):
            before[0] = max(before[0], float(np.abs(system.phi(q, t)).max()))
            return project(q, t, max_iter)

        system.project = recording
    started = time.perf_counter()
    r = pq.simulate(system, t_end, rtol=rtol, atol=rtol * 1e-2, n_points=201, n_segments=n_segments)
    return {
        "c1": np.abs(r.constraint_residual[:, 0]).max(), "c2": np.abs(r.constraint_residual[:, 1]).max(),
        "before": before[0] if correction == "projection" else float("nan"),
        "energy": r.energy_drift, "nfev": r.nfev, "seconds": time.perf_counter() - started,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--rtol", type=float, default=1e-8)
    args = parser.parse_args()
    cases = [("none", {}), ("baumgarte", {"beta": 1.0}), ("baumgarte", {"beta": 10.0}),
             ("projection", {"n_segments": 20}), ("projection", {"n_segments": 100})]
    print(f"quick-return, {args.t_end} s, rtol {args.rtol:g}")
    print(f"{'correction':<26}{'max|c1|':>10}{'max|c2|':>10}{'|Φ| before':>12}"
          f"{'energy':>10}{'nfev':>7}{'s':>7}")
    for correction, kw in cases:
        row = run(correction, args.t_end, args.rtol, **kw)
        label = correction + "".join(f" {k}={v}" for k, v in kw.items())
        print(f"{label:<26}{row['c1']:>10.2e}{row['c2']:>10.2e}{row['before']:>12.2e}{row['energy']:>10.2e}"
              f"{row['nfev']:>7d}{row['seconds']:>7.1f}")


if __name__ == "__main__":
    main()

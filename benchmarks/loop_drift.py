"""Loop-closure drift of Barhorst's quick-return mechanism versus the correction method.

``scenes.mechanisms.quick_return`` (Barhorst §3.3) runs 10 s with zero drive, once per
position correction of :class:`projeq.constraints.partitioned.ConstrainedSystem`:

- ``none``: q̇ = K (F ṡ + f) only; the velocity constraint holds exactly, so Φ drifts by
  the integration error of q alone;
- ``baumgarte``: q̇ −= β C_Φ⁺ Φ (Φ̇ = −β Φ), for two rates β;
- ``projection``: Gauss–Newton onto Φ = 0 at segment ends (``n_segments``) and outputs;
  the column "max |Φ| before" is the drift found at the segment ends before projecting.

Prints max |c1|, |c2| of (107) along the Result, the energy drift, right-hand-side
evaluations and the wall time, all measured in this one run.

A second table re-pivots: the crank–rocker ``four_bar`` (θ1(0) = 0, ω1(0) = 6 rad/s,
gravity on) started with the crank's rate, with the rocker's rate and re-pivoting, and
with the rocker's rate fixed (which stops at the rocker's first extreme position); it
prints the partitions' switch times, the largest crank-angle difference to the crank run,
the energy drift, evaluations and wall time.

    python benchmarks/loop_drift.py [--t-end 10] [--rtol 1e-8] [--four-bar-t-end 2]
    python benchmarks/loop_drift.py --quick    # 0.2 s each (a test runs it)
"""

from __future__ import annotations

import os
import argparse
import time

import numpy as np

import projeq as pq
from projeq.scenes.mechanisms import four_bar, quick_return


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


def repivoting(t_end: float, rtol: float) -> None:
    """The four-bar table (module docstring)."""
    print(f"\nfour-bar (crank-rocker), {t_end} s, rtol {rtol:g}")
    print(f"{'start partition':<26}{'switch times (s)':<34}{'max|Δθ1|':>10}{'energy':>10}{'nfev':>7}{'s':>7}")
    t = np.linspace(0.0, t_end, 201)
    reference = None
    crank = four_bar(theta1=0.0, omega1=6.0)
    for label, system in (("crank", crank), ("rocker, repivot", crank.with_independent([1], repivot=True)),
                          ("rocker, fixed", crank.with_independent([1]))):
        started = time.perf_counter()
        try:
            r = pq.simulate(system, t_end, t_eval=t, rtol=rtol, atol=rtol * 1e-2)
        except pq.SimulationError as error:
            print(f"{label:<26}stopped: {str(error)[:90]}")
            continue
        reference = r if reference is None else reference
        switches = " ".join(f"{t_k:.3f}{list(independent)}" for t_k, independent, _ in r.partitions[1:]) or "-"
        print(f"{label:<26}{switches:<34}{np.abs(r.q[:, 0] - reference.q[:, 0]).max():>10.2e}"
              f"{r.energy_drift:>10.2e}{r.nfev:>7d}{time.perf_counter() - started:>7.1f}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-end", type=float, default=10.0)
    parser.add_argument("--rtol", type=float, default=1e-8)
    parser.add_argument("--four-bar-t-end", type=float, default=2.0)
    parser.add_argument("--quick", action="store_true", help="--t-end 0.2 --four-bar-t-end 0.2")
    args = parser.parse_args(argv)
    if args.quick:
        args.t_end = args.four_bar_t_end = 0.2
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
    repivoting(args.four_bar_t_end, args.rtol)


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

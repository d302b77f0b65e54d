"""The spin-up beam (``scenes.spin_up_beam``, Ωs = 4 rad/s, Ts = 15 s, 20 s) in projeq and in
Exudyn's nonlinear ANCF cable (``ObjectANCFCable2D``, 16 elements, generalized-α,
h = 1e-3): CPU time (time.process_time, same run) and the in-plane tip deflection v(L, t)
at t = 5, 10, 15, 20 s (in the hub frame, the direction of rotation), both against
projeq's converged reference (``beam_convergence.REFERENCE``).

Exudyn's beam is clamped at the hub axis by four coordinate constraints on its first node:
position (0, 0) and slope (cos θ(t), sin θ(t)) with θ(t) of ``spin_up_motion``, the
offsets set once per step by a PreStepUserFunction (Exudyn's recommendation for
prescribed motion). Its Newton absolute tolerance is raised from 1e-10 to 1e-6 N (see
``projeq.studies.bench_peers.exudyn_tip_deflection``, the model); with the default it cuts its
steps to 1e-6 s and needs ~50× the CPU time. Its beam is extensible (EA = 2.8e7 N) and its curvature is exact; projeq's
default is inextensible with the linear curvature v″ and the second-order axial field u₂
(docs/theory.md §10). ``--study`` adds Exudyn runs with 32 elements and h = 5e-4 (its discretisation
error). Measured: Exudyn differs from projeq's reference by 2.9e-4 m at Ωs = 4, 3.3e-5 m at
Ωs = 2, 4.1e-6 m at Ωs = 1 rad/s — as the cube of the deflection (ratios 8 and 64), the
signature of the geometric terms beyond projeq's second-order beam theory (exact curvature
and stretching in the ANCF cable), not of either code's discretisation.

    pip install 'projeq[bench]'   # exudyn
    python benchmarks/exudyn_spin_up.py [--json] [--quick] [--study] [--omega 4]
"""

from __future__ import annotations

import os

# one BLAS thread: CPU times of single-threaded runs, comparable between codes; with OpenBLAS's
# threads the matrix–vector products of the precomputed mode at n ≥ 10 (n_z ≥ 221) spin on a
# shared machine and cost 10–20× the CPU time
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import argparse
import importlib.util
import json
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from beam_convergence import FASTEST, QUICK_REFERENCE, REFERENCE, TIMES, tip_deflection

from projeq.studies import bench_peers

OMEGA_S = 4.0


def exudyn_tip_deflection(omega_s: float = OMEGA_S, **options) -> tuple[np.ndarray, float]:
    """v(L, t) at TIMES by Exudyn and the CPU time of its time integration
    (:func:`projeq.studies.bench_peers.exudyn_tip_deflection`)."""
    return bench_peers.exudyn_tip_deflection(omega_s, TIMES, **options)


def _projeq(knobs: dict) -> tuple[np.ndarray, float]:
    v, cpu, _ = tip_deflection(**knobs)
    return v, cpu


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--json", action="store_true")
    parser.add_argument("--quick", action="store_true", help="the quick reference of beam_convergence")
    parser.add_argument("--study", action="store_true", help="also Exudyn with 32 elements and h = 5e-4")
    parser.add_argument("--omega", type=float, default=OMEGA_S, help="final spin Ωs in rad/s (default 4)")
    args = parser.parse_args(argv)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the reference's explicit integrator is slow on the stiff modes: known
        reference, reference_cpu = _projeq({**(QUICK_REFERENCE if args.quick else REFERENCE), "omega_s": args.omega})
    have_exudyn = importlib.util.find_spec("exudyn") is not None
    if not have_exudyn:
        print("exudyn is not installed (pip install 'projeq[bench]'): its runs left out, CPU / exudyn is nan")
    runs = {"exudyn 16 el, h 1e-3": exudyn_tip_deflection(args.omega)} if have_exudyn else {}
    runs["projeq " + ", ".join(f"{k}={v}" for k, v in FASTEST.items())] = _projeq({**FASTEST, "omega_s": args.omega})
    if args.study and have_exudyn:
        import exudyn

        # (EA × 10 to test extensibility did not finish in 4 CPU minutes: Newton step reductions)
        for name, options in (("32 el, h 1e-3", {"n_elements": 32}), ("16 el, h 5e-4", {"h": 5e-4})):
            try:
                runs["exudyn " + name] = exudyn_tip_deflection(args.omega, **options)
            except exudyn.SolverError as exc:  # a stiffer axial mode may defeat its Newton iteration
                runs["exudyn " + name + f" (failed: {exc})"] = (np.full(len(TIMES), np.nan), np.nan)
    exudyn_cpu = runs["exudyn 16 el, h 1e-3"][1] if have_exudyn else float("nan")
    report = {
        "omega_s": args.omega, "times_s": TIMES.tolist(), "reference_tip_m": reference.tolist(),
        "reference_cpu_s": reference_cpu,
        "runs": {name: {"tip_m": v.tolist(), "max_error_m": float(np.abs(v - reference).max()), "cpu_s": cpu,
                        "cpu_over_exudyn": cpu / exudyn_cpu} for name, (v, cpu) in runs.items()},
    }
    if args.json:
        print(json.dumps(report, indent=2))
        return report
    print(f"spin-up Ωs = {args.omega} rad/s; reference (projeq, CPU {reference_cpu:.1f} s) v(L) at t = "
          f"{TIMES.tolist()} s: {np.round(reference, 7).tolist()} m")
    print(f"{'run':<80} {'max |v − ref| m':>15} {'CPU s':>7} {'/ exudyn':>8}")
    for name, row in report["runs"].items():
        print(f"{name:<80} {row['max_error_m']:>15.2e} {row['cpu_s']:>7.2f} {row['cpu_over_exudyn']:>8.3f}")
    return report


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

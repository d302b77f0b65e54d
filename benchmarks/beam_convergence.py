"""Speed vs accuracy of the spin-up beam: tip deflection against a converged reference.

For ``scenes.spin_up_beam`` (Ωs = 4 rad/s by default) the in-plane tip deflection v(L, t)
at t = 5, 10, 15, 20 s is compared with a reference (12 clamped–free eigenfunctions per
plane, quadrature order 40, DOP853 at rtol 1e-10) for each setting of the model knobs:
number of Ritz functions, family, stiffening and the precomputed-shape-integral mode
(``precomputed_integrals``, small deformations). CPU time is measured in the same run,
and so is the CPU time of one M_n, h_n evaluation of the beam in both modes (the speed
gain per evaluation). Prints a table row by row (``--json`` for JSON at the end) and names
the cheapest setting that reaches 1e-4 m.

    python benchmarks/beam_convergence.py            # full study (several minutes)
    python benchmarks/beam_convergence.py --quick    # a few settings
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

import projeq as pq
from projeq.scenes.elastic import spin_up_beam

TIMES = np.array([5.0, 10.0, 15.0, 20.0])


def tip_deflection(omega_s: float, rtol: float = 1e-8, method: str = "DOP853", **knobs) -> tuple[np.ndarray, float]:
    """v(L, t) at TIMES and the CPU time of the simulation."""
    system = spin_up_beam(omega_s=omega_s, **knobs)
    started = time.process_time()
    result = pq.simulate(system, TIMES[-1], method=method, rtol=rtol, atol=rtol * 1e-2, t_eval=np.concatenate(([0.0], TIMES)))
    cpu = time.process_time() - started
    beam = system.subsystem("beam")
    return beam.deflection(result, beam.length)[1:, 1], cpu


def settings(quick: bool) -> list[dict]:
    counts = (1, 2, 3, 4) if quick else tuple(range(1, 13))
    rows = [{"n_shapes": n, "family": "clamped_free"} for n in counts]
    rows += [{"n_shapes": n, "family": "clamped_free", "precomputed_integrals": True} for n in counts]
    rows += [{"n_shapes": n, "family": "polynomial"} for n in counts if n <= 8]
    if not quick:
        rows += [{"n_shapes": 4, "family": "clamped_free", "stiffening": False}]
    return rows


def evaluation_cost(n_shapes: int, precomputed: bool, repeats: int = 300) -> float:
    """CPU seconds of one beam M_n, h_n evaluation at a deformed, moving state."""
    beam = spin_up_beam(n_shapes=n_shapes, family="clamped_free", precomputed_integrals=precomputed).subsystem("beam")
    rng = np.random.default_rng(0)
    y_dot, q_e = rng.standard_normal(beam.n_y), 1e-2 * rng.standard_normal(beam.n_e)
    started = time.process_time()
    for _ in range(repeats):
        beam.gauss_terms(y_dot, np.eye(3), np.zeros(3), q_e)
    return (time.process_time() - started) / repeats


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--omega", type=float, default=4.0, help="final spin Ωs in rad/s (default 4)")
    parser.add_argument("--json", action="store_true")
    args = parser.parse_args(argv)
    reference, ref_cpu = tip_deflection(args.omega, rtol=1e-10, n_shapes=12, family="clamped_free")
    if not args.json:
        print(f"spin-up Ωs = {args.omega} rad/s; reference v(L) at t = {TIMES.tolist()}: {np.round(reference, 6).tolist()} m")
        print(f"{'family':>13} {'n':>3} {'stiffening':>10} {'precomputed':>11} {'max error m':>12} {'CPU s':>7} {'CPU/ref CPU':>11}", flush=True)
    rows = []
    for knobs in settings(args.quick):
        try:
            v, cpu = tip_deflection(args.omega, **knobs)
            error = float(np.abs(v - reference).max())
        except pq.SimulationError as exc:  # the unstiffened model may blow up
            v, cpu, error = None, float("nan"), float("inf")
            knobs = {**knobs, "failed": str(exc)[:60]}
        rows.append({**knobs, "max_error_m": error, "cpu_s": cpu})
        if not args.json:
            r = rows[-1]
            print(
                f"{r['family']:>13} {r['n_shapes']:>3} {str(r.get('stiffening', True)):>10} "
                f"{str(r.get('precomputed_integrals', False)):>11} {r['max_error_m']:>12.2e} {r['cpu_s']:>7.2f} "
                f"{r['cpu_s'] / ref_cpu:>11.3f}",
                flush=True,
            )
    costs = {n: (evaluation_cost(n, False), evaluation_cost(n, True)) for n in ((2, 4) if args.quick else (2, 4, 8, 12))}
    good = [r for r in rows if r["max_error_m"] <= 1e-4]
    best = min(good, key=lambda r: r["cpu_s"]) if good else None
    report = {
        "omega_s": args.omega, "reference_tip_m": reference.tolist(), "reference_cpu_s": ref_cpu, "rows": rows,
        "cheapest_1e-4": best, "evaluation_cpu_s": {n: list(c) for n, c in costs.items()},
    }
    if args.json:
        print(json.dumps(report, indent=2, default=str))
        return report
    print(f"\none beam evaluation (M_n, h_n), clamped_free, µs: {'n':>3} {'quadrature':>10} {'precomputed':>11} {'gain':>5}")
    for n, (quadrature, precomputed) in costs.items():
        print(f"{'':>49} {n:>3} {1e6 * quadrature:>10.0f} {1e6 * precomputed:>11.0f} {quadrature / precomputed:>5.2f}")
    print("cheapest setting within 1e-4 m:", best)
    return report


if __name__ == "__main__":
    main()

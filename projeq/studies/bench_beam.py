"""Speed vs accuracy of the spin-up beam: tip deflection against a converged reference
(``benchmarks/beam_convergence.py``; its quick mode is part of ``projeq bench``).

For ``scenes.spin_up_beam`` (Ωs = 4 rad/s by default, Ts = 15 s) the in-plane tip
deflection v(L, t) at t = 5, 10, 15, 20 s is compared with a converged reference (8
clamped–free eigenfunctions per plane, DOP853 at rtol 1e-10: 6 and 8 functions differ by
1e-6 m) for each setting of the knobs: number of Ritz functions (1…12), family, quadrature
vs precomputed shape integrals, stiffening on/off, evaluator (``"hub_beam"``: the beam path
of :mod:`projeq.assembly.beam_fast`; ``"recursive"``: the general order-n path) and
integrator/tolerance. CPU time (time.process_time) of each run is measured in the same
run as the reference; ratios to it are printed. The unstiffened model is unstable above
the first bending frequency (3.80 rad/s): its rows report the failure, not a crash.
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np

from projeq.scenes.elastic import spin_up_beam
from projeq.simulation.driver import SimulationError, simulate

TIMES = np.array([5.0, 10.0, 15.0, 20.0])
REFERENCE = {"n_shapes": 8, "family": "clamped_free", "precomputed_integrals": True, "method": "DOP853", "rtol": 1e-10}
# quick: 5 functions by Radau at rtol 1e-7, 5e-6 m from REFERENCE (measured at Ωs = 4 rad/s)
QUICK_REFERENCE = {**REFERENCE, "n_shapes": 5, "method": "Radau", "rtol": 1e-7}
FASTEST = {"n_shapes": 3, "family": "clamped_free", "precomputed_integrals": True, "method": "Radau", "rtol": 1e-4}


def tip_deflection(omega_s: float, method: str = "DOP853", rtol: float = 1e-8, evaluator: str = "hub_beam",
                   **knobs) -> tuple[np.ndarray, float, int]:
    """v(L, t) at TIMES, the CPU time of the simulation and its number of evaluations
    (atol = 1e-2 rtol in m and m/s: the deflections are of order 0.1 m)."""
    system = spin_up_beam(omega_s=omega_s, **knobs)
    started = time.process_time()
    result = simulate(system, TIMES[-1], method=method, rtol=rtol, atol=rtol * 1e-2,
                      t_eval=np.concatenate(([0.0], TIMES)), evaluator=evaluator)
    cpu = time.process_time() - started
    beam = system.subsystem("beam")
    return beam.deflection(result, beam.length)[1:, 1], cpu, result.nfev


def settings(quick: bool) -> list[dict]:
    """The knob settings of the study (each a dict of tip_deflection's keywords)."""
    cf = {"family": "clamped_free"}
    if quick:
        return [
            {**FASTEST, "precomputed_integrals": False, "evaluator": "recursive"},
            {**FASTEST, "precomputed_integrals": False},
            {**FASTEST, "n_shapes": 2},
            FASTEST,
            {**FASTEST, "n_shapes": 4},
            {**FASTEST, "n_shapes": 2, "stiffening": False},
        ]
    rows = [{**FASTEST, "n_shapes": n, "method": m, "rtol": r}  # cheapest first: the full study is long
            for n in (2, 3, 4) for m, r in (("Radau", 1e-3), ("Radau", 1e-4), ("Radau", 1e-6), ("BDF", 1e-5),
                                            ("LSODA", 1e-6), ("DOP853", 1e-6), ("RK45", 1e-6))]
    rows += [{**FASTEST, "n_shapes": n, "stiffening": False, "precomputed_integrals": p} for n in (1, 2, 4) for p in (False, True)]
    rows += [{**FASTEST, "n_shapes": n, "precomputed_integrals": False, "evaluator": "recursive"} for n in (2, 3, 4)]
    # the sweep over the number of functions by Radau at rtol 1e-6 (the explicit methods crawl at
    # the stability limit of the stiff higher modes: DOP853 at 1e-8 needs 83000 calls for 5 polynomials)
    sweep = {"method": "Radau", "rtol": 1e-6}
    rows += [{**cf, **sweep, "n_shapes": n, "precomputed_integrals": p} for n in range(1, 13) for p in (False, True)]
    rows += [{**sweep, "family": "polynomial", "n_shapes": n, "precomputed_integrals": True} for n in range(1, 9)]
    return rows


def run(omega_s: float, knobs: dict, reference: np.ndarray) -> dict:
    """One row: the setting, its largest tip error over TIMES, CPU time and evaluations; a
    failed integration (the unstable unstiffened model) is reported as an infinite error."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            v, cpu, nfev = tip_deflection(omega_s, **knobs)
            error, note = float(np.abs(v - reference).max()), ""
        except SimulationError as exc:
            cpu, nfev, error, note = float("nan"), 0, float("inf"), "failed: " + str(exc)[:50]
    if any("unstable" in str(w.message) for w in caught):
        note = ("unstable (warned); " + note).strip("; ")
    return {**knobs, "max_error_m": error, "cpu_s": cpu, "nfev": nfev, "note": note}


def evaluation_cost(n_shapes: int, precomputed: bool, repeats: int = 300) -> float:
    """CPU seconds of one s̈ of the spin-up by the beam path at a deformed, moving state."""
    system = spin_up_beam(n_shapes=n_shapes, family="clamped_free", precomputed_integrals=precomputed)
    ev, rng = system.evaluator("hub_beam"), np.random.default_rng(0)
    q, s_dot = 1e-2 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s)
    started = time.process_time()
    for _ in range(repeats):
        ev.accelerations(q, s_dot, 3.0)
    return (time.process_time() - started) / repeats


def convergence(omega_s: float = 4.0, quick: bool = False, deadline: float = math.inf, show=None) -> dict:
    """The study: the reference run, one row per setting (:func:`settings`), the cost of one
    s̈ by quadrature and by precomputed integrals, and the cheapest setting within 1e-4 m
    of the reference.

    ``deadline`` (a ``time.perf_counter()`` value) stops the study before the next setting
    once passed (``"complete"`` is then False); ``show``, e.g. ``print``, receives the table
    line by line as it is computed.
    """
    show = show or (lambda line: None)
    reference_knobs = QUICK_REFERENCE if quick else REFERENCE
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # DOP853 at rtol 1e-10 is slow on the stiff modes: known
        reference, reference_cpu, _ = tip_deflection(omega_s, **reference_knobs)
    show(f"spin-up Ωs = {omega_s} rad/s; reference {reference_knobs}: v(L) at t = {TIMES.tolist()} s = "
         f"{np.round(reference, 7).tolist()} m, CPU {reference_cpu:.2f} s")
    show(f"{'family':>12} {'n':>3} {'stiff':>5} {'precomputed':>11} {'evaluator':>9} {'method':>6} {'rtol':>7} "
         f"{'max err m':>10} {'CPU s':>7} {'/ref':>7} {'nfev':>7}")
    rows, todo = [], settings(quick)
    for knobs in todo:
        if time.perf_counter() > deadline:
            break
        rows.append(run(omega_s, knobs, reference))
        show(_line(rows[-1], reference_cpu))
    counts = (2, 4) if quick else (2, 4, 8, 12)
    costs = {n: (evaluation_cost(n, False), evaluation_cost(n, True)) for n in counts}
    good = [r for r in rows if r["max_error_m"] <= 1e-4]
    best = min(good, key=lambda r: r["cpu_s"]) if good else None
    show(f"\none s̈ by the beam path, clamped_free, µs: {'n':>3} {'quadrature':>10} {'precomputed':>11} {'gain':>5}")
    for n, (quadrature, precomputed) in costs.items():
        show(f"{'':>40} {n:>3} {1e6 * quadrature:>10.0f} {1e6 * precomputed:>11.0f} {quadrature / precomputed:>5.2f}")
    show(f"cheapest setting within 1e-4 m: {best}")
    return {
        "omega_s": omega_s, "times_s": TIMES.tolist(), "reference": reference_knobs,
        "reference_tip_m": reference.tolist(), "reference_cpu_s": reference_cpu, "rows": rows,
        "cheapest_within_1e-4_m": best, "evaluation_cpu_s": {n: list(c) for n, c in costs.items()},
        "complete": len(rows) == len(todo),
    }


def _line(r: dict, reference_cpu: float) -> str:
    return (
        f"{r.get('family', 'clamped_free'):>12} {r['n_shapes']:>3} {r.get('stiffening', True)!s:>5} "
        f"{r.get('precomputed_integrals', False)!s:>11} {r.get('evaluator', 'hub_beam'):>9} "
        f"{r.get('method', 'DOP853'):>6} {r.get('rtol', 1e-8):>7.0e} {r['max_error_m']:>10.2e} {r['cpu_s']:>7.2f} "
        f"{r['cpu_s'] / reference_cpu:>7.3f} {r['nfev']:>7} {r['note']}"
    )

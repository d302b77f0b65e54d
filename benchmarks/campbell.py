"""Campbell diagrams of the two rotor scenes: cost per speed and accuracy of the branches.

1. ``scenes.rotating_blade`` (L = EI = ρA = 1, so Ω is Wright et al.'s η) with ten
   clamped–free functions per plane, hub radius R/L = 0, 0.5, 1, over η = 0 … 12: the
   first two flapwise and lead-lag branches against the Frobenius series of Wright, Smith,
   Thresher & Wang (1982), "Vibration modes of centrifugally stiffened beams", J. Appl.
   Mech. 49:197–202 (w'''' − (N w′)′ = λ² w, N = η² [r (1 − ξ) + (1 − ξ²)/2]; lead-lag
   λ² + η² in place of λ²; tests/analysis/rotating_cantilever.py); the wall time per speed; the
   critical speeds (Brent's method on the branch, and linear interpolation between the speeds
   of the sweep) against the crossings of the series' branches with k η.
2. ``scenes.spinning_beam`` with ρI = 0 (four clamped–free eigenfunctions per plane, exact
   at rest): forward and backward whirl against |ω_k ∓ Ω| over Ω = 0 … 30, through the
   zero of each forward whirl; and the split of the second whirls at Ω = 10 with ρI = 0.01
   (rotary inertia makes the shaft gyroscopic: 2Ω = 20 rad/s without it).

``--quick`` (≤ 3 s, run by tests/analysis/test_campbell.py): four functions per plane, five
speeds, the spinning beam's closed form and the blade's ω_lag² = ω_flap² − Ω².

    python benchmarks/campbell.py [--quick]

Measured 2026-12-06 (2 shared cores, interpreted evaluator, numba absent), max relative errors:

    R/L  flap 1   flap 2   lag 1    lag 2    s/speed crossings Brent    linear   s/crossing
    0.0  2.2e-05  2.8e-05  1.3e-04  3.2e-05  0.091   6         7.3e-05  7.7e-03  0.76
    0.5  5.9e-05  7.6e-05  1.2e-04  8.1e-05  0.085   5         4.5e-04  1.3e-02  0.38
    1.0  1.0e-04  1.3e-04  1.6e-04  1.4e-04  0.098   4         4.3e-06  1.8e-02  0.33

The frequency errors are the Ritz errors of ten functions, largest at η = 12 (≤ 1e-5 up to
η = 5). Brent's critical speeds are within 6.5e-7 of the series' crossings except where a
branch grazes its engine order (lead-lag 1 × 1Ω near η = 10.3, R/L = 0.5: the frequency error
1.2e-4 over the small difference of slopes gives 4.5e-4); linear interpolation on the ΔΩ = 1
sweep is 1e-2 off. Spinning beam, ρI = 0: 5.6e-12 (0.05 s per speed); backward − forward whirl
2 at Ω = 10: 20.000 rad/s (= 2Ω), with ρI = 0.01 15.112 rad/s.
"""

from __future__ import annotations

import os
import argparse
import pathlib
import sys
import time
import warnings

import numpy as np
from scipy.optimize import brentq

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))  # for tests.analysis

from projeq.analysis.campbell import campbell  # noqa: E402
from projeq.scenes import rotating_blade, spinning_beam  # noqa: E402
from projeq.subsystems.beam.shapes import clamped_free_roots  # noqa: E402
from tests.analysis.rotating_cantilever import frobenius_frequencies  # noqa: E402


def blade(hub_radius: float, speeds, n_shapes: int, refine: bool = False):
    start = time.perf_counter()
    diagram = campbell(lambda w: rotating_blade(omega=w, hub_radius=hub_radius, n_shapes=n_shapes), speeds,
                       n_modes=4, refine=refine)
    return diagram, (time.perf_counter() - start) / len(speeds)


def exact_critical_speed(critical, hub_radius: float) -> float:
    """The crossing of the Frobenius branch with k η near the refined one (brentq, ±0.3)."""
    kind, number = critical.mode.rsplit(" ", 1)
    lead_lag, i = kind == "lead-lag", int(number) - 1

    def gap(eta):
        return frobenius_frequencies(eta, hub_radius, i + 1, lead_lag)[i] - critical.order * eta

    return brentq(gap, critical.speed - 0.3, critical.speed + 0.3, xtol=1e-13)


def blade_table(n_shapes: int = 10) -> None:
    print(f"rotating_blade, {n_shapes} functions per plane: max relative error over η = 0 … 12 "
          "against the Frobenius series; critical speeds (orders 1, 2, 3) found on the sweep by Brent's "
          "method and by linear interpolation, max relative error against the series' crossings")
    print(f"{'R/L':>5} {'flap 1':>9} {'flap 2':>9} {'lag 1':>9} {'lag 2':>9} {'s/speed':>8} {'crossings':>9} "
          f"{'Brent':>9} {'linear':>9} {'s/crossing':>10}")
    speeds = np.linspace(0.0, 12.0, 13)
    for hub_radius in (0.0, 0.5, 1.0):
        diagram, per_speed = blade(hub_radius, speeds, n_shapes)
        errors = np.zeros(4)
        for k, eta in enumerate(speeds):
            exact = np.r_[frobenius_frequencies(eta, hub_radius, 2), frobenius_frequencies(eta, hub_radius, 2, True)]
            found = [diagram.branch(f"{kind} {i}")[k] for kind in ("flapwise", "lead-lag") for i in (1, 2)]
            errors = np.maximum(errors, np.abs(np.array(found) / exact - 1))
        start = time.perf_counter()
        refined = blade(hub_radius, speeds, n_shapes, refine=True)[0]
        per_crossing = (time.perf_counter() - start - per_speed * len(speeds)) / max(1, len(refined.critical_speeds))
        exact = [exact_critical_speed(c, hub_radius) for c in refined.critical_speeds]
        brent = max(abs(c.speed / e - 1) for c, e in zip(refined.critical_speeds, exact))
        linear = max(abs(c.speed / e - 1) for c, e in zip(diagram.critical_speeds, exact))
        print(f"{hub_radius:5.2f} " + " ".join(f"{e:9.1e}" for e in errors) + f" {per_speed:8.3f} "
              f"{len(exact):9d} {brent:9.1e} {linear:9.1e} {per_crossing:10.3f}")


def whirl_error(n_shapes: int, speeds, rho_I=None):
    diagram = campbell(lambda w: spinning_beam(omega=w, n_shapes=n_shapes, rho_I=rho_I), speeds, n_modes=2 * n_shapes)
    omega_k = clamped_free_roots(n_shapes) ** 2
    error = 0.0
    for k in range(n_shapes):
        error = max(error, np.abs(diagram.branch(f"forward whirl {k + 1}") / np.abs(omega_k[k] - speeds) - 1).max(),
                    np.abs(diagram.branch(f"backward whirl {k + 1}") / (omega_k[k] + speeds) - 1).max())
    return diagram, error


def spinning_table() -> None:
    speeds = np.linspace(0.0, 30.0, 31)
    start = time.perf_counter()
    _, error = whirl_error(4, speeds)
    print(f"spinning_beam, ρI = 0, 4 functions per plane, Ω = 0 … 30: max relative error of the whirls "
          f"against |ω_k ∓ Ω|: {error:.1e} ({(time.perf_counter() - start) / len(speeds):.3f} s per speed)")
    for rho_I in (None, 0.01):
        diagram, _ = whirl_error(4, speeds, rho_I=rho_I)
        split = diagram.branch("backward whirl 2") - diagram.branch("forward whirl 2")
        print(f"spinning_beam, ρI = {rho_I or 0}: backward − forward whirl 2 at Ω = 10: {split[10]:.4f} rad/s")


#: bounds of the quick mode's relative errors, 10× the largest measured (1.5e-14 and 2.3e-15; were 1e-10)
QUICK_BOUNDS = {"whirls vs |ω_k ∓ Ω|": 1.5e-13, "ω_lag² = ω_flap² − Ω²": 2.3e-14}


def quick() -> dict:
    """The small cases; returns each relative error by the name of its reference (QUICK_BOUNDS)."""
    speeds = np.linspace(0.0, 8.0, 5)
    _, whirl = whirl_error(2, speeds)
    diagram, _ = blade(0.5, speeds, 4)
    identity = np.abs(diagram.branch("lead-lag 1") ** 2 - (diagram.branch("flapwise 1") ** 2 - speeds**2)).max()
    identity /= diagram.branch("flapwise 1").max() ** 2
    print(f"quick: spinning beam whirls vs |ω_k ∓ Ω|: {whirl:.1e}; blade ω_lag² = ω_flap² − Ω²: {identity:.1e}")
    return {"whirls vs |ω_k ∓ Ω|": whirl, "ω_lag² = ω_flap² − Ω²": identity}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the small cases only (≤ 3 s)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")  # the interpreted-evaluator notice where numba is missing
    if args.quick:
        errors = quick()
        return int(any(errors[name] > bound for name, bound in QUICK_BOUNDS.items()))
    blade_table()
    spinning_table()
    return 0


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    sys.exit(main())

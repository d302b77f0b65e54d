"""Campbell diagrams of the two rotor scenes: cost per speed and accuracy of the branches.

1. ``scenes.rotating_blade`` (L = EI = ρA = 1, so Ω is Wright et al.'s η) with ten
   clamped–free functions per plane, hub radius R/L = 0, 0.5, 1, over η = 0 … 12: the
   first two flapwise and lead-lag branches against the Frobenius series of Wright, Smith,
   Thresher & Wang (1982), "Vibration modes of centrifugally stiffened beams", J. Appl.
   Mech. 49:197–202 (w'''' − (N w′)′ = λ² w, N = η² [r (1 − ξ) + (1 − ξ²)/2]; lead-lag
   λ² + η² in place of λ²; tests/analysis/rotating_cantilever.py); the wall time per speed; the critical speeds
   of the coarse sweep against a sweep four times finer (linear interpolation between
   speeds: O(ΔΩ²)).
2. ``scenes.spinning_beam`` with ρI = 0 (four clamped–free eigenfunctions per plane, exact
   at rest): forward and backward whirl against |ω_k ∓ Ω| over Ω = 0 … 30, through the
   zero of each forward whirl; and the split of the second whirls at Ω = 10 with ρI = 0.01
   (rotary inertia makes the shaft gyroscopic: 2Ω = 20 rad/s without it).

``--quick`` (≤ 3 s, run by tests/analysis/test_campbell.py): four functions per plane, five
speeds, the spinning beam's closed form and the blade's ω_lag² = ω_flap² − Ω².

    python benchmarks/campbell.py [--quick]

Measured (2 shared cores, interpreted evaluator): see the printed table; 10 functions per
plane cost ≈ 0.1 s per speed (the linearisation 0.03 s).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))  # for tests.analysis

from projeq.analysis.campbell import campbell  # noqa: E402
from projeq.scenes import rotating_blade, spinning_beam  # noqa: E402
from projeq.subsystems.beam.shapes import clamped_free_roots  # noqa: E402
from tests.analysis.rotating_cantilever import frobenius_frequencies  # noqa: E402


def blade(hub_radius: float, speeds, n_shapes: int):
    start = time.perf_counter()
    diagram = campbell(lambda w: rotating_blade(omega=w, hub_radius=hub_radius, n_shapes=n_shapes), speeds, n_modes=4)
    return diagram, (time.perf_counter() - start) / len(speeds)


def blade_table(n_shapes: int = 10) -> None:
    print(f"rotating_blade, {n_shapes} functions per plane: max relative error over η = 0 … 12 "
          "against the Frobenius series")
    print(f"{'R/L':>5} {'flap 1':>9} {'flap 2':>9} {'lag 1':>9} {'lag 2':>9} {'s/speed':>8}  critical speeds "
          "(coarse − fine)")
    coarse = np.linspace(0.0, 12.0, 13)
    for hub_radius in (0.0, 0.5, 1.0):
        diagram, per_speed = blade(hub_radius, coarse, n_shapes)
        errors = np.zeros(4)
        for k, eta in enumerate(coarse):
            exact = np.r_[frobenius_frequencies(eta, hub_radius, 2), frobenius_frequencies(eta, hub_radius, 2, True)]
            found = [diagram.branch(f"{kind} {i}")[k] for kind in ("flapwise", "lead-lag") for i in (1, 2)]
            errors = np.maximum(errors, np.abs(np.array(found) / exact - 1))
        fine = blade(hub_radius, np.linspace(0.0, 12.0, 49), n_shapes)[0]
        pairs = {(c.mode, c.order): c.speed for c in fine.critical_speeds}
        shifts = [abs(c.speed - pairs[(c.mode, c.order)]) for c in diagram.critical_speeds if (c.mode, c.order) in pairs]
        print(f"{hub_radius:5.2f} " + " ".join(f"{e:9.1e}" for e in errors) + f" {per_speed:8.3f}  "
              f"{len(shifts)} found, max shift {max(shifts, default=0.0):.1e} rad/s")


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


def quick() -> float:
    """The small cases; returns the largest error (closed form 1e-10, identity 1e-10)."""
    speeds = np.linspace(0.0, 8.0, 5)
    _, whirl = whirl_error(2, speeds)
    diagram, _ = blade(0.5, speeds, 4)
    identity = np.abs(diagram.branch("lead-lag 1") ** 2 - (diagram.branch("flapwise 1") ** 2 - speeds**2)).max()
    identity /= diagram.branch("flapwise 1").max() ** 2
    print(f"quick: spinning beam whirls vs |ω_k ∓ Ω|: {whirl:.1e}; blade ω_lag² = ω_flap² − Ω²: {identity:.1e}")
    return max(whirl, identity)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the small cases only (≤ 3 s)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")  # the interpreted-evaluator notice where numba is missing
    if args.quick:
        return int(quick() > 1e-10)
    blade_table()
    spinning_table()
    return 0


if __name__ == "__main__":
    sys.exit(main())

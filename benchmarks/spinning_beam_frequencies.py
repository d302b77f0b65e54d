"""The spinning beam without rotary inertia (ρI = 0): Ritz frequencies against the closed form.

H. Bremer, "Problems in fast moving non-holonomic elastic systems", B(23) with ρI = 0 at the constant
spin α̇ = Ω: with u = v + i w the field equations are ρA(ü + 2iΩu̇ − Ω²u) + EI ∂⁴u/∂x⁴ = 0 with the
cantilever's boundary conditions (clamped at 0; B₁ = EI u″ = 0, B₀ = −EI u‴ = 0 at L,
``projection_boundary_operators``), so the modes are the non-rotating cantilever's, u = φ_k(x) e^{iλt},
and (λ + Ω)² = ω_k²: the frequencies seen in the co-rotating frame are |ω_k ± Ω|, ω_k = (β_k L)²
√(EI/(ρA L⁴)), 1 + cos β_k L cosh β_k L = 0 (e.g. Meirovitch, Fundamentals of Vibrations, 2001, §8.5).
The Ritz model of the Projection Equation (``ritz_models(n, kinds=("projection",))``, clamped
polynomials (x/L)^(k+1), n = n_v = n_w functions per plane) is compared with them for n = 2 … 8; the
error of the first three frequencies and its rate are printed. The symbolic derivation of the Ritz
matrices dominates the time (n = 8: about a minute).

    python benchmarks/spinning_beam_frequencies.py           # n = 2 … 8
    python benchmarks/spinning_beam_frequencies.py --quick   # n = 2 only (PROJEQ_QUICK=1 too)
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from scipy.optimize import brentq

from projeq.symbolic.spinning_beam import ritz_models

OMEGA = 1.3  # spin in units of √(EI/(ρA L⁴)) (ρA = EI = L = 1)


def cantilever_frequencies(count: int = 3) -> np.ndarray:
    """ω_k = (β_k L)² of the clamped-free Euler–Bernoulli beam (ρA = EI = L = 1)."""
    return np.array([brentq(lambda b: 1 + np.cos(b) * np.cosh(b), k * np.pi + 0.1, (k + 1) * np.pi - 0.1) ** 2
                     for k in range(count)]) if count else np.zeros(0)


def closed_form(omega: float = OMEGA, count: int = 3) -> np.ndarray:
    """The lowest ``count`` of |ω_k ± Ω| (the co-rotating frame's frequencies)."""
    return np.sort(np.abs(np.concatenate([cantilever_frequencies(count) + omega,
                                          cantilever_frequencies(count) - omega])))[:count]


def ritz_frequencies(n: int, omega: float = OMEGA) -> np.ndarray:
    """Frequencies |Im λ| of M ä + Ω G ȧ + (K − Ω² K_c) a = 0, ρI = 0, ascending (each once)."""
    model = ritz_models(n, rho_I_value=0.0, kinds=("projection",))["projection"]
    size = len(model.M)
    system = np.block([[np.zeros((size, size)), np.eye(size)],
                       [-np.linalg.solve(model.M, model.K - omega**2 * model.K_c),
                        -np.linalg.solve(model.M, omega * model.G)]])
    return np.sort(np.abs(np.linalg.eigvals(system).imag))[::2]


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", default=os.environ.get("PROJEQ_QUICK") == "1")
    args = parser.parse_args(argv)
    exact = closed_form()
    print(f"closed form |ω_k ± Ω|, Ω = {OMEGA}: " + ", ".join(f"{f:.10f}" for f in exact))
    print(f"{'n':>2} {'derive_s':>8}  relative errors of the first three frequencies")
    rows = []
    for n in ([2] if args.quick else range(2, 9)):
        start = time.perf_counter()
        found = ritz_frequencies(n)[:3]
        error = np.abs(found / exact - 1)
        rows.append({"n": n, "seconds": time.perf_counter() - start, "frequencies": found, "errors": error})
        print(f"{n:>2} {rows[-1]['seconds']:8.2f}  " + "  ".join(f"{e:.2e}" for e in error))
    for previous, row in zip(rows, rows[1:]):
        print(f"n {previous['n']} → {row['n']}: error of the third frequency divided by "
              f"{previous['errors'][2] / row['errors'][2]:.3g}")
    return {"exact": exact, "rows": rows}


if __name__ == "__main__":
    main()

"""The spinning beam's natural frequencies: the PDE's against the Ritz model of the Projection Equation.

H. Bremer, "Problems in fast moving non-holonomic elastic systems", B(23) at the constant spin α̇ = Ω with
the boundary conditions of its integration by parts B(21) (B₀ = B₁ = 0 at the free end,
``projection_boundary_operators``). A whirl v + i w = U(x) e^{iλt} solves
EI U⁗ + ρI(λ² − Ω²) U″ − ρA(λ + Ω)² U = 0 (``whirl_equations``); the co-rotating frequencies are |λ|.

* ρI = 0: the modes are the non-rotating cantilever's, (λ + Ω)² = ω_k², the frequencies |ω_k ± Ω|,
  ω_k = (β_k L)² √(EI/(ρA L⁴)), 1 + cos β_k L cosh β_k L = 0 (e.g. Meirovitch, Fundamentals of
  Vibrations, 2001, §8.5): a closed form.
* ρI > 0: the PDE's frequencies by Chebyshev collocation (``whirl_frequencies``), checked independently
  against the roots of the 4 × 4 boundary determinant of U = C₁ cosh ax + C₂ sinh ax + C₃ cos bx + C₄ sin bx
  (a², −b² the roots of EI s⁴ + ρI(λ² − Ω²)s² − ρA(λ + Ω)² = 0); at Ω = 0 that determinant is the
  Rayleigh cantilever's frequency equation (Han, Benaroya & Wei, "Dynamics of transversely vibrating
  beams using four engineering theories", J. Sound Vib. 225, 1999).

The Ritz model of the Projection Equation (``ritz_models(n, kinds=("projection",))``, clamped polynomials
(x/L)^(k+1), n = n_v = n_w functions per plane) is compared with them for n = 2 … 8; the errors of the
first three frequencies and their rates are printed. The symbolic derivation of the Ritz matrices
dominates the time (n = 8: about a minute; both ρI values share it).

Measured (Ω = 1.3): the PDE's spectral frequencies equal the determinant's roots to 2e-15. The Ritz
errors of the first frequency fall 7.5e-3, 4.8e-4, 2.4e-6, 6.1e-8, 1.4e-10 for n = 2…6 at ρI = 0 and
7.1e-3, 4.7e-4, 2.3e-6, 6.0e-8, 1.0e-10 at ρI = 0.01 (factors 15, 200, 40, 400–600 per added function:
each odd n adds the shape the next mode needs); beyond n = 6 they stop falling (ρI = 0.01: 1e-10,
3e-10 at n = 7, 8; ρI = 0: 5.9e-9, 7.8e-8): the monomials (x/L)^(k+1) are nearly dependent, cond(M) =
6e5, 1e9, 2e12 at n = 4, 6, 8. The third frequency falls to 7e-9 at n = 7.

    python benchmarks/spinning_beam_frequencies.py           # n = 2 … 8
    python benchmarks/spinning_beam_frequencies.py --quick   # n = 2 only (PROJEQ_QUICK=1 too)
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np
from scipy.optimize import brentq

from projeq.symbolic.spinning_beam import ritz_models, whirl_frequencies

OMEGA = 1.3  # spin in units of √(EI/(ρA L⁴)) (ρA = EI = L = 1)
RHO_I = 0.01  # rotary inertia per length (radius of gyration 0.1 L)


def cantilever_frequencies(count: int = 3) -> np.ndarray:
    """ω_k = (β_k L)² of the clamped-free Euler–Bernoulli beam (ρA = EI = L = 1)."""
    return np.array([brentq(lambda b: 1 + np.cos(b) * np.cosh(b), k * np.pi + 0.1, (k + 1) * np.pi - 0.1,
                            xtol=1e-14, rtol=1e-15) ** 2 for k in range(count)]) if count else np.zeros(0)


def closed_form(omega: float = OMEGA, count: int = 3) -> np.ndarray:
    """The lowest ``count`` of |ω_k ± Ω| (the co-rotating frame's frequencies)."""
    return np.sort(np.abs(np.concatenate([cantilever_frequencies(count) + omega,
                                          cantilever_frequencies(count) - omega])))[:count]


def boundary_determinant(lam, omega: float, rho_I: float):
    """det of the clamped-free conditions on U = (cosh ax, sinh ax, cos bx, sin bx)·C (ρA = EI = L = 1):
    U(0) = U′(0) = 0, U″(1) = 0, U‴(1) + ρI(λ² − Ω²) U′(1) = 0, divided by cosh a; ``lam`` may be an array."""
    lam = np.asarray(lam, dtype=float)
    k = rho_I * (lam**2 - omega**2)
    root = np.sqrt(k**2 + 4 * (lam + omega) ** 2)
    a, b = np.sqrt((root - k) / 2), np.sqrt((root + k) / 2)
    ch, sh, c, s = np.cosh(a), np.sinh(a), np.cos(b), np.sin(b)
    zero, one = np.zeros_like(lam), np.ones_like(lam)
    rows = [[one, zero, one, zero], [zero, a, zero, b], [a * a * ch, a * a * sh, -b * b * c, -b * b * s],
            [(a**3 + k * a) * sh, (a**3 + k * a) * ch, (b**3 - k * b) * s, (k * b - b**3) * c]]
    return np.linalg.det(np.moveaxis(np.array(rows), (0, 1), (-2, -1))) / ch


def determinant_frequencies(omega: float = OMEGA, rho_I: float = RHO_I, count: int = 3, top: float = 60.0):
    """The lowest ``count`` |λ| at which :func:`boundary_determinant` changes sign (grid 1e-3, then brentq);
    at Ω = 0 each appears twice (λ and −λ)."""
    grid = np.arange(-top, top, 1e-3) + 0.5e-3  # never exactly λ = −Ω (a = b = 0)
    values = boundary_determinant(grid, omega, rho_I)
    roots = [brentq(boundary_determinant, grid[i], grid[i + 1], args=(omega, rho_I), xtol=1e-14, rtol=1e-15)
             for i in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))]
    return np.sort(np.abs(roots))[:count]


def ritz_frequencies(n: int, omega: float = OMEGA, rho_I: float = 0.0) -> np.ndarray:
    """Frequencies |Im λ| of M ä + Ω G ȧ + (K − Ω² K_c) a = 0, ascending (each once)."""
    model = ritz_models(n, rho_I_value=rho_I, kinds=("projection",))["projection"]
    size = len(model.M)
    system = np.block([[np.zeros((size, size)), np.eye(size)],
                       [-np.linalg.solve(model.M, model.K - omega**2 * model.K_c),
                        -np.linalg.solve(model.M, omega * model.G)]])
    return np.sort(np.abs(np.linalg.eigvals(system).imag))[::2]


def convergence(label: str, exact: np.ndarray, sizes, rho_I: float) -> list:
    """Ritz errors against ``exact`` for each n in ``sizes``, printed with the rate e(n)/e(n+1)."""
    print(f"{label}: " + ", ".join(f"{f:.10f}" for f in exact))
    print(f"{'n':>2} {'derive_s':>8}  relative errors of the first three frequencies")
    rows = []
    for n in sizes:
        start = time.perf_counter()
        found = ritz_frequencies(n, rho_I=rho_I)[:3]
        error = np.abs(found / exact - 1)
        rows.append({"n": n, "seconds": time.perf_counter() - start, "frequencies": found, "errors": error})
        print(f"{n:>2} {rows[-1]['seconds']:8.2f}  " + "  ".join(f"{e:.2e}" for e in error))
    for previous, row in zip(rows, rows[1:]):
        print(f"n {previous['n']} → {row['n']}: errors divided by "
              + ", ".join(f"{p / e:.3g}" for p, e in zip(previous["errors"], row["errors"])))
    return rows


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", default=os.environ.get("PROJEQ_QUICK") == "1")
    args = parser.parse_args(argv)
    sizes = [2] if args.quick else range(2, 9)
    exact = closed_form()
    rows = convergence(f"ρI = 0, closed form |ω_k ± Ω|, Ω = {OMEGA}", exact, sizes, 0.0)
    pde = whirl_frequencies(OMEGA, RHO_I)
    determinant = determinant_frequencies()
    print(f"ρI = {RHO_I}: PDE by Chebyshev collocation against the boundary determinant's roots: relative "
          + ", ".join(f"{e:.1e}" for e in np.abs(pde / determinant - 1)))
    inertia_rows = convergence(f"ρI = {RHO_I}, the PDE's frequencies, Ω = {OMEGA}", pde, sizes, RHO_I)
    return {"exact": exact, "rows": rows, "pde": pde, "determinant": determinant,
            "inertia_rows": inertia_rows}


os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: this measures the compiled path


if __name__ == "__main__":
    main()

"""Ritz shape-function families for beams: Φ, Φ′, Φ″ at stations x (docs/theory.md §10).

A family is a callable ``family(n, L)`` returning ``shapes(x) -> (Φ, Φ′, Φ″[, Φ‴])``, each
of shape (n, len(x)); Φ‴ (for shear forces) is optional in user families. Bending families
of a clamped root satisfy Φ(0) = Φ′(0) = 0, of a pinned root Φ(0) = 0; axial and torsional
ones Φ(0) = 0. ``n`` (the number of functions) is the accuracy knob.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

# roots of 1 + cos βL cosh βL = 0 (clamped–free), refined numerically below
_CLAMPED_FREE_GUESS = (1.875, 4.694, 7.855, 10.996)


def polynomial(n: int, L: float):
    """Clamped bending: Φ_k = (x/L)^(k+1), k = 1 … n."""
    k = np.arange(2, n + 2)[:, None]

    def shapes(x):
        xi = np.asarray(x, dtype=float)[None, :] / L
        third = k * (k - 1) * (k - 2) * xi ** np.maximum(k - 3, 0) / L**3
        return xi**k, k * xi ** (k - 1) / L, k * (k - 1) * xi ** (k - 2) / L**2, third

    return shapes


def axial_polynomial(n: int, L: float):
    """Axial displacement with u(0) = 0: Φ_k = (x/L)^k, k = 1 … n."""
    k = np.arange(1, n + 1)[:, None]

    def shapes(x):
        xi = np.asarray(x, dtype=float)[None, :] / L
        second = k * (k - 1) * xi ** np.maximum(k - 2, 0) / L**2
        return xi**k, k * xi ** (k - 1) / L, second, k * (k - 1) * (k - 2) * xi ** np.maximum(k - 3, 0) / L**3

    return shapes


def clamped_free_roots(n: int) -> NDArray:
    """β_k L of 1 + cos βL cosh βL = 0, k = 1 … n (1.8751041, 4.6940911, …)."""
    from scipy.optimize import brentq  # here, not at the top: keeps `import projeq` light

    guesses = list(_CLAMPED_FREE_GUESS) + [(2 * k - 1) * np.pi / 2 for k in range(5, n + 1)]
    f = lambda b: 1.0 + np.cos(b) * np.cosh(b)  # noqa: E731
    return np.array([brentq(f, g - 0.3, g + 0.3) for g in guesses[:n]])


def clamped_free(n: int, L: float):
    """Eigenfunctions of the clamped–free Euler–Bernoulli beam (normalised to 2 at the tip):
    Φ_k = cosh βx − cos βx − σ_k (sinh βx − sin βx), σ_k = (cosh βL + cos βL)/(sinh βL + sin βL)."""
    beta = clamped_free_roots(n)[:, None] / L
    bL = beta * L
    sigma = (np.cosh(bL) + np.cos(bL)) / (np.sinh(bL) + np.sin(bL))

    def shapes(x):
        bx = beta * np.asarray(x, dtype=float)[None, :]
        ch, c, sh, s = np.cosh(bx), np.cos(bx), np.sinh(bx), np.sin(bx)
        return (
            ch - c - sigma * (sh - s),
            beta * (sh + s - sigma * (ch - c)),
            beta**2 * (ch + c - sigma * (sh + s)),
            beta**3 * (sh - s - sigma * (ch + c)),
        )

    return shapes


def axial_clamped_free(n: int, L: float):
    """Axial eigenfunctions of the fixed–free bar: Φ_k = sin((2k − 1) π x / 2L)."""
    a = (2 * np.arange(1, n + 1) - 1)[:, None] * np.pi / (2 * L)

    def shapes(x):
        ax = a * np.asarray(x, dtype=float)[None, :]
        return np.sin(ax), a * np.cos(ax), -(a**2) * np.sin(ax), -(a**3) * np.cos(ax)

    return shapes


def pinned_free_roots(n: int) -> NDArray:
    """β_k L of tan βL = tanh βL, k = 1 … n (3.9266023, 7.0685835, 10.2101761, …; the
    root βL = 0, the rigid rotation about the pin, is left to the hub joint)."""
    from scipy.optimize import brentq

    f = lambda b: np.sin(b) * np.cosh(b) - np.cos(b) * np.sinh(b)  # noqa: E731  (tan = tanh)
    guesses = (4 * np.arange(1, n + 1) + 1) * np.pi / 4
    return np.array([brentq(f, g - 0.3, g + 0.3) for g in guesses])


def pinned_free(n: int, L: float):
    """Elastic eigenfunctions of the pinned–free Euler–Bernoulli beam (Φ(0) = Φ″(0) = 0,
    Φ″(L) = Φ‴(L) = 0): Φ_k = sin βx + σ_k sinh βx, σ_k = sin βL / sinh βL."""
    beta = pinned_free_roots(n)[:, None] / L
    bL = beta * L
    sigma = np.sin(bL) / np.sinh(bL)

    def shapes(x):
        bx = beta * np.asarray(x, dtype=float)[None, :]
        ch, c, sh, s = np.cosh(bx), np.cos(bx), np.sinh(bx), np.sin(bx)
        return s + sigma * sh, beta * (c + sigma * ch), beta**2 * (sigma * sh - s), beta**3 * (sigma * ch - c)

    return shapes


BENDING = {"polynomial": polynomial, "clamped_free": clamped_free, "pinned_free": pinned_free}
AXIAL = {"polynomial": axial_polynomial, "clamped_free": axial_clamped_free}

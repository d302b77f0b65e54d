"""Numerical differentiation: every finite-difference stencil and the complex step projeq uses.

Each rule differentiates a function f of one real variable ε at ε = 0 — a directional
derivative when f(ε) = g(x + ε v) — element-wise for array values. With ε_m ≈ 2.2e-16
and |f| the size of the values, the errors of a step h are (Taylor expansion; e.g.
Fornberg, "Generation of finite difference formulas on arbitrarily spaced grids",
Math. Comp. 51, 1988; Martins, Sturdza & Alonso, "The complex-step derivative
approximation", ACM TOMS 29, 2003):

- :func:`central`, (f(h) − f(−h)) / 2h: truncation h²/6 |f‴|, round-off ε_m |f| / h;
- :func:`richardson`, (−f(2h) + 8 f(h) − 8 f(−h) + f(−2h)) / 12h: truncation h⁴/30 |f⁽⁵⁾|,
  round-off 1.5 ε_m |f| / h;
- :func:`second` (the second derivative), (−f(2h) + 16 f(h) − 30 f(0) + 16 f(−h) − f(−2h)) / 12h²:
  truncation h⁴/90 |f⁽⁶⁾|, round-off 5.3 ε_m |f| / h²;
- :func:`forward`, (f(h) − f(0)) / h: truncation h/2 |f″|, round-off 2 ε_m |f| / h;
- :func:`complex_step`, Im f(ih) / h: truncation h²/6 |f‴|, round-off ε_m |f′|.

The complex step subtracts nothing, so h can be tiny (:data:`COMPLEX_STEP` = 1e-30) and the
derivative is exact to round-off; it needs f to accept complex arguments (numpy ufuncs and
:mod:`projeq.spatial` do). The steps are the callers' choice, stated where they are chosen;
:func:`jacobian` and :func:`gradient` state their own step rules.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

COMPLEX_STEP = 1e-30  # Im f(ih)/h: truncation h²/6 |f‴| ≈ 1e-61, far below round-off
JACOBIAN_STEP = 1e-4  # relative step of the coarser central difference in :func:`jacobian`
GRADIENT_STEP = 1e-6  # relative step of :func:`gradient`


def central(f, h: float):
    """df/dε at 0 by the central difference (f(h) − f(−h)) / 2h: truncation O(h²),
    h²/6 |f‴|; round-off ε_m |f| / h (balanced at h ≈ ε_m^(1/3) ≈ 6e-6 relative)."""
    return (f(h) - f(-h)) / (2 * h)


def richardson(f, h: float):
    """df/dε at 0 by the five-point stencil (−f(2h) + 8 f(h) − 8 f(−h) + f(−2h)) / 12h:
    Richardson's extrapolation (4 D(h) − D(2h))/3 of two central differences D. Truncation
    O(h⁴), h⁴/30 |f⁽⁵⁾|; round-off 1.5 ε_m |f| / h (balanced at h ≈ ε_m^(1/5) ≈ 7e-4 relative)."""
    return (-f(2 * h) + 8 * f(h) - 8 * f(-h) + f(-2 * h)) / (12 * h)


def second(f, h: float):
    """d²f/dε² at 0 by the five-point stencil (−f(2h) + 16 f(h) − 30 f(0) + 16 f(−h) − f(−2h)) / 12h²:
    truncation O(h⁴), h⁴/90 |f⁽⁶⁾|; round-off 5.3 ε_m |f| / h² (balanced at h ≈ ε_m^(1/6) ≈ 2.5e-3
    relative)."""
    return (-f(2 * h) + 16 * f(h) - 30 * f(0.0) + 16 * f(-h) - f(-2 * h)) / (12 * h * h)


def forward(f, h: float, f0=None):
    """df/dε at 0 by the forward difference (f(h) − f(0)) / h, with ``f0`` = f(0) when it is
    known (one evaluation instead of two): truncation O(h), h/2 |f″|; round-off 2 ε_m |f| / h
    (balanced at h ≈ √ε_m ≈ 1.5e-8 relative)."""
    return (f(h) - (f(0.0) if f0 is None else f0)) / h


def complex_step(f, h: float = COMPLEX_STEP):
    """df/dε at 0 as Im f(ih) / h for an f that is real on the real axis and accepts complex
    arguments: truncation O(h²), h²/6 |f‴|, and no subtractive cancellation, so with the
    default h = 1e-30 it is exact to round-off."""
    return np.imag(f(1j * h)) / h


def jacobian(f, z0: NDArray, step: float = JACOBIAN_STEP) -> NDArray:
    """∂f/∂z at z0, column i by :func:`richardson` along e_i with h = step · max(1, |z0_i|) / 2
    (the coarser central difference spans step · max(1, |z0_i|)): truncation O(h⁴).

    >>> J = jacobian(lambda z: np.array([np.sin(z[0]) * z[1]]), np.array([0.5, 2.0]))
    >>> bool(np.allclose(J, [[2 * np.cos(0.5), np.sin(0.5)]], rtol=1e-11, atol=0))
    True
    """
    z0 = np.asarray(z0, dtype=float)
    n_f = len(f(z0))
    columns = []
    for i in range(len(z0)):
        e = np.zeros_like(z0)
        e[i] = 1.0
        columns.append(richardson(lambda eps, e=e: f(z0 + eps * e), step * max(1.0, abs(z0[i])) / 2))
    return np.array(columns).T.reshape(n_f, len(z0))


def gradient(f, x: NDArray, f0: float | None = None, step: float = GRADIENT_STEP) -> NDArray:
    """∇f(x) of a scalar function, component i with h = step · (1 + |x_i|): by :func:`central`
    (truncation O(h²)), or, given ``f0`` = f(x), by :func:`forward` (O(h), half the evaluations)."""
    out = np.empty_like(x)
    for i in range(len(x)):
        e = np.zeros_like(x)
        e[i] = 1.0
        along = lambda eps, e=e: f(x + eps * e)  # noqa: E731
        h = step * (1.0 + abs(x[i]))
        out[i] = central(along, h) if f0 is None else forward(along, h, f0)
    return out

"""An extended-precision reference s̈ for ``scenes.chain(n)``, independent of projeq's evaluators.

Lagrange's equations of the n-link compound pendulum in **absolute** angles φ = P q
(P lower-triangular ones, so φ_j = q_1 + … + q_j; any textbook on Lagrangian mechanics),
evaluated and solved with mpmath at ``digits`` significant digits, then rounded to float64.
It serves to decide which of two float64 evaluators is closer to the exact s̈ when they
disagree (issue 7: fast vs dense at n = 100, see docs/theory.md, "Accuracy of the two
evaluators").

The scene (``projeq.scenes.chain``): links of length L = 1 m, mass m = 1 kg, solid
cylinders of radius r = 0.01 m, transverse moment I_c = m (3r² + L²)/12 about the mass
centre, hinged at the upper end about +y; in φ = 0 they hang along −z, gravity g = 9.81 m/s²
along −z. A rotation by φ about +y turns −e_z into e(φ) = (−sin φ, 0, −cos φ), so the mass
centre of link i (1-based) is r_i = Σ_j c_ij e(φ_j) with c_ij = L (j < i), L/2 (j = i),
0 (j > i), and e′(φ_j)·e′(φ_k) = cos(φ_j − φ_k). With T = Σ_i ½ m |ṙ_i|² + ½ I_c φ̇_i² and
V = −Σ_i m g Σ_j c_ij cos φ_j, Lagrange's equations d/dt ∂T/∂φ̇_j − ∂T/∂φ_j = −∂V/∂φ_j read

    Σ_k M_jk φ̈_k = −Σ_k a_jk sin(φ_j − φ_k) φ̇_k² − g_j sin φ_j,

    M_jk = a_jk cos(φ_j − φ_k) + I_c δ_jk,
    a_jk = Σ_{i ≥ max(j,k)} m c_ij c_ik = m L² (n − max(j,k) + ½) − δ_jk m L²/4,
    g_j  = Σ_{i ≥ j} m g c_ij = m g L (n − j + ½),

and q̈ = P⁻¹ φ̈ (q̈_1 = φ̈_1, q̈_j = φ̈_j − φ̈_{j−1}). The angles are summed and the equations
assembled in mpmath from the float64 inputs taken exactly, and solved to the same
precision (:func:`solve_refined`), so the result is the exact s̈ of the float inputs up to
about 10^−digits · κ(M_abs) before rounding to float64; κ(M_abs) ≈ 1e5 at n = 200, where
the relative-angle mass matrix Pᵀ M_abs P of the evaluators has κ ≈ 7e8. Cost: O(n²)
interpreted multi-precision operations, about 0.1 s at n = 30, 0.5 s at n = 100, 2 s at
n = 200 and 4 s at n = 300 on a 2-core machine.

>>> import numpy as np
>>> s_ddot = chain_s_ddot(np.array([0.5]), np.array([0.0]))  # one link: −m g (L/2) sin φ / (m L²/3 + m r²/4)
>>> bool(np.isclose(s_ddot[0], -9.81 * 0.5 * np.sin(0.5) / (1 / 3 + 0.01**2 / 4), rtol=1e-15))
True
"""

from __future__ import annotations

import mpmath
import numpy as np
import scipy.linalg
from numpy.typing import NDArray

from projeq.checks import count, finite_array, state_vector

LENGTH, MASS, RADIUS, GRAVITY = 1.0, 1.0, 0.01, 9.81  # the links and gravity of scenes.chain
MIN_DIGITS = 20  # fewer: the reference's own error 10^−digits κ(M_abs) (κ ≈ 1e5) would near float64's ε


def chain_s_ddot(q, s_dot, digits: int = 40) -> NDArray:
    """s̈ of ``scenes.chain(n)`` at (q, ṡ) by Lagrange's equations in absolute angles,
    solved at ``digits`` significant digits (module docstring; q = relative joint angles,
    ṡ = q̇).

    Parameters
    ----------
    q, s_dot : array_like, shape (n,)
        Relative joint angles and their rates, finite.
    digits : int
        Significant decimal digits of the computation, at least 20.

    Returns
    -------
    ndarray, shape (n,)
        q̈ rounded to float64.
    """
    q = finite_array("q", q)
    if q.ndim != 1 or q.size == 0:
        raise ValueError(f"q: expected a non-empty 1-D array, got shape {q.shape}")
    s_dot = state_vector("s_dot", s_dot, q.size)
    ctx = mpmath.MPContext()
    ctx.dps = count("digits", digits, MIN_DIGITS)
    phi, phi_dot = _cumulative_sum(ctx, q), _cumulative_sum(ctx, s_dot)
    M_abs, rhs = _lagrange_equations(ctx, phi, phi_dot)
    phi_ddot = solve_refined(ctx, M_abs, rhs)
    q_ddot = [phi_ddot[0]] + [phi_ddot[j] - phi_ddot[j - 1] for j in range(1, len(q))]
    return np.array([float(x) for x in q_ddot])


def _lagrange_equations(ctx, phi: list, phi_dot: list) -> tuple:
    """M_abs(φ) and the right-hand side −Σ_k a_jk sin(φ_j − φ_k) φ̇_k² − g_j sin φ_j of the
    module docstring's equations, as mpmath matrices (0-based j, k: n − j + ½ becomes
    n − j − ½). cos(φ_j − φ_k) and sin(φ_j − φ_k) by the addition theorems, so that only
    2n sines and cosines are evaluated."""
    n = len(phi)
    m, L, r, g = (ctx.mpf(x) for x in (MASS, LENGTH, RADIUS, GRAVITY))
    I_c = m * (3 * r**2 + L**2) / 12
    cos, sin = [ctx.cos(x) for x in phi], [ctx.sin(x) for x in phi]
    M_abs, rhs = ctx.matrix(n, n), ctx.matrix(n, 1)
    for j in range(n):
        for k in range(n):
            a_jk = m * L**2 * (n - max(j, k) - ctx.mpf(0.5)) - (m * L**2 / 4 if j == k else 0)
            M_abs[j, k] = a_jk * (cos[j] * cos[k] + sin[j] * sin[k]) + (I_c if j == k else 0)
            rhs[j] -= a_jk * (sin[j] * cos[k] - cos[j] * sin[k]) * phi_dot[k] ** 2
        rhs[j] -= m * g * L * (n - j - ctx.mpf(0.5)) * sin[j]
    return M_abs, rhs


def solve_refined(ctx, A, b):
    """x with A x = b to the precision of the mpmath context ``ctx``, by mixed-precision
    iterative refinement (Higham, *Accuracy and Stability of Numerical Algorithms*, 2nd ed.,
    2002, §12.1): corrections from one float64 LU of A, residuals b − A x in ctx's
    precision, until the normwise backward error ‖b − A x‖∞ / (‖A‖∞ ‖x‖∞ + ‖b‖∞) is at
    most 10 n ε_ctx. Each step gains about −log10(κ(A) ε_64) digits (≳ 10 for κ ≲ 1e5): a
    few O(n²) steps instead of mpmath's interpreted O(n³) LU (20 s at n = 200).

    Raises ArithmeticError when that is not reached within ``ctx.dps`` steps (κ(A) ε_64
    not small, so float64 corrections do not converge).
    """
    n = b.rows
    lu = scipy.linalg.lu_factor(_float(A))
    A_norm, b_norm = ctx.mnorm(A, ctx.inf), ctx.mnorm(b, ctx.inf)
    x = ctx.zeros(n, 1)
    for _ in range(ctx.dps):
        r = b - A * x
        if ctx.mnorm(r, ctx.inf) <= 10 * n * ctx.eps * (A_norm * ctx.mnorm(x, ctx.inf) + b_norm):
            return x
        x += ctx.matrix(scipy.linalg.lu_solve(lu, _float(r)))
    raise ArithmeticError(f"iterative refinement did not converge in {ctx.dps} steps: "
                          "A is too ill-conditioned for float64 corrections")


def _float(A) -> NDArray:
    """An mpmath matrix as a float64 array."""
    return np.array(A.tolist(), dtype=float)


def _cumulative_sum(ctx, x: NDArray) -> list:
    """φ = P x in ctx's precision (the float64 entries are taken exactly)."""
    total, sums = ctx.mpf(0), []
    for x_j in x:
        total += ctx.mpf(float(x_j))
        sums.append(total)
    return sums

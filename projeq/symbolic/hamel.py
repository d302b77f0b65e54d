"""Hamel's equations for minimal velocities ṡ = H(q) q̇ (B(3)–(4) of Bremer (2009), docs/theory.md §8).

Index map (0-based, as in the code) of Hamel's coefficients: ``beta[nu, mu, n]`` is
β_{ν+1}^{μ+1, n+1} of B(4), i.e. ν the row of H being differentiated, μ the speed that
multiplies ∂T/∂ṡ_ν in B(3), n the equation.
"""

import sympy as sp

from .validation import check_symbols, matrix, symbol_vector

__all__ = ["hamel_coefficients", "hamel_equations", "check_regular"]


def check_regular(H, q, at=None) -> sp.Expr:
    """det H(q), after checking that H is square and regular (at the point ``at`` if given).

    Raises ``ValueError`` starting with ``H:`` when H is not square, its determinant
    vanishes identically, or it vanishes at ``at`` (a mapping q_i → value).

    >>> phi, r = sp.symbols("phi r")
    >>> check_regular(sp.diag(1, r), [phi, r])
    r
    """
    H = matrix("H", H)
    if H.rows != H.cols:
        raise ValueError(f"H: must be square (ṡ = H q̇ with as many speeds as coordinates), got {H.rows}×{H.cols}")
    if H.rows != len(q):
        raise ValueError(f"H: has {H.cols} columns but there are {len(q)} coordinates q")
    det = sp.simplify(H.det())
    if det == 0:
        raise ValueError("H: singular for every q (det H ≡ 0); the speeds ṡ = H q̇ are not independent")
    if at is not None and sp.simplify(det.subs(at)) == 0:
        raise ValueError(f"H: singular at q = {dict(at)} (det H = 0 there)")
    return det


def hamel_coefficients(H, q, at=None) -> sp.Array:
    """Hamel's coefficients B(4): β_ν^{μ,n} = Σ_{i,k} K_kμ K_in (∂H_νi/∂q_k − ∂H_νk/∂q_i), K = H⁻¹.

    Returns a rank-3 ``sympy.Array`` ``beta[nu, mu, n]`` (index map in the module
    docstring). All coefficients vanish when ṡ = H q̇ are derivatives of coordinates
    (H a Jacobian: ∂H_νi/∂q_k is symmetric in i, k).

    >>> x, y, g = q = sp.symbols("x y gamma")
    >>> H = sp.Matrix([[sp.cos(g), sp.sin(g), 0], [-sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
    >>> hamel_coefficients(H, q)[1, 2, 0]  # β₂^{3,1} of B(7)
    -1
    """
    q = symbol_vector("q", q)
    H = matrix("H", H)
    check_regular(H, q, at)
    return _coefficients(H, q, _kinematics(H))


def _kinematics(H) -> sp.Matrix:
    """K = H⁻¹ of q̇ = K ṡ (a kinematic relation; the mass matrix is never inverted)."""
    return H.inv().applyfunc(sp.simplify)


def _coefficients(H, q, K) -> sp.Array:
    """B(4) for a checked, square H with K = H⁻¹; ``beta[nu, mu, n]``."""
    n_s = H.rows
    dH = [H.diff(q_k) for q_k in q]  # dH[k][ν, i] = ∂H_νi/∂q_k
    beta = sp.MutableDenseNDimArray.zeros(n_s, n_s, n_s)
    for nu in range(n_s):
        curl = sp.Matrix(n_s, n_s, lambda i, k: dH[k][nu, i] - dH[i][nu, k])
        if curl.is_zero_matrix:  # s_ν holonomic (Schwarz)
            continue
        beta_nu = (K.T * curl.T * K).applyfunc(sp.simplify)  # [μ, n] = Σ_{i,k} K_kμ curl_ik K_in
        for mu in range(n_s):
            for n in range(n_s):
                beta[nu, mu, n] = beta_nu[mu, n]
    return sp.ImmutableDenseNDimArray(beta)


def hamel_equations(T, q, s, H, Q, s_ddot=None, t=sp.Symbol("t"), parameters=()) -> sp.Matrix:
    """Residuals of Hamel's equations B(3), one per speed:

        d/dt ∂T/∂ṡ_n − Σ_i (∂T/∂q_i) K_in − Q_n + Σ_{ν,μ} (∂T/∂ṡ_ν) ṡ_μ β_ν^{μ,n} = 0,

    with T = T(q, ṡ, t) the kinetic energy in the speeds, q̇ = K ṡ (K = H⁻¹) and Q the
    generalised forces of the speeds (virtual power Σ Q_n δṡ_n). The total derivative is
    expanded with ``s_ddot`` (default: symbols ``\\dot{s_n}``) for s̈; the result is linear
    in s̈ (``sympy.linear_eq_to_matrix`` gives the Gauss form).

    Every symbol in T, H, Q must be a coordinate, a speed, t or in ``parameters``.
    Constraints among the speeds (such as v_y = 0 for the car) go in *after* this
    derivation (docs/theory.md §8).
    """
    q, s = symbol_vector("q", q), symbol_vector("s", s)
    H, Q = matrix("H", H), matrix("Q", Q)
    if H.rows != len(s):
        raise ValueError(f"H: has {H.rows} rows but there are {len(s)} speeds s")
    if Q.shape != (len(s), 1):
        raise ValueError(f"Q: expected {len(s)} generalised forces (one per speed), got shape {Q.shape}")
    s_ddot = symbol_vector("s_ddot", s_ddot if s_ddot is not None else [sp.Symbol(rf"\dot{{{x}}}") for x in s])
    declared = set(q) | set(s) | {t} | set(parameters)
    for name, expr in (("T", T), ("H", H), ("Q", Q)):
        check_symbols(name, expr, declared)
    check_regular(H, q)
    K = _kinematics(H)
    beta = _coefficients(H, q, K)
    q_dot = K * sp.Matrix(s)
    dT_ds = [sp.diff(T, s_n) for s_n in s]
    residuals = []
    for n, p_n in enumerate(dT_ds):
        d_dt = sum(p_n.diff(a) * b for a, b in zip(s, s_ddot)) + sum(p_n.diff(a) * b for a, b in zip(q, q_dot)) + p_n.diff(t)
        potential = sum(sp.diff(T, q[i]) * K[i, n] for i in range(len(q)))
        coupling = sum(dT_ds[nu] * s[mu] * beta[nu, mu, n] for nu in range(len(s)) for mu in range(len(s)))
        residuals.append(sp.expand(d_dt - potential - Q[n] + coupling))
    return sp.Matrix(residuals)

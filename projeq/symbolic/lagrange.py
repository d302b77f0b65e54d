"""Lagrange's equations with multipliers and Hamilton's canonical equations with multipliers (docs/theory.md §11).

For a Lagrangian L(t, q, q̇), generalized forces Q and Pfaffian constraints A(t, q) q̇ = b(t, q)
(Orsino (2020) slides 16–26):

* Lagrange, K(7):   d/dt ∂L/∂q̇ − ∂L/∂q = Q + Aᵀλ,   A q̇ = b;
* Hamilton, K(23)–(26):   q̇ = ∂H/∂p,   ṗ = −∂H/∂q + Q + Aᵀλ,   A ∂H/∂p = b,
  p = ∂L/∂q̇, H = pᵀq̇ − L.

Both are DAE (index 2 for velocity constraints, 3 if A = ∂h/∂q of a holonomic h written at
position level). **Index reduction**: the constraint is differentiated once,
A q̈ + Ȧ q̇ − ḃ = −α (A q̇ − b), with Baumgarte stabilisation of the velocity-level drift
(α = 0 switches it off), and solved for λ with q̈ = M⁻¹(∂L/∂q + Q − w + Aᵀλ), where
M = ∂²L/∂q̇², w = d/dt(∂L/∂q̇) − M q̈. The Hamilton form integrates (q, p) with
q̇ = M⁻¹(p − ∂L/∂q̇|_{q̇=0}) (L quadratic in q̇) and the same λ; both are index-1 ODE.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Mapping, Sequence

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
from sympy.core.function import AppliedUndef

from .program import check_declared, replace_derivatives

__all__ = ["MultiplierSystem", "multiplier_system"]


@dataclass(frozen=True)
class MultiplierSystem:
    """L(t, q, q̇), Q and A q̇ = b, with the lecture's multiplier and canonical equations.

    Attributes: ``L``, ``q`` (functions of ``t``), ``Q``, ``A`` (c × n), ``b`` (c), ``parameters``;
    ``q_symbols``, ``p``, ``lam``: plain symbols for the coordinates, momenta and multipliers.
    """

    L: sp.Expr
    q: tuple
    t: sp.Symbol
    Q: sp.Matrix
    A: sp.Matrix
    b: sp.Matrix
    parameters: Mapping = field(default_factory=dict, repr=False)

    @cached_property
    def q_symbols(self) -> tuple:
        return tuple(sp.Symbol(qi.func.__name__) for qi in self.q)

    @cached_property
    def p(self) -> tuple:
        return tuple(sp.Symbol(f"p_{qi.func.__name__}") for qi in self.q)

    @cached_property
    def lam(self) -> tuple:
        return tuple(sp.Symbol(f"lambda_{i + 1}") for i in range(self.A.rows))

    @cached_property
    def _plain(self):
        """(q, q̇) as plain symbols and L, ∂L/∂q̇, Q, A, b in them."""
        u = tuple(sp.Symbol(f"{qi.func.__name__}_dot") for qi in self.q)
        names = [self.q_symbols, u]
        L = replace_derivatives(self.L, self.q, self.t, names)
        Q = replace_derivatives(self.Q, self.q, self.t, names)
        A, b = (replace_derivatives(X, self.q, self.t, names) for X in (self.A, self.b))
        return u, L, sp.Matrix([L]).jacobian(u).T, Q, A, b

    def lagrange_equations(self) -> sp.Matrix:
        """Left-hand sides of K(7): d/dt ∂L/∂q̇ − ∂L/∂q − Q − Aᵀλ = 0 (in q(t), with λ = ``lam``)."""
        q_dot = [qi.diff(self.t) for qi in self.q]
        dL_dq_dot = sp.Matrix([sp.diff(self.L, v) for v in q_dot])
        dL_dq = sp.Matrix([sp.diff(self.L, qi) for qi in self.q])
        return dL_dq_dot.diff(self.t) - dL_dq - self.Q - self.A.T * sp.Matrix(self.lam)

    def hamiltonian(self) -> sp.Expr:
        """H(t, q, p) = pᵀq̇ − L, K(26), with q̇ solved from p = ∂L/∂q̇, K(25) (L quadratic in q̇)."""
        u, L, p_of_u, *_ = self._plain
        M = p_of_u.jacobian(u)
        if M.has(*u):
            raise ValueError("L: not quadratic in the velocities, so p = ∂L/∂q̇ cannot be solved "
                             "linearly for q̇")
        u_of_p = M.LUsolve(sp.Matrix(self.p) - p_of_u.subs({v: 0 for v in u}))
        on_p = dict(zip(u, u_of_p))
        return sp.Matrix(self.p).dot(u_of_p) - L.subs(on_p)

    def canonical_equations(self) -> tuple[sp.Matrix, sp.Matrix]:
        """(q̇, ṗ) of K(23)–(24): q̇ = ∂H/∂p, ṗ = −∂H/∂q + Q + Aᵀλ, in ``q_symbols``, ``p``, ``lam``."""
        H = self.hamiltonian()
        u, *_, Q, A, _ = self._plain
        q_dot = sp.Matrix([sp.diff(H, pi) for pi in self.p])
        Q_p = Q.subs(dict(zip(u, q_dot)))
        p_dot = sp.Matrix([-sp.diff(H, qi) for qi in self.q_symbols]) + Q_p + A.T * sp.Matrix(self.lam)
        return q_dot, p_dot

    @cached_property
    def _compiled(self):
        """Numeric M, ∂L/∂q̇|₀, ∂L/∂q + Q, w, A, b, Ȧq̇ − ḃ at (t, q, q̇), lambdified with cse."""
        u, L, p_of_u, Q, A, b = self._plain
        q, t = self.q_symbols, self.t
        M = p_of_u.jacobian(u)
        w = p_of_u.jacobian(q) * sp.Matrix(u) + p_of_u.diff(t)
        residual = A * sp.Matrix(u) - b
        gamma = residual.jacobian(q) * sp.Matrix(u) + residual.diff(t)
        pieces = [M, p_of_u.subs({v: 0 for v in u}), sp.Matrix([L]).jacobian(q).T + Q, w, A, b, gamma]
        numbers = {k: sp.sympify(v) for k, v in self.parameters.items()}  # xreplace: subs takes seconds here
        return sp.lambdify([t, q, u], [X.xreplace(numbers) for X in pieces], modules="numpy", cse=True)

    def _evaluate(self, t, q, u, alpha):
        """(M, ∂L/∂q̇|₀, ∂L/∂q + Q, Aᵀλ, q̈) with λ from A q̈ + Ȧq̇ − ḃ = −α (A q̇ − b)."""
        M, p0, force, w, A, b, gamma = (np.atleast_1d(np.asarray(X, dtype=float))
                                        for X in self._compiled(t, q, u))
        A = A.reshape(len(self.lam), len(q))
        M_inv_f, M_inv_At = np.linalg.solve(M, force.ravel() - w.ravel()), np.linalg.solve(M, A.T)
        lam = np.linalg.solve(A @ M_inv_At, -A @ M_inv_f - gamma.ravel() - alpha * (A @ u - b.ravel()))
        return M, p0.ravel(), force.ravel(), A.T @ lam, M_inv_f + M_inv_At @ lam

    def velocity_residual(self, t: float, q, q_dot) -> np.ndarray:
        """A q̇ − b at a state (the drift of the velocity constraint)."""
        _, _, _, _, A, b, _ = self._compiled(t, np.asarray(q, float), np.asarray(q_dot, float))
        return np.asarray(A, dtype=float).reshape(len(self.lam), -1) @ q_dot - np.asarray(b, float).ravel()

    def momenta(self, t: float, q, q_dot) -> np.ndarray:
        """p = ∂L/∂q̇ = M q̇ + ∂L/∂q̇|_{q̇=0}, K(25)."""
        M, p0, *_ = self._evaluate(t, np.asarray(q, float), np.asarray(q_dot, float), 0.0)
        return M @ q_dot + p0

    def simulate(self, q0, q_dot0, t_span, form: str = "lagrange", alpha: float = 0.0, t_eval=None,
                 rtol: float = 1e-10, atol: float = 1e-12):
        """Integrate the index-reduced DAE (DOP853). ``form`` "lagrange": state (q, q̇);
        "hamilton": state (q, p), p₀ from q̇₀ by K(25). ``alpha``: Baumgarte rate (1/s).

        Returns the solve_ivp result with ``q``, ``q_dot`` (n × len(t)) added.
        """
        n = len(self.q)
        q0, q_dot0 = (np.asarray(v, dtype=float).ravel() for v in (q0, q_dot0))
        if q0.size != n or q_dot0.size != n:
            raise ValueError(f"q0, q_dot0: expected {n} values each, got {q0.size} and {q_dot0.size}")
        if form not in ("lagrange", "hamilton"):
            raise ValueError(f"form: expected 'lagrange' or 'hamilton', got {form!r}")

        def lagrange(t, x):
            return np.concatenate([x[n:], self._evaluate(t, x[:n], x[n:], alpha)[-1]])

        def hamilton(t, x):
            q_dot = self._velocities(t, x[:n], x[n:])
            _, _, force, constraint_force, _ = self._evaluate(t, x[:n], q_dot, alpha)
            return np.concatenate([q_dot, force + constraint_force])  # ṗ = ∂L/∂q + Q + Aᵀλ = −∂H/∂q + Q + Aᵀλ

        x0 = np.concatenate([q0, q_dot0 if form == "lagrange" else self.momenta(t_span[0], q0, q_dot0)])
        sol = solve_ivp(lagrange if form == "lagrange" else hamilton, t_span, x0, method="DOP853",
                        t_eval=t_eval, rtol=rtol, atol=atol)
        sol.q = sol.y[:n]
        sol.q_dot = sol.y[n:] if form == "lagrange" else np.array(
            [self._velocities(ti, xi[:n], xi[n:]) for ti, xi in zip(sol.t, sol.y.T)]).T
        return sol

    def hamilton_dae(self, phi=None):
        """Hamilton's canonical equations with multipliers as a semi-explicit DAE in y = (q, p, λ),
        K(23)–(26) and Barhorst's eq. 7 with 3, *not* index-reduced:

            q̇ = ∂H/∂p,   ṗ = −∂H/∂q + Q + Aᵀλ,   0 = A ∂H/∂p − b   (index 2)

        or, with ``phi`` (position constraints Φ(q(t)) = 0 whose Jacobian is A, b = 0), 0 = Φ(q)
        (index 3). ∂H/∂p = M⁻¹(p − ∂L/∂q̇|_{q̇=0}) and −∂H/∂q = ∂L/∂q at q̇ = ∂H/∂p (Legendre
        duality) are evaluated numerically, so H is never inverted symbolically.

        Returns (f, mass, index): f(t, y) for M y′ = f, the diagonal of M, each component's index,
        for :func:`projeq.simulation.integrators.radau_dae`.
        """
        n, c = len(self.q), len(self.lam)
        position = None
        if phi is not None:
            phi = sp.Matrix(phi)
            if phi.shape != (c, 1):
                raise ValueError(f"phi: expected {c} position constraints (one per row of A), got {phi.shape}")
            check_declared(list(phi), self.q, self.t, self.parameters, "phi")
            plain = replace_derivatives(phi, self.q, self.t, [self.q_symbols]).subs(self.parameters)
            position = sp.lambdify([self.t, self.q_symbols], plain, modules="numpy")

        def f(t, y):
            q, p, lam = y[:n], y[n:2 * n], y[2 * n:]
            q_dot = self._velocities(t, q, p)
            _, _, force, _, A, b, _ = self._compiled(t, q, q_dot)
            A = np.asarray(A, dtype=float).reshape(c, n)
            residual = (np.asarray(position(t, q), float).ravel() if position is not None
                        else A @ q_dot - np.asarray(b, float).ravel())
            return np.concatenate([q_dot, np.asarray(force, float).ravel() + A.T @ lam, residual])

        mass = np.r_[np.ones(2 * n), np.zeros(c)]
        index = np.r_[np.ones(n), np.full(n, 1 if phi is None else 2), np.full(c, 2 if phi is None else 3)]
        return f, mass, index

    def simulate_dae(self, q0, q_dot0, t_span, phi=None, t_eval=None, rtol: float = 1e-8, atol: float = 1e-10):
        """Integrate :meth:`hamilton_dae` by Radau IIA (:func:`projeq.simulation.integrators.radau_dae`) from a
        consistent state: p₀ = ∂L/∂q̇ at (q0, q̇0), λ₀ from the constraint differentiated once (only
        the start value: the integration keeps the DAE as it stands). Returns the
        :class:`~projeq.simulation.integrators.DAEResult` with ``q``, ``p``, ``lam`` and ``q_dot`` added."""
        from projeq.simulation.integrators import radau_dae

        n = len(self.q)
        y0 = self.dae_start(t_span[0], q0, q_dot0)
        f, mass, index = self.hamilton_dae(phi)
        sol = radau_dae(f, t_span, y0, mass=mass, index=index, rtol=rtol, atol=atol, t_eval=t_eval)
        sol.q, sol.p, sol.lam = sol.y[:n], sol.y[n:2 * n], sol.y[2 * n:]
        sol.q_dot = np.array([self._velocities(ti, qi, pi) for ti, qi, pi in zip(sol.t, sol.q.T, sol.p.T)]).T
        return sol

    def dae_start(self, t0: float, q0, q_dot0) -> np.ndarray:
        """The consistent initial state y₀ = (q₀, p₀, λ₀) of :meth:`hamilton_dae`: p₀ = ∂L/∂q̇ at (q₀, q̇₀),
        λ₀ from the constraint differentiated once (Aᵀλ₀ the constraint force of the index-1 form)."""
        n = len(self.q)
        q0, q_dot0 = (np.asarray(v, dtype=float).ravel() for v in (q0, q_dot0))
        if q0.size != n or q_dot0.size != n:
            raise ValueError(f"q0, q_dot0: expected {n} values each, got {q0.size} and {q_dot0.size}")
        _, _, _, constraint_force, _ = self._evaluate(t0, q0, q_dot0, 0.0)
        _, _, _, _, A, _, _ = self._compiled(t0, q0, q_dot0)
        lam0 = np.linalg.lstsq(np.asarray(A, float).reshape(-1, n).T, constraint_force, rcond=None)[0]
        return np.concatenate([q0, self.momenta(t0, q0, q_dot0), lam0])

    def _velocities(self, t, q, p):
        """q̇ = M⁻¹(p − ∂L/∂q̇|_{q̇=0}) = ∂H/∂p, K(23), numerically (M does not depend on q̇)."""
        M, p0, *_ = self._evaluate(t, q, np.zeros_like(q), 0.0)
        return np.linalg.solve(M, p - p0)


def multiplier_system(L, q: Sequence, t: sp.Symbol, A=None, b=None, Q=None,
                      parameters: Mapping | None = None) -> MultiplierSystem:
    """Lagrangian system with Pfaffian constraints A(t, q) q̇ = b(t, q) (Orsino (2020) K(1)).

    Parameters
    ----------
    L : Lagrangian in q(t), q̇(t), t.  q : coordinates, functions of ``t``.
    A : c × n matrix, b : c-vector (default b = 0); Q : n generalized forces (default 0).
    parameters : ``{symbol: value}`` for every other symbol.

    Examples
    --------
    >>> from sympy.physics.mechanics import dynamicsymbols
    >>> t = sp.Symbol("t"); x, y = dynamicsymbols("x y")
    >>> system = multiplier_system((x.diff(t)**2 + y.diff(t)**2) / 2 - 10 * y, [x, y], t, A=[[-y**2, 1]])
    >>> sp.expand(system.hamiltonian())
    p_x**2/2 + p_y**2/2 + 10*y
    """
    q = tuple(q)
    if not q or not all(isinstance(qi, AppliedUndef) and qi.args == (t,) for qi in q):
        raise ValueError(f"q: expected functions of {t} such as dynamicsymbols('x'), got {list(q)}")
    n = len(q)
    A = sp.Matrix(A) if A is not None else sp.zeros(0, n)
    if A.cols != n or A.rows >= n:
        raise ValueError(f"A: expected a c × {n} matrix with c < {n} (one column per coordinate), "
                         f"got {A.shape}")
    b = sp.Matrix(b) if b is not None else sp.zeros(A.rows, 1)
    Q = sp.Matrix(Q) if Q is not None else sp.zeros(n, 1)
    if b.shape != (A.rows, 1):
        raise ValueError(f"b: expected {A.rows} values (one per row of A), got shape {b.shape}")
    if Q.shape != (n, 1):
        raise ValueError(f"Q: expected {n} generalized forces (one per coordinate), got shape {Q.shape}")
    parameters = dict(parameters or {})
    check_declared([L, *Q], q, t, parameters, "L, Q")
    check_declared([*A, *b], q, t, parameters, "A, b")
    return MultiplierSystem(sp.sympify(L), q, t, Q, A, b, parameters)

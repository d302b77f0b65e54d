"""Barhorst's two canonical momentum forms: ODEs in (q, p) without multipliers (THEORY §11).

``seeds/000_…`` (Barhorst): with independent speeds u and q̇ = K(q) u (dependent speeds already
eliminated, Barhorst's (K_ki + K_kd A_di)),

* **projective** form, eqs. 28–37: p = Σ_j (L_j · V_j + H_j · W_j) with the partial velocities
  V_j = ∂v_j/∂u, W_j = ∂ω_j/∂u ("vectors of constraint concordance", (29)–(30)), and
  ṗ = Q + P, P = Σ_j (L_j · dV_j/dt + H_j · dW_j/dt) (32)–(34), q̇ = K B p (36)–(37);
* **Lagrangian** form, eqs. 45–52: p = Kᵀ ∂L/∂q̇ (45), ṗ = Kᵀ(∂L/∂q + Q) + K̇ᵀ ∂L/∂q̇ (51)–(52).

Both momenta equal ∂T/∂u, but ṗ is built differently. B = (∂p/∂u)⁻¹ is applied numerically
(u = B (p − p|_{u=0})), never inverted symbolically; Barhorst's R_i(q, p) is P evaluated at u(p).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Mapping, Sequence

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from .lagrange import MultiplierSystem
from .program import check_declared, choose_dependent
from .projection import Body

__all__ = ["CanonicalForm", "lagrangian_canonical", "projective_canonical"]


@dataclass(frozen=True)
class CanonicalForm:
    """ṗ = Q + R(q, p), q̇ = K u(p) in plain symbols ``q``, ``u`` (``p`` is linear in ``u``)."""

    q: tuple
    u: tuple
    t: sp.Symbol
    K: sp.Matrix
    p: sp.Matrix
    p_dot: sp.Matrix
    parameters: Mapping = field(default_factory=dict, repr=False)

    @cached_property
    def _compiled(self):
        """∂p/∂u, p|_{u=0}, K, ṗ at (t, q, u), lambdified with common subexpressions."""
        u = sp.Matrix(self.u)
        pieces = [self.p.jacobian(u), self.p.subs({ui: 0 for ui in u}), self.K, self.p_dot]
        return sp.lambdify([self.t, self.q, self.u], [X.subs(self.parameters) for X in pieces],
                           modules="numpy", cse=True)

    def _speeds(self, t, q, p):
        """u = B (p − p|_{u=0}), B = (∂p/∂u)⁻¹ numerically (Barhorst (31), (47))."""
        dp_du, p0, *_ = self._compiled(t, q, np.zeros(len(self.u)))
        return np.linalg.solve(np.asarray(dp_du, float), p - np.asarray(p0, float).ravel())

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """d(q, p)/dt = (K u, ṗ) with u = u(q, p)."""
        n = len(self.q)
        u = self._speeds(t, x[:n], x[n:])
        _, _, K, p_dot = self._compiled(t, x[:n], u)
        return np.concatenate([np.asarray(K, float) @ u, np.asarray(p_dot, float).ravel()])

    def momenta(self, t: float, q, u) -> np.ndarray:
        """p(q, u) at a state."""
        dp_du, p0, *_ = self._compiled(t, q, u)
        return np.asarray(dp_du, float) @ u + np.asarray(p0, float).ravel()

    def simulate(self, q0, u0, t_span, t_eval=None, rtol: float = 1e-10, atol: float = 1e-12):
        """Integrate (q, p) from q0 and the independent speeds u0 (DOP853); adds ``q``, ``u``."""
        n, k = len(self.q), len(self.u)
        q0, u0 = (np.asarray(v, dtype=float).ravel() for v in (q0, u0))
        if q0.size != n or u0.size != k:
            raise ValueError(f"q0, u0: expected {n} coordinates and {k} speeds, got {q0.size} and {u0.size}")
        x0 = np.concatenate([q0, self.momenta(t_span[0], q0, u0)])
        sol = solve_ivp(self.rhs, t_span, x0, method="DOP853", t_eval=t_eval, rtol=rtol, atol=atol)
        sol.q = sol.y[:n]
        sol.u = np.array([self._speeds(ti, xi[:n], xi[n:]) for ti, xi in zip(sol.t, sol.y.T)]).T
        return sol


def _rate(X: sp.Matrix, q: Sequence, q_dot: sp.Matrix, t: sp.Symbol) -> sp.Matrix:
    """dX/dt = Σ ∂X/∂q_j q̇_j + ∂X/∂t for X(q, t)."""
    return sum((X.diff(qj) * qd for qj, qd in zip(q, q_dot)), X.diff(t))


def lagrangian_canonical(system: MultiplierSystem, independent: Sequence | None = None) -> CanonicalForm:
    """Barhorst's Lagrangian canonical form (eqs. 45–52) of a :class:`MultiplierSystem` with A q̇ = 0.

    The speeds u are the independent q̇_λ (``independent``: their coordinates; default chosen
    from A), q̇ = K u with K from A (dependent rows −A_ρ⁻¹ A_λ, Barhorst's A_di).
    """
    u_all, L, dL_dq_dot, Q, A, b = system._plain
    if b != sp.zeros(*b.shape):
        raise ValueError("b: the canonical forms need homogeneous constraints A q̇ = 0")
    q, n = system.q_symbols, len(system.q)
    dependent = None if independent is None else [qi for qi in system.q if qi not in independent]
    rho = choose_dependent(A, system.q, dependent)
    lam = [j for j in range(n) if j not in rho]
    u = tuple(u_all[j] for j in lam)
    K_rho = -A[:, rho].LUsolve(A[:, lam])
    K = sp.Matrix([sp.eye(len(lam))[lam.index(j), :] if j in lam else K_rho[rho.index(j), :]
                   for j in range(n)])
    on_u = dict(zip(u_all, K * sp.Matrix(u)))
    dL_dq_dot = dL_dq_dot.subs(on_u)
    force = (sp.Matrix([L]).jacobian(q).T + Q).subs(on_u)
    p = K.T * dL_dq_dot
    p_dot = K.T * force + _rate(K, q, K * sp.Matrix(u), system.t).T * dL_dq_dot
    return CanonicalForm(q, u, system.t, K, p, p_dot, system.parameters)


def projective_canonical(bodies: Sequence[Body], q: Sequence, u: Sequence, K, t: sp.Symbol,
                         parameters: Mapping | None = None) -> CanonicalForm:
    """Barhorst's projective canonical form (eqs. 28–37) from body velocities in q, u (plain symbols).

    ``bodies``: :class:`projeq.symbolic.projection.Body` (v_c, ω, f, M in the coordinates of a frame R
    turning with ω_IR, as in B(10)); ``K``: q̇ = K(q) u. v_c and ω must be linear in u; their partial
    velocities V = ∂v_c/∂u, W = ∂ω/∂u are Barhorst's vectors of constraint concordance (29)–(30)
    (Bremer's F_n). With momenta L = m v_c, H = I_c ω: p = Σ (Vᵀ L + Wᵀ H) (28), and
    P = Σ (V̇ + ω̃_IR V)ᵀ L + (Ẇ + ω̃_IR W)ᵀ H (34), the rates of V, W seen from inertial space.
    """
    q, u, K = tuple(q), tuple(u), sp.Matrix(K)
    if K.shape != (len(q), len(u)):
        raise ValueError(f"K: expected a {len(q)} × {len(u)} matrix (q̇ = K u), got {K.shape}")
    declared = {**(parameters or {}), **{s: 0 for s in q + u}}
    check_declared(list(K), (), t, declared, "K")
    q_dot, us = K * sp.Matrix(u), sp.Matrix(u)
    p, P, Q = sp.zeros(len(u), 1), sp.zeros(len(u), 1), sp.zeros(len(u), 1)
    for i, body in enumerate(bodies):
        b = body.vectors(f"bodies[{i}]")
        check_declared([*b["v_c"], *b["omega"], *b["f"], *b["M"], *b["omega_IR"], *b["I_c"], b["m"]], (), t,
                       declared, "bodies")
        V, W = b["v_c"].jacobian(us), b["omega"].jacobian(us)
        L_mom, H_mom = b["m"] * b["v_c"], b["I_c"] * b["omega"]
        p += V.T * L_mom + W.T * H_mom
        # X · (ω_IR × V_k) = V_k · (X × ω_IR): the frame's rotation of V, W seen from inertial space
        P += (_rate(V, q, q_dot, t).T * L_mom + V.T * L_mom.cross(b["omega_IR"])
              + _rate(W, q, q_dot, t).T * H_mom + W.T * H_mom.cross(b["omega_IR"]))
        Q += V.T * b["f"] + W.T * b["M"]
    return CanonicalForm(q, u, t, K, p, Q + P, dict(parameters or {}))

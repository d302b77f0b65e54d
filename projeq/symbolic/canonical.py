"""Barhorst's two canonical momentum forms: ODEs in (q, p) without multipliers (docs/theory.md §11).

A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems — another perspective on the
canonical equations of motion": with independent speeds u and q̇ = K(q) u + J(q, t) (dependent speeds
already eliminated, Barhorst's (K_ki + K_kd A_di) of eqs. 8–11 for general speeds u = Y q̇ + Z),

* **projective** form, eqs. 28–37: p = Σ_j (L_j · V_j + H_j · W_j) with the partial velocities
  V_j = ∂v_j/∂u, W_j = ∂ω_j/∂u ("vectors of constraint concordance", (29)–(30)), and
  ṗ = Q + P, P = Σ_j (L_j · dV_j/dt + H_j · dW_j/dt) (32)–(34), q̇ = K B p (36)–(37);
* **Lagrangian** form, eqs. 45–52: p = Kᵀ ∂L/∂q̇ (45), ṗ = Kᵀ(∂L/∂q + Q) + K̇ᵀ ∂L/∂q̇ (51)–(52),
  q̇ = K u(p) + J (47)–(49).

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
from sympy.matrices.utilities import dotprodsimp

from .lagrange import MultiplierSystem
from .program import check_declared, choose_dependent, replace_derivatives
from .projection import Body

__all__ = ["CanonicalForm", "energy_rate", "lagrangian_canonical", "projective_canonical"]


@dataclass(frozen=True)
class CanonicalForm:
    """ṗ = Q + R(q, p), q̇ = K u(p) + J in plain symbols ``q``, ``u`` (``p`` is linear in ``u``;
    J = 0 unless the speeds u = Y q̇ + Z have Z ≠ 0 or the constraints are inhomogeneous)."""

    q: tuple
    u: tuple
    t: sp.Symbol
    K: sp.Matrix
    p: sp.Matrix
    p_dot: sp.Matrix
    parameters: Mapping = field(default_factory=dict, repr=False)
    J: sp.Matrix | None = None

    @cached_property
    def _compiled(self):
        """∂p/∂u, p|_{u=0}, K, ṗ, J at (t, q, u), lambdified with common subexpressions."""
        u = sp.Matrix(self.u)
        J = sp.zeros(len(self.q), 1) if self.J is None else self.J
        pieces = [self.p.jacobian(u), self.p.subs({ui: 0 for ui in u}), self.K, self.p_dot, J]
        numbers = {k: sp.sympify(v) for k, v in self.parameters.items()}  # xreplace: subs takes seconds here
        return sp.lambdify([self.t, self.q, self.u], [X.xreplace(numbers) for X in pieces],
                           modules="numpy", cse=True)

    def _speeds(self, t, q, p):
        """u = B (p − p|_{u=0}), B = (∂p/∂u)⁻¹ numerically (Barhorst (31), (47))."""
        dp_du, p0, *_ = self._compiled(t, q, np.zeros(len(self.u)))
        return np.linalg.solve(np.asarray(dp_du, float), p - np.asarray(p0, float).ravel())

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """d(q, p)/dt = (K u + J, ṗ) with u = u(q, p)."""
        n = len(self.q)
        u = self._speeds(t, x[:n], x[n:])
        _, _, K, p_dot, J = self._compiled(t, x[:n], u)
        return np.concatenate([np.asarray(K, float) @ u + np.asarray(J, float).ravel(),
                               np.asarray(p_dot, float).ravel()])

    def q_dot(self, t: float, q, u) -> np.ndarray:
        """q̇ = K u + J at a state."""
        _, _, K, _, J = self._compiled(t, np.asarray(q, float), np.asarray(u, float))
        return np.asarray(K, float) @ np.asarray(u, float) + np.asarray(J, float).ravel()

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


def lagrangian_canonical(system: MultiplierSystem, independent: Sequence | None = None,
                         speeds: Sequence | None = None) -> CanonicalForm:
    """Barhorst's Lagrangian canonical form (eqs. 45–52) of a :class:`MultiplierSystem` with A q̇ = b.

    ``speeds``: Barhorst's general speeds u = Y(q) q̇ + Z(q, t) (his eq. 8; e.g. eq. 93, the rolling
    disk's body-fixed angular velocity), N expressions in the system's q(t), q̇(t), t, linear in q̇
    with Y invertible; default u = q̇. Then q̇ = K u + J with K = Y⁻¹, J = −K Z (eq. 9), the
    constraints read a u + a₀ = 0 with a = A K, a₀ = A J − b (eq. 10), and the dependent speeds
    u_D = A_DI u_I + c (eq. 11) leave q̇ = K̄ u_I + J̄, K̄ = K_I + K_D A_DI (Barhorst's
    K_ki + K_kd A_di). ``independent``: the independent speeds, as positions in ``speeds`` (ints)
    or, for u = q̇, as coordinates; default chosen from the constraints. The returned form's ``u``
    are the independent speeds (``<q>_dot`` for u = q̇, else ``u1``, ``u2``, … by position).
    """
    q_dot, L, dL_dq_dot, Q, A, b = system._plain
    q, n = system.q_symbols, len(system.q)
    if speeds is None:
        u_all, K, J = q_dot, sp.eye(n), sp.zeros(n, 1)
    else:
        u_all, K, J = _general_speeds(system, speeds)
    a, a0 = A * K, A * J - b
    dependent = _dependent_speeds(system, u_all, independent, speeds is None)
    rho = choose_dependent(a, u_all, dependent)
    lam = [j for j in range(n) if j not in rho]
    u = tuple(u_all[j] for j in lam)
    A_DI, c = -a[:, rho].LUsolve(a[:, lam]), -a[:, rho].LUsolve(a0)
    P = sp.Matrix([sp.eye(len(lam))[lam.index(j), :] if j in lam else A_DI[rho.index(j), :] for j in range(n)])
    offset = sp.Matrix([0 if j in lam else c[rho.index(j)] for j in range(n)])
    K_bar = (K * P).applyfunc(sp.trigsimp)
    J_bar = (K * offset + J).applyfunc(sp.trigsimp)
    q_dot_of_u = K_bar * sp.Matrix(u) + J_bar
    on_u = dict(zip(q_dot, q_dot_of_u))
    dL_dq_dot = dL_dq_dot.subs(on_u)
    force = (sp.Matrix([L]).jacobian(q).T + Q).subs(on_u)
    p = K_bar.T * dL_dq_dot
    p_dot = K_bar.T * force + _rate(K_bar, q, q_dot_of_u, system.t).T * dL_dq_dot
    return CanonicalForm(q, u, system.t, K_bar, p, p_dot, system.parameters, J_bar)


def _general_speeds(system: MultiplierSystem, speeds: Sequence):
    """(u symbols, K = Y⁻¹, J = −K Z) of u = Y q̇ + Z (Barhorst eqs. 8–9) in the plain symbols."""
    q_dot = system._plain[0]
    n = len(q_dot)
    speeds = sp.Matrix(list(speeds))
    if speeds.shape != (n, 1):
        raise ValueError(f"speeds: expected {n} expressions u = Y q̇ + Z (one per coordinate), got {speeds.rows}")
    check_declared(list(speeds), system.q, system.t, system.parameters, "speeds")
    plain = replace_derivatives(speeds, system.q, system.t, [system.q_symbols, q_dot])
    Y = plain.jacobian(q_dot)
    if Y.has(*q_dot):
        raise ValueError("speeds: must be linear in the velocities, u = Y(q) q̇ + Z(q, t)")
    Z = (plain - Y * sp.Matrix(q_dot)).applyfunc(sp.expand)
    if Y.det().simplify() == 0:
        raise ValueError("speeds: Y = ∂u/∂q̇ is singular; the speeds must determine q̇ (Barhorst eq. 9)")
    K = Y.inv().applyfunc(sp.trigsimp)
    return tuple(sp.symbols(f"u1:{n + 1}")), K, -K * Z


def _dependent_speeds(system: MultiplierSystem, u_all, independent, default_speeds: bool):
    """The dependent speeds (symbols in ``u_all``) for ``independent`` (None: chosen later)."""
    if independent is None:
        return None
    chosen = []
    for item in independent:
        if isinstance(item, (int, np.integer)) and 0 <= item < len(u_all):
            chosen.append(int(item))
        elif default_speeds and item in system.q:
            chosen.append(system.q.index(item))
        else:
            raise ValueError(f"independent: expected positions 0…{len(u_all) - 1} of the speeds"
                             f"{' or coordinates q' if default_speeds else ''}, got {item!r}")
    return [u_all[j] for j in range(len(u_all)) if j not in chosen]


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


def energy_rate(form: CanonicalForm, E) -> sp.Expr:
    """Barhorst's energy-conservation condition, eq. 38 (eq. 55 for the Lagrangian form):

        dE/dt = ∂E/∂p|_q (Q + R) + ∂E/∂q|_p q̇,   q̇ = K u(p) + J,

    for an energy ``E`` given in the form's (q, u) (plain symbols). With D = ∂p/∂u (p is linear in u):
    ∂E/∂p|_q = ∂E/∂u D⁻¹ and ∂E/∂q|_p = ∂E/∂q|_u − ∂E/∂u D⁻¹ ∂p/∂q|_u (E(q, p) = E(q, u(q, p))).
    Returns the rate as an expression in (q, u, t) — "if it is identically zero then energy is
    conserved for the system as formulated" (Barhorst §2.1.1); D⁻¹ is the symbolic adjugate over the
    determinant (one speed: 1/D).
    """
    E = sp.sympify(E)
    q, u = sp.Matrix(form.q), sp.Matrix(form.u)
    D = form.p.jacobian(u)
    with dotprodsimp(False):  # sympy's intermediate simplification makes the 3 × 3 adjugate take minutes
        D_inv = D.adjugate() / D.det() if D.rows > 1 else sp.Matrix([[1 / D[0, 0]]])
    dE_du = sp.Matrix([E]).jacobian(u)
    dE_dp = dE_du * D_inv
    dE_dq = sp.Matrix([E]).jacobian(q) - dE_dp * form.p.jacobian(q)
    J = sp.zeros(len(form.q), 1) if form.J is None else form.J
    q_dot = form.K * u + J
    return (dE_dp * form.p_dot + dE_dq * q_dot)[0, 0]

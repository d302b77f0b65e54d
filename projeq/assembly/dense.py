"""The dense Gauss form M(q) s̈ + b(q, ṡ, t) = 0 (docs/theory.md §5; B(14)–(15)).

The functional matrix J_n = ∂ẏ_n/∂ṡ = T_np J_p + F_n P_n and ζ̄_n = J̇_n ṡ = T_np ζ̄_p + ζ_n
are built root to leaves; then

    M = Σ J_nᵀ M_n J_n,   b = Σ J_nᵀ (M_n ζ̄_n − h_n).

O(N²) to build, O(N³) to solve: the reference for the recursive evaluator, and the path
for shared minimal velocities (coupled joints), where P_n picks several columns.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.assembly.linalg import column_scales, solve_spd, warn_if_ill_conditioned
from projeq.assembly.kinematics import forward, gauss_terms
from projeq.checks import kernel_state


class DenseEvaluator:
    """Gauss form and accelerations of one System (its workspace: ``P``, the joints'
    columns of ∂ẏ/∂ṡ). Counts calls in ``n_calls``."""

    def __init__(self, system):
        self.system = system
        self.P = [system.joint_s_columns(n) for n in range(len(system.joints))]
        self.scale = column_scales(system)  # each pivot's yardstick, the mass its velocity moves
        self.n_calls, self.conditioned = 0, False

    def gauss_form(self, q: NDArray, s_dot: NDArray, t: float) -> tuple[NDArray, NDArray]:
        """M(q) and b(q, ṡ, t) with M s̈ + b = 0."""
        self.n_calls += 1
        system = self.system
        q, s_dot = kernel_state("q", q, system.n_q), kernel_state("s_dot", s_dot, system.n_s)
        kin = forward(system, q, s_dot, t)
        M_n, h_n = gauss_terms(system, kin, q, s_dot, t)
        J = [None] * len(system.joints) + [np.zeros((0, system.n_s))]
        zeta_bar = [None] * len(system.joints) + [np.zeros(0)]
        dtype = np.result_type(*kin.T_aug, *kin.F, *M_n, *h_n)  # complex for a complex step
        M = np.zeros((system.n_s, system.n_s), dtype=dtype)
        b = np.zeros(system.n_s, dtype=dtype)
        for n in range(len(system.joints)):
            p = system.parent[n]
            cols, P = self.P[n]
            T, zeta = kin.T_aug[n][:-1, :-1], kin.T_aug[n][:-1, -1]
            J[n] = T @ J[p]  # J_n = T_np J_p + F_n P_n
            J[n][:, cols] += kin.F[n] @ P
            zeta_bar[n] = T @ zeta_bar[p] + zeta  # ζ̄_n = T_np ζ̄_p + ζ_n
            MJ = M_n[n] @ J[n]
            M += J[n].T @ MJ
            b += J[n].T @ (M_n[n] @ zeta_bar[n] - h_n[n])
        return M, b

    def accelerations(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        """s̈ = −M⁻¹ b; the first call warns when M is too ill-conditioned for it (see
        :func:`projeq.assembly.linalg.warn_if_ill_conditioned`)."""
        M, b = self.gauss_form(q, s_dot, t)
        if not self.conditioned:  # once per evaluator
            self.conditioned = True
            warn_if_ill_conditioned(M, "the dense evaluator's mass matrix M(q)")
        return -solve_spd(M, b[:, None], "system mass matrix M(q)", self.scale)[:, 0]

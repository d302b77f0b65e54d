"""Order-n solution of the Projection Equation: Bremer's Gaussian elimination (docs/theory.md §6).

Backward pass, leaves to root, with h_n = Q_n − G_n ẏ_n:

    M̂_n = M_n + Σ_c T_cnᵀ M̄_c T_cn,        ĥ_n = h_n + Σ_c T_cnᵀ h̄_c
    D_n = F_nᵀ M̂_n F_n
    M̄_n = M̂_n − M̂_n F_n D_n⁻¹ F_nᵀ M̂_n,   h̄_n = (E − M̂_n F_n D_n⁻¹ F_nᵀ)(ĥ_n − M̂_n ζ_n)

Forward pass, root to leaves (ÿ of the ground = 0):

    s̈_n = D_n⁻¹ F_nᵀ (ĥ_n − M̂_n (T_np ÿ_p + ζ_n)),   ÿ_n = T_np ÿ_p + F_n s̈_n + ζ_n

Both passes are written with the augmented matrices

    Ã_n = [[M̂_n, −ĥ_n], [−ĥ_nᵀ, 0]],   T̃_np = [[T_np, ζ_n], [0, 1]],   F̃_n = [F_n; 0]

for which the two lines of M̄_n and h̄_n are one Schur complement and one congruence,

    Ā_n = Ã_n − Ã_n F̃_n D_n⁻¹ F̃_nᵀ Ã_n = [[M̄_n, ·], [·, ·]] with h̄ in the last column,
    Ã_p += T̃_npᵀ Ā_n T̃_np,

and the forward pass acts on (ÿ_n; 1) = T̃_np (ÿ_p; 1) + F̃_n s̈_n. The last column of
T̃ᵀ Ā T̃ is −T_npᵀ h̄_n with h̄_n exactly as above (docs/theory.md §6 expands this).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.assembly.linalg import mass_scales, solve_spd
from projeq.assembly.kinematics import forward, gauss_terms
from projeq.checks import kernel_state


class RecursiveEvaluator:
    """Accelerations of one tree System in O(N). Counts calls in ``n_calls``.

    Its workspace is one augmented matrix Ã_n per subsystem (and the ground), allocated
    once and overwritten by every call.
    """

    def __init__(self, system):
        if system.coupled:
            raise ValueError(
                "method: 'recursive' needs a tree whose joints own their minimal velocities; "
                "this system has coupled joints (shared ṡ): use method='dense'"
            )
        self.system = system
        self.scale = mass_scales(system)  # each pivot's yardstick, the mass its joint carries
        self._workspaces = {np.dtype(float): _workspace(system, float)}  # and complex, for a complex step
        self.n_calls = 0

    def accelerations(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        """s̈ by the backward and forward passes of docs/theory.md §6."""
        self.n_calls += 1
        system, scale = self.system, self.scale
        q, s_dot = kernel_state("q", q, system.n_q), kernel_state("s_dot", s_dot, system.n_s)
        kin = forward(system, q, s_dot, t)
        M, h = gauss_terms(system, kin, q, s_dot, t)
        dtype = np.result_type(*kin.T_aug, *kin.F, *M, *h)
        if dtype not in self._workspaces:
            self._workspaces[dtype] = _workspace(system, dtype)
        fill_groups, A_hat = self._workspaces[dtype]
        for idx, A in fill_groups:  # Ã_n = [[M_n, −h_n], [−h_nᵀ, 0]], a stack per n_y
            k = A.shape[1] - 1
            # not np.negative(..., out=view): numpy 2.4 mis-reads such strided views when the
            # stack has one member (tests/assembly/test_recursive_vs_dense.py covers both)
            minus_h = np.negative([h[n] for n in idx])
            A[:, :k, :k] = [M[n] for n in idx]
            A[:, :k, k] = minus_h
            A[:, k, :k] = minus_h
            A[:, k, k] = 0.0
        A_hat[-1][0, 0] = 0.0  # the ground's Ã only collects, nothing reads it
        T_aug, F, parent, names = kin.T_aug, kin.F, system.parent, system.names
        N = len(names)
        gain = [None] * N
        for n in range(N - 1, -1, -1):  # backward: leaves → root
            A = A_hat[n]
            AF = A[:, :-1] @ F[n]  # Ã_n F̃_n
            gain[n] = solve_spd(F[n].T @ AF[:-1], AF.T, names[n], scale[n])  # D_n⁻¹ F̃_nᵀ Ã_n
            A -= AF @ gain[n]  # Ā_n
            A_hat[parent[n]] += T_aug[n].T @ A @ T_aug[n]  # Ã_p += T̃ᵀ Ā T̃
        minus_s_ddot = [None] * N
        y_aug = [None] * N + [np.ones(1)]  # (ÿ; 1), ground at rest
        for n in range(N):  # forward: root → leaves
            a = np.asarray(T_aug[n] @ y_aug[parent[n]], dtype=dtype)  # (T_np ÿ_p + ζ_n; 1)
            minus_s_ddot[n] = gain[n] @ a  # −s̈_n = −D_n⁻¹ F_nᵀ (ĥ_n − M̂_n a)
            a[:-1] -= F[n] @ minus_s_ddot[n]  # ÿ_n = a + F_n s̈_n
            y_aug[n] = a
        return -np.concatenate(minus_s_ddot)


def _workspace(system, dtype) -> tuple[list, list]:
    """The augmented matrices Ã_n, stacked by n_y so that one call fills each stack, and
    per-subsystem views into them (the ground's 1×1 Ã last)."""
    by_size: dict = {}
    for n, sub in enumerate(system.subsystems):
        by_size.setdefault(sub.n_y, []).append(n)
    groups, A_hat = [], [None] * len(system.subsystems) + [np.zeros((1, 1), dtype=dtype)]
    for k, idx in by_size.items():
        stack = np.zeros((len(idx), k + 1, k + 1), dtype=dtype)
        groups.append((idx, stack))
        for j, n in enumerate(idx):
            A_hat[n] = stack[j]
    return groups, A_hat

"""One forward pass over the tree: poses, describing velocities and chain terms (THEORY §4).

For each subsystem n with predecessor p and joint frame J (fixed in p):

    A_pn = A_pJ A_Jn,  r_pn = r_pJ + A_pJ r_Jn,  T⁶_np = [[A_np, −A_np r̃_pn], [0, A_np]]
    u = T⁶_np Sₚᵀ ẏ_p            (p's twist carried to n)
    ẏ_n = Sₙ (u + F⁶ ṡ_n + f⁶),  T_np = Sₙ T⁶_np Sₚᵀ,  F_n = Sₙ F⁶
    ζ_n = Sₙ (u × w + Ḟ⁶ ṡ_n + ḟ⁶),  w = F⁶ ṡ_n + f⁶

where u × w is the motion cross product (``spatial.cross_motion``): it is Ṫ_np ẏ_p, since
Ȧ_np = −ω̃_rel A_np and ṙ_pn = A_pn v_rel. The lists have one extra entry at index −1 for
the ground (n_y = 0, at rest in the inertial frame), so ``parent = -1`` needs no branch.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from projeq.spatial import chain_matrix, cross_motion


@dataclass
class Kinematics:
    """Per-subsystem kinematic state; index −1 is the ground.

    ``T_aug[n]`` is T̃_np = [[T_np, ζ_n], [0, 1]], the affine map (ÿ_p; 1) ↦ (ÿ_n − F_n s̈_n; 1)
    that both evaluators use; ``T[n]`` and ``zeta[n]`` are views into it.
    """

    R: list  # body → inertial rotation of frame n
    r: list  # origin of frame n, inertial coordinates
    twist: list  # (v_O, ω) of frame n in its own coordinates
    y_dot: list  # ẏ_n = S_n twist
    T_aug: list  # T̃_np
    F: list  # F_n (n_y × n_s_n)

    @property
    def T(self) -> list:
        """T_np (n_y × n_y_p) of every subsystem."""
        return [T[:-1, :-1] for T in self.T_aug[:-1]]

    @property
    def zeta(self) -> list:
        """ζ_n = Ṫ_np ẏ_p + Ḟ_n ṡ_n (+ ḟ_n) of every subsystem."""
        return [T[:-1, -1] for T in self.T_aug[:-1]]


def forward(system, q: NDArray, s_dot: NDArray, t: float) -> Kinematics:
    """Poses, ẏ_n, T̃_np (T_np and ζ_n) and F_n of every subsystem at (q, ṡ, t), root to leaves."""
    N = len(system.joints)
    ground = (np.eye(3), np.zeros(3), np.zeros(6), np.zeros(0), np.ones((1, 1)), None)
    R, r, twist, y_dot, T_aug, F = ([None] * N + [g] for g in ground)
    for n, joint in enumerate(system.joints):
        p = system.parent[n]
        rel = joint.relative(system._q_get[n](q), system._s_get[n](s_dot), t)
        A_pn = joint.orientation @ rel.A
        r_pn = joint.r_pn + joint.orientation @ rel.r
        T6 = chain_matrix(A_pn.T, r_pn)
        u = T6 @ twist[p]
        R[n], r[n] = R[p] @ A_pn, r[p] + R[p] @ r_pn
        twist[n] = u + rel.w
        zeta6 = cross_motion(u, rel.w) + rel.zeta
        S_n, S_p = system.S[n], system.S[p]
        T6 = T6 if S_p is None else T6 @ S_p.T
        if S_n is None:
            y_dot[n], F[n] = twist[n], rel.F
        else:
            y_dot[n], F[n], T6, zeta6 = S_n @ twist[n], S_n @ rel.F, S_n @ T6, S_n @ zeta6
        T_aug[n] = _augmented_chain(T6, zeta6)
    return Kinematics(R, r, twist, y_dot, T_aug, F)


def _augmented_chain(T: NDArray, zeta: NDArray) -> NDArray:
    """T̃ = [[T, ζ], [0, 1]]."""
    rows, cols = T.shape
    T_aug = np.zeros((rows + 1, cols + 1))
    T_aug[:rows, :cols] = T
    T_aug[:rows, cols] = zeta
    T_aug[rows, cols] = 1.0
    return T_aug


def gauss_terms(system, kin: Kinematics, q: NDArray, s_dot: NDArray, t: float) -> tuple[list, list]:
    """M_n and h_n = Q_n − G_n ẏ_n of every subsystem, forces included (B(14)).

    The lists have a ground entry at −1 (empty), where joint forces on the ground land.
    """
    M, h = [], []
    for n, sub in enumerate(system.subsystems):
        M_n, h_n = sub.gauss_terms(kin.y_dot[n], kin.R[n], system.gravity)
        M.append(M_n)
        h.append(h_n)
    M.append(np.zeros((0, 0)))
    h.append(np.zeros(0))
    for force in system.forces:
        force.add_to(h, kin, t, q, s_dot)
    return M, h

"""Reaction forces of constraints given as equations, and an event when a contact lets go (THEORY §7).

With the constraint inserted before the projection, Fᵀ(M s̈_tree + b) = 0 leaves the
residual M s̈_tree + b of the tree's Gauss form in the constrained directions, the
complement of F, i.e. the range of A_sᵀ: M s̈_tree + b = A_sᵀ λ. The multipliers λ are
the constraint forces in the constraint's own coordinates: for a row Φ_i = 0 the
generalised force A_sᵀλ_i acts along ∂Φ_i/∂q, so with Φ_i a distance along a unit normal,
λ_i is the normal force (positive pushing in the direction of growing Φ_i).

In a tree the joints' reactions follow from the same residuals subsystem by subsystem:
r_n = M_n ÿ_n + G_n ẏ_n − Q_n is the force the constraints exert on subsystem n, and the
joint of n carries W_n = r_n + Σ_c T_cnᵀ W_c (its children c pass theirs on), in the ẏ_n
coordinates of n (for a rigid body: force and moment about O_n in body axes). Its part
along the joint's free directions, F_nᵀ W_n, is zero (no joint forces); the rest, in the
complement of F_n, is the reaction.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.kinematics import forward, gauss_terms


def reactions(system, result) -> NDArray:
    """λ (n_t × n_c) along a trajectory of a :class:`~projeq.constrained.ConstrainedSystem`
    (rows: Φ first, then the Pfaffian rows), from ``M s̈_tree + b = A_sᵀ λ``."""
    if not hasattr(system, "accelerations_tree"):
        raise ValueError(f"system: reactions need a ConstrainedSystem, got {system!r}")
    if result.q.shape[1:] != (system.n_q,) or result.s_dot.shape[1:] != (system.n_s,):
        raise ValueError(
            f"result: its states (q {result.q.shape[1:]}, s_dot {result.s_dot.shape[1:]}) are not "
            f"those of the system (n_q = {system.n_q}, n_s = {system.n_s})"
        )
    rows = [system.accelerations_tree(q, s, t)[1] for t, q, s in zip(result.t, result.q, result.s_dot)]
    return np.array(rows).reshape(len(result.t), system.n_c)


def contact_event(system, row: int, terminal: bool = True):
    """An event ``event(t, q, s_dot) = λ_row`` for :func:`projeq.simulate` that fires when the
    unilateral contact force of constraint ``row`` falls through zero (the body lifts off);
    terminal by default, so the run stops there."""
    if not isinstance(row, (int, np.integer)) or not 0 <= row < system.n_c:
        raise ValueError(f"row: expected a constraint row in 0..{system.n_c - 1}, got {row!r}")

    def event(t, q, s_dot):
        return system.accelerations_tree(q, s_dot, t)[1][row]

    event.terminal, event.direction = terminal, -1
    return event


def joint_reactions(system, q, s_dot, t: float = 0.0) -> dict:
    """{name: W_n}: the wrench each joint of a tree System transmits to its subsystem (and
    the subtree beyond), in the subsystem's ẏ coordinates (a rigid body's [force; moment
    about O_n] in body axes), from W_n = r_n + Σ_c T_cnᵀ W_c with r_n = M_n ÿ_n − h_n and
    ÿ_n = T_np ÿ_p + F_n s̈_n + ζ_n (B(14); THEORY §7)."""
    q, s_dot = system.check_state(q, s_dot, t)
    s_ddot = system.accelerations(q, s_dot, t)
    kin = forward(system, q, s_dot, float(t))
    M, h = gauss_terms(system, kin, q, s_dot, float(t))
    N = len(system.joints)
    y_ddot = [None] * N + [np.zeros(0)]
    for n in range(N):  # root → leaves: accelerations ÿ_n
        cols, P = system.joint_s_columns(n)
        y_ddot[n] = kin.T[n] @ y_ddot[system.parent[n]] + kin.F[n] @ (P @ s_ddot[cols]) + kin.zeta[n]
    W = [M[n] @ y_ddot[n] - h[n] for n in range(N)]
    for n in reversed(range(N)):  # leaves → root: pass each wrench on to the parent
        if system.parent[n] >= 0:
            W[system.parent[n]] = W[system.parent[n]] + kin.T[n].T @ W[n]
    return dict(zip(system.names, W))

"""Reaction forces of constraints given as equations, and an event when a contact lets go (docs/theory.md §7).

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

from projeq.assembly.kinematics import forward, gauss_terms
from projeq.system import CLOSED, check_model


def reactions(system, result) -> NDArray:
    """λ (n_t × n_lambda) along a trajectory of a :class:`~projeq.constraints.partitioned.ConstrainedSystem`
    (rows: Φ first, then the Pfaffian rows), from ``M s̈_tree + b = A_sᵀ λ``; each row in
    its own partition if the run re-pivoted (``result.partitions``)."""
    _check_multipliers(system, "reactions")
    if result.q.shape[1:] != (system.n_q,) or result.s_dot.shape[1:] != (system.n_s,):
        raise ValueError(
            f"result: its states (q {result.q.shape[1:]}, s_dot {result.s_dot.shape[1:]}) are not "
            f"those of the system (n_q = {system.n_q}, n_s = {system.n_s})"
        )
    rows = [model.accelerations_tree(q, s, t)[1]
            for model, t, q, s in zip(system.row_models(result), result.t, result.q, result.s_dot)]
    return np.array(rows).reshape(len(result.t), system.n_lambda)


def _check_multipliers(system, what: str) -> None:
    """ValueError unless ``system`` is a model with constraint equations (multipliers λ)."""
    check_model(system)
    if not system.n_lambda:
        raise ValueError(
            f"system: {what} need a ConstrainedSystem (constraint equations with multipliers λ), got {system!r}, "
            "whose constraints are in its joints (their reactions: joint_reactions)"
        )



def contact_event(system, row: int, terminal: bool = True):
    """An event ``event(t, q, s_dot) = λ_row`` for :func:`projeq.simulate` that fires when the
    unilateral contact force of constraint ``row`` falls through zero (the body lifts off);
    terminal by default, so the run stops there."""
    _check_multipliers(system, "contact events")
    if not isinstance(row, (int, np.integer)) or not 0 <= row < system.n_lambda:
        raise ValueError(f"row: expected a constraint row in 0..{system.n_lambda - 1}, got {row!r}")

    def event(t, q, s_dot):
        return system.accelerations_tree(q, s_dot, t)[1][row]

    event.terminal, event.direction = terminal, -1
    return event


def joint_reactions(system, q, s_dot, t: float = 0.0, cuts=None) -> dict:
    """{name: W_n}: the wrench each joint transmits to its subsystem (and the subtree
    beyond), in the subsystem's ẏ coordinates (a rigid body's [force; moment about O_n] in
    body axes), from W_n = r_n + Σ_c T_cnᵀ W_c with r_n = M_n ÿ_n − h_n − w_n and
    ÿ_n = T_np ÿ_p + F_n s̈_n + ζ_n (B(14); docs/theory.md §7).

    For a :class:`~projeq.constraints.partitioned.ConstrainedSystem`, ``cuts`` is a dict
    {name: :class:`~projeq.constraints.cut_joints.PinClosure`} of the cut joints whose closures make up
    its Φ, in the order of Φ's rows (ValueError if, stacked, they are not Φ); their multipliers
    λ are the cut joints' forces, applied as the wrenches w_n, and the result also holds, under
    each cut's name, the wrench of the cut joint on its subsystem a. For a tree System (no
    multipliers) ``cuts`` is not used (w_n = 0). q must close the loops (:data:`projeq.system.CLOSED`).
    """
    check_model(system)
    q, s_dot = system.check_state(q, s_dot, t)
    system.check_closed("q", q, t, CLOSED)
    tree, cuts = system.tree, (_check_cuts(system, cuts, q, t) if system.n_lambda else {})
    s_ddot_tree, lam = system.accelerations_tree(q, s_dot, t)
    s_dot_tree = system.tree_velocities(q, s_dot, t)
    kin = forward(tree, q, s_dot_tree, float(t))
    applied, cut_wrenches, row = {}, {}, 0
    for name, closure in cuts.items():
        loads = closure.wrenches(kin, lam[row: row + len(closure.rows)], q)
        row += len(closure.rows)
        cut_wrenches[name] = loads[closure.a]
        for n, w in loads.items():
            applied[n] = applied.get(n, 0.0) + w
    return _transmitted(tree, q, s_dot_tree, s_ddot_tree, t, applied, kin) | cut_wrenches


def _check_cuts(system, cuts, q: NDArray, t: float) -> dict:
    if not isinstance(cuts, dict) or not all(callable(getattr(c, "wrenches", None)) for c in cuts.values()):
        raise ValueError(f"cuts: expected a dict {{name: PinClosure}} of the cut joints, got {cuts!r}")
    rows = sum(len(c.rows) for c in cuts.values())
    if rows != system.m_h or system.m_p:
        raise ValueError(
            f"cuts: the cut joints give {rows} closure rows, the system has {system.m_h} holonomic and "
            f"{system.m_p} Pfaffian constraints; every constraint must be a cut joint's closure"
        )
    clash = set(cuts) & set(system.names)
    if clash:
        raise ValueError(f"cuts: names {sorted(clash)} are subsystem names already")
    _check_cuts_are_phi(system, cuts, q, t)
    return cuts


def _check_cuts_are_phi(system, cuts: dict, q: NDArray, t: float) -> None:
    """The cuts' closures, stacked in the order given, are the system's Φ: λ_i is the force of
    row i, so other points, axes or an order other than Φ's would apply each λ to another
    joint. Both vanish on the constraint manifold; they are compared at q moved by
    0.1 (1 + |q|) along two seeded random directions, to 1e-9 of Φ's size there (the same
    function agrees to round-off)."""
    rng = np.random.default_rng(0)
    for _ in range(2):
        moved = q + 0.1 * (1.0 + np.abs(q)) * rng.standard_normal(q.size)
        phi = system.phi(moved, t)
        stacked = np.concatenate([np.ravel(closure(moved, t)) for closure in cuts.values()])
        if np.abs(stacked - phi).max() > 1e-9 * max(1.0, np.abs(phi).max()):
            raise ValueError(
                f"cuts: the cut joints {list(cuts)} are not the system's Φ (at q = {np.round(moved, 3).tolist()} "
                f"they give {np.round(stacked, 6).tolist()}, Φ = {np.round(phi, 6).tolist()}); give the closures "
                "Φ was built from, in the order of its rows"
            )


def _transmitted(tree, q, s_dot, s_ddot, t, applied: dict, kin=None) -> dict:
    """W_n of every tree joint, leaves → root, with the loads ``applied`` {n: w_n} (B(14))."""
    kin = forward(tree, q, s_dot, float(t)) if kin is None else kin
    M, h = gauss_terms(tree, kin, q, s_dot, float(t))
    N = len(tree.joints)
    y_ddot = [None] * N + [np.zeros(0)]
    for n in range(N):  # root → leaves: accelerations ÿ_n
        cols, P = tree.joint_s_columns(n)
        y_ddot[n] = kin.T[n] @ y_ddot[tree.parent[n]] + kin.F[n] @ (P @ s_ddot[cols]) + kin.zeta[n]
    W = [M[n] @ y_ddot[n] - h[n] - applied.get(n, 0.0) for n in range(N)]
    for n in reversed(range(N)):  # leaves → root: pass each wrench on to the parent
        if tree.parent[n] >= 0:
            W[tree.parent[n]] = W[tree.parent[n]] + kin.T[n].T @ W[n]
    return dict(zip(tree.names, W))

"""Checks for systems whose minimal velocities are non-holonomic quasi-velocities.

With q̇ = K(q) ṡ + k the velocity constraints hold by construction for any ṡ; what can go
wrong is *input*:

- :func:`initial_speeds` turns given rates q̇₀ into ṡ₀ and refuses q̇₀ that violate the
  constraints they are meant to satisfy (ValueError with the residuals);
- :func:`check_configuration` refuses a configuration where a joint's K(q) is not finite
  or not of full column rank (coordinate singularities such as Euler angles at 90° tilt),
  or where F(q) loses rank (minimal velocities no longer independent).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.checks import state_vector

# relative size of a residual (to the rates' size) above which q̇ violates the constraints:
# far above round-off (1e-16) and far below any physical violation
CONSTRAINT_TOLERANCE = 1e-8
# condition number of K or F above which the configuration is treated as singular
SINGULAR_CONDITION = 1e10
# ... and above which a run is stopped as approaching a coordinate singularity: the minimal
# velocities' gain from K or F reaches 1e5, so ṡ grows like 1/distance and steps shrink to nothing
NEAR_SINGULAR_CONDITION = 1e5


def _joint_rows(system, n):
    return slice(system.q_slice[n].start, system.e_q_slice[n].start), slice(
        system.s_slice[n].start, system.e_s_slice[n].start
    )


def initial_speeds(system, q, q_dot, t: float = 0.0, tol: float = CONSTRAINT_TOLERANCE) -> NDArray:
    """The minimal velocities ṡ with K(q) ṡ + k = q̇, for rates q̇ that satisfy the
    constraints.

    Raises ValueError when q̇ violates the system's declared velocity constraints (the
    residuals are named) or is not of the form K ṡ + k (no ṡ reproduces it).
    """
    q = state_vector("q", q, system.n_q)
    q_dot = state_vector("q_dot", q_dot, system.n_q)
    check_configuration(system, q, t)
    scale = 1.0 + np.abs(q_dot).max()
    residual = system.constraint_residual(q, q_dot, t)
    if residual.size and np.abs(residual).max() > tol * scale:
        raise ValueError(
            f"q_dot: the initial rates violate the velocity constraints: residual "
            f"{np.array2string(residual, precision=4)} (tolerance {tol * scale:.2g}); "
            "give rates that satisfy them, or give the minimal velocities s_dot directly"
        )
    K = system.K(q, t)
    k = system.q_dot(q, np.zeros(system.n_s), t)
    s_dot, *_ = np.linalg.lstsq(K, q_dot - k, rcond=None)
    mismatch = K @ s_dot + k - q_dot
    if np.abs(mismatch).max() > tol * scale:
        raise ValueError(
            f"q_dot: no minimal velocities reproduce the given rates (q̇ − K ṡ − k = "
            f"{np.array2string(mismatch, precision=4)}); they violate the constraints built into K"
        )
    return s_dot


def may_lose_rank(joint) -> bool:
    """Whether ``joint`` has minimal velocities of its own whose K(q) or F(q) can lose rank: not a
    revolute or prismatic joint, whose K = E and F = its unit axis have condition number 1 at every q."""
    return bool(joint.n_s) and not joint.coupling and joint.compiled_kind not in ("revolute", "prismatic")


def may_be_singular(system) -> bool:
    """Whether a joint of the tree ``system`` :func:`may_lose_rank`, which :func:`check_configuration`
    and :func:`near_singularity` check (a forward pass and condition numbers: 0.5 ms on the spin-up
    beam, whose prescribed hub has none; ~2 ms on chain(5))."""
    return any(may_lose_rank(joint) for joint in system.joints)


def near_singularity(system, q, t: float) -> None:
    """During a run: ValueError when the state at t has come near a coordinate singularity
    (a condition number of K or F above :data:`NEAR_SINGULAR_CONDITION`), naming the joint."""
    try:
        check_configuration(system, q, t, NEAR_SINGULAR_CONDITION)
    except ValueError as exc:
        raise ValueError(f"q: the run approaches a coordinate singularity at t = {t:.6g}, where the minimal "
                         f"velocities grow without bound and the steps shrink to nothing: {exc}") from None


def _joint_F(system, n: int, q_n: NDArray, n_s: int, t: float) -> NDArray | None:
    """F_n(q) of joint n alone (its ``n_s`` minimal velocities at rest: F⁶ depends on its own coordinates
    and t; :func:`projeq.assembly.kinematics.selected_F`), None where it cannot be evaluated there."""
    from projeq.assembly.kinematics import selected_F

    try:
        return selected_F(system, n, system.joints[n].relative(q_n, np.zeros(n_s), t).F)
    except (FloatingPointError, ZeroDivisionError, ValueError):
        return None


def check_configuration(system, q, t: float = 0.0, max_condition: float = SINGULAR_CONDITION) -> None:
    """Raise ValueError if some joint's K(q) or F(q) is singular at q (non-finite entries,
    or condition number above ``max_condition``), naming the joint and the coordinates: each joint that
    :func:`may_lose_rank` on its own (its K and F depend on its coordinates and t alone)."""
    q = state_vector("q", q, system.n_q)
    for n, joint in enumerate(system.joints):
        if not may_lose_rank(joint):
            continue
        rows, cols = _joint_rows(system, n)
        where = f"joint of {system.names[n]!r} at q = {np.round(q[rows], 6).tolist()}"
        with np.errstate(all="ignore"):
            K, F = joint.K(q[rows], t), _joint_F(system, n, q[rows], cols.stop - cols.start, t)
        for label, M in (("K(q) of q̇ = K ṡ", K), ("F(q)", F)):
            if M is None:
                continue
            if not np.all(np.isfinite(M)):
                bad = sorted({int(i) for i in np.argwhere(~np.isfinite(M))[:, 0]})
                raise ValueError(
                    f"{label} is singular (not finite in rows {bad}) for the {where}: a coordinate "
                    "singularity of the chosen coordinates; use other coordinates (another Euler "
                    "sequence or quaternions) or a configuration away from it"
                )
            cond = np.linalg.cond(M) if M.size else 1.0
            if not cond < max_condition:
                raise ValueError(
                    f"{label} loses rank (condition number {cond:.3g}) for the {where}: the minimal "
                    "velocities are not independent there (a coordinate singularity); use other "
                    "coordinates or a configuration away from it"
                )

"""The loops of the fast evaluator on flat arrays: docs/theory.md §4 (kinematics) and §6 (passes).

Plain Python on scalars and small arrays, written so that numba can compile it
(:func:`kernel` with ``compiled=True`` applies ``numba.njit(cache=True)``); the same source
runs interpreted with ``compiled=False``, so both are the same algorithm. The kernels are
dtype-generic: called with complex128 workspaces (the complex step of
:mod:`projeq.analysis.jacobians`) numba compiles a second specialization of the same source;
their temporaries take the workspace's dtype and their pivot checks compare real parts.

Joint kinds: ``FIXED`` (no dof), ``REVOLUTE`` (F⁶ = [0; e]), ``PRISMATIC`` (F⁶ = [e; 0]),
about a unit axis e in joint-frame coordinates, and ``GIVEN``: any other joint, whose
relative motion (A, r, F⁶, w, ζ of :class:`projeq.joints.base.Relative`) its own
``relative`` computes before each call (0–6 minimal velocities: the passes solve
D_n = F_nᵀ M̂_n F_n by Cholesky); subsystems: rigid bodies (M_n = M6, h_n of docs/theory.md §3). Twists are (v_O, ω) in body coordinates; index −1 is the ground.

Compiled twins. numba compiles scalar loops, not the array functions of
:mod:`projeq.spatial`, so four formulas have a second, scalar form here and only here:
:func:`_relative_rotation` (Rodrigues, :func:`projeq.spatial.rodrigues`), :func:`chain_matrix_into`
(:func:`projeq.spatial.chain_matrix`), :func:`add_cross` (:func:`projeq.spatial.cross`, added
into an output: the per-body loops allocate no temporaries) and
:func:`_rigid_h` (:func:`projeq.subsystems.rigid.rigid_h`); tests/assembly/test_fast.py
checks each against its twin.
"""

from __future__ import annotations

import functools
import hashlib
import inspect
import sys
import types
from pathlib import Path

import numpy as np

FIXED, REVOLUTE, PRISMATIC, GIVEN = 0, 1, 2, 3
KINDS = {"fixed": FIXED, "revolute": REVOLUTE, "prismatic": PRISMATIC}  # a joint's compiled_kind -> its code here
#: the columns of ``index`` (one row per joint n and its body): joint kind, parent p (−1: the
#: ground), first coordinate and first velocity of the joint in q and ṡ, the joint's columns of
#: F_n (minimal velocities, with an elastic body's q̇_e) and the body's n_y. The model's
#: constants travel in few arrays because every array argument of a compiled call costs its
#: unboxing (about 0.1–0.2 µs each here)
KIND, PARENT, Q_INDEX, S_INDEX, N_COLS, N_Y = range(6)
#: the rows of ``geometry[n]`` (3-vectors): the joint axis e, the joint's offset r_pJ in the
#: parent, then the three rows of its orientation A_pJ; of ``inertia[n]``: r_c, the three rows
#: of I_c, then (m, 0, 0)
AXIS, OFFSET, ORIENTATION = 0, 1, 2
CENTRE, INERTIA, MASS = 0, 1, 4
#: the entries of ``given[n]`` (:meth:`projeq.joints.base.Joint.relative_values`): A row by row,
#: r, w, ζ, then F⁶ column by column
GIVEN_A, GIVEN_R, GIVEN_W, GIVEN_ZETA, GIVEN_F = 0, 9, 12, 18, 24


def kernel_array(a, dtype=float) -> np.ndarray:
    """``a`` as the one kind of array the compiled kernels are specialised for: of ``dtype``,
    C-contiguous and writeable (a read-only or strided view, such as a row of a frozen Result
    or a column of a solution, is copied: numba would compile the kernels again for its layout,
    10–30 s cold)."""
    a = np.asarray(a, dtype=dtype)
    return a if a.flags.c_contiguous and a.flags.writeable else np.array(a, dtype=dtype, order="C")


def _numba():
    """numba (None where it is not installed), with projeq's compilation notice and safe cache loading
    installed (:func:`projeq.assembly.compilation.prepare`)."""
    try:
        import numba
    except ImportError:
        return None
    from projeq.assembly.compilation import prepare

    prepare()
    return numba


def numba_module():
    """numba, ready for projeq's kernels (:func:`_numba`); ImportError where it is not installed."""
    numba = _numba()
    if numba is None:
        raise ImportError("numba is not installed (pip install numba)")
    return numba


def has_numba() -> bool:
    """Whether numba (a dependency of projeq) can be imported."""
    return _numba() is not None


def chain_terms(index, geometry, inertia, gravity, q, s_dot, given, elastic, port, T, zeta, F, M, h, R, r_O, twist):
    """T_np, ζ_n, F_n, M_n (of the elastic subsystems) and h_n = Q_n − G_n ẏ_n of every body
    (docs/theory.md §3–4), and the poses R_n, r_n and twists of the reference frames
    (row N of R, r_O, twist: the ground, at rest).

    A_pn = A_pJ A_Jn, r_pn = r_pJ + A_pJ r_Jn, T_np = [[A_np, −A_np r̃_pn], [0, A_np]],
    u = T_np ẏ_p, ẏ_n = u + w, ζ_n = u × w (motion cross product) + Ḟ ṡ + ḟ,
    R_n = R_p A_pn, r_n = r_p + R_p r_pn. The joint's relative motion (A_Jn, r_Jn, its
    twist w and its own part of ζ) comes from the kernel for the kinds it knows (F⁶ = [0; e]
    or [e; 0], w = F⁶ ṡ_n) and from ``given`` (and the columns of F set by the caller)
    for a joint of kind ``GIVEN``. ``index``, ``geometry``, ``inertia`` and ``given``: one row
    per joint and body, columns named by the constants of this module (:data:`KIND` ...).

    Elastic subsystems (docs/theory.md §10): ``elastic`` = (slot, e_index, n_e, m_k, r₀, Ψ, Q,
    K_e, damping, I, Φ_θ, T) — slot[n] ≥ 0 picks the station fields of body n (:func:`elastic_body`,
    :func:`rotary_body`),
    whose ẏ_n = (twist, q̇_e) has n_y = 6 + n_e rows and F_n the extra columns [0; E];
    ``port`` = (slot, r₀, Ψ, Q, angles, c) — slot[n] ≥ 0: joint n sits at a station of its
    elastic parent p, whose frame (:func:`port_motion`) is the base of the joint, and
    T̃_np = T̃⁶_np P̃ with P̃ = [[T⁶_port, F_port, ζ̂_port], [0, 0, 1]] (the reference's
    :func:`projeq.assembly.kinematics.forward`).
    Scalar loops only (no temporaries per body), which is what numba compiles best.
    """
    N = index.shape[0]
    kind, parent, q_index, s_index = index[:, KIND], index[:, PARENT], index[:, Q_INDEX], index[:, S_INDEX]
    n_cols = index[:, N_COLS]
    axis, offset, orientation = geometry[:, AXIS], geometry[:, OFFSET], geometry[:, ORIENTATION:]
    m, r_c, I_c = inertia[:, MASS, 0], inertia[:, CENTRE], inertia[:, INERTIA:MASS]
    body, e_index, n_e, el_m, el_r0, el_Psi, el_Q, el_K, el_damping, el_I, el_Phi_theta, el_T = elastic
    port_slot, port_r0, port_Psi, port_Q, port_angles, port_c = port
    twist[N] = 0.0
    R[N] = 0.0
    r_O[N] = 0.0
    for a in range(3):
        R[N, a, a] = 1.0
    dtype = T.dtype  # of the workspace: float, or complex under the complex step
    g_body = np.zeros((N + 1, 3), dtype)
    g_body[N] = gravity
    A_rel, A_np, r_rel, r = np.empty((3, 3), dtype), np.empty((3, 3), dtype), np.empty(3, dtype), np.empty(3, dtype)
    u, w, T6, zeta6 = np.empty(6, dtype), np.empty(6, dtype), np.empty((6, 6), dtype), np.empty(6, dtype)
    T_port, zeta_port, A_port, r_port = np.empty((6, 6), dtype), np.empty(6, dtype), np.empty((3, 3), dtype), np.empty(3, dtype)
    w_port, F_port = np.empty(6, dtype), np.empty((6, el_Psi.shape[3]), dtype)
    port_R, port_r, port_twist, port_g = np.empty((3, 3), dtype), np.empty(3, dtype), np.empty(6, dtype), np.empty(3, dtype)
    v_p, work = np.empty(3, dtype), np.empty((2, 3), dtype)
    for n in range(N):
        e, k, p = axis[n], kind[n], parent[n] if parent[n] >= 0 else N
        j = port_slot[n]
        if j >= 0:  # the base is the frame at a station of the elastic parent p
            k_p, i0, s0 = n_e[p], e_index[p, 0], e_index[p, 1]
            port_motion(port_r0[j], port_Psi[j, :, :k_p], port_Q[j, :k_p, :k_p], port_angles[j, :, :k_p], port_c[j],
                        q[i0 : i0 + k_p], s_dot[s0 : s0 + k_p], A_port, r_port, F_port[:, :k_p], zeta_port)
            for a in range(6):
                w_port[a] = 0.0
                for i in range(k_p):
                    w_port[a] += F_port[a, i] * s_dot[s0 + i]
            for a in range(3):
                for b in range(3):
                    A_np[a, b] = A_port[b, a]
            chain_matrix_into(A_np, r_port, T_port)
            for a in range(6):
                u[a] = dot6(T_port[a], twist[p])
            add_motion_cross(u, w_port, zeta_port)
            for a in range(6):
                port_twist[a] = u[a] + w_port[a]
            for a in range(3):
                port_r[a] = r_O[p, a] + R[p, a, 0] * r_port[0] + R[p, a, 1] * r_port[1] + R[p, a, 2] * r_port[2]
                port_g[a] = A_port[0, a] * g_body[p, 0] + A_port[1, a] * g_body[p, 1] + A_port[2, a] * g_body[p, 2]
                for b in range(3):
                    port_R[a, b] = R[p, a, 0] * A_port[0, b] + R[p, a, 1] * A_port[1, b] + R[p, a, 2] * A_port[2, b]
            R_b, r_b, twist_b, g_b = port_R, port_r, port_twist, port_g
        else:
            R_b, r_b, twist_b, g_b = R[p], r_O[p], twist[p], g_body[p]
        if k == GIVEN:
            for a in range(3):
                r_rel[a] = given[n, GIVEN_R + a]
                for b in range(3):
                    A_rel[a, b] = given[n, GIVEN_A + 3 * a + b]
            k_s = n_cols[n] - n_e[n]  # the joint's own columns: its row goes on with q̇ after them
            for a in range(6):
                w[a] = given[n, GIVEN_W + a]
                for c in range(6):  # F⁶ column by column
                    F[n, a, c] = given[n, GIVEN_F + 6 * c + a] if c < k_s else 0.0
        else:
            x = q[q_index[n]] if k != FIXED else 0.0
            _relative_rotation(k, e, x, A_rel)
            F[n] = 0.0
            if k == REVOLUTE:
                F[n, 3:6, 0] = e
            elif k == PRISMATIC:
                F[n, :3, 0] = e
            sd = s_dot[s_index[n]] if k != FIXED else 0.0
            for a in range(3):
                r_rel[a] = e[a] * x if k == PRISMATIC else 0.0
            for a in range(6):
                w[a] = F[n, a, 0] * sd
        for a in range(3):  # A_np = (A_pJ A_Jn)ᵀ, r_pn = r_pJ + A_pJ r_Jn
            r[a] = offset[n, a] + orientation[n, a, 0] * r_rel[0] + orientation[n, a, 1] * r_rel[1] + orientation[n, a, 2] * r_rel[2]
            for b in range(3):
                A_np[b, a] = orientation[n, a, 0] * A_rel[0, b] + orientation[n, a, 1] * A_rel[1, b] + orientation[n, a, 2] * A_rel[2, b]
        for a in range(3):  # R_n = R_p A_pn, r_n = r_p + R_p r_pn
            r_O[n, a] = r_b[a] + R_b[a, 0] * r[0] + R_b[a, 1] * r[1] + R_b[a, 2] * r[2]
            for b in range(3):
                R[n, a, b] = R_b[a, 0] * A_np[b, 0] + R_b[a, 1] * A_np[b, 1] + R_b[a, 2] * A_np[b, 2]
        v_p[:] = twist_b[:3]  # the parent's twist at the origin of n: v_p + ω_p × r_pn, ω_p
        add_cross(twist_b[3:], r, v_p)
        w_p = twist_b[3:]
        for a in range(3):  # u = T_np ẏ_p, g_n = A_np g_p
            u[a] = A_np[a, 0] * v_p[0] + A_np[a, 1] * v_p[1] + A_np[a, 2] * v_p[2]
            u[a + 3] = A_np[a, 0] * w_p[0] + A_np[a, 1] * w_p[1] + A_np[a, 2] * w_p[2]
            g_body[n, a] = A_np[a, 0] * g_b[0] + A_np[a, 1] * g_b[1] + A_np[a, 2] * g_b[2]
        for a in range(6):
            twist[n, a] = u[a] + w[a]
        zeta6[:] = 0.0
        add_motion_cross(u, w, zeta6)
        if k == GIVEN:
            for a in range(6):
                zeta6[a] += given[n, GIVEN_ZETA + a]
        if j >= 0:  # T_np = T⁶ [T⁶_port, F_port], ζ_n = T⁶ ζ̂_port + ζ⁶
            chain_matrix_into(A_np, r, T6)
            for a in range(6):
                zeta[n, a] = zeta6[a] + dot6(T6[a], zeta_port)
                for b in range(6):
                    T[n, a, b] = dot6(T6[a], T_port[:, b])
                for b in range(n_e[p]):
                    T[n, a, 6 + b] = dot6(T6[a], F_port[:, b])
        else:
            chain_matrix_into(A_np, r, T[n])
            zeta[n, :6] = zeta6
        i = body[n]
        if i >= 0:
            k_n, i0, s0, n_j = n_e[n], e_index[n, 0], e_index[n, 1], n_cols[n] - n_e[n]
            for a in range(k_n):  # F_n = [F⁶, [0; E]]
                F[n, 6 + a, n_j + a] = 1.0
            elastic_body(el_m[i], el_r0[i], el_Psi[i, :, :, :k_n], el_Q[i, :, :k_n, :k_n], el_K[i, :k_n, :k_n],
                         el_damping[i], q[i0 : i0 + k_n], s_dot[s0 : s0 + k_n], twist[n], g_body[n], M[n], h[n])
            rotary_body(el_I[i], el_Phi_theta[i, :, :, :k_n], el_T[i, :, :k_n, :k_n], q[i0 : i0 + k_n],
                        s_dot[s0 : s0 + k_n], twist[n], M[n], h[n])
        else:
            _rigid_h(m[n], r_c[n], I_c[n], twist[n], g_body[n], h[n, :6], work)


def elastic_body(m, r0, Psi, Q, K_e, damping, q_e, q_e_dot, twist, g, M, h):
    """M_n = Σ_k m_k J_kᵀ J_k and h_n = −Σ_k m_k J_kᵀ c_k − [0; K_e (q_e + d q̇_e)] of a body whose
    slices (masses m_k) sit at r_k = r₀_k + Ψ_k q_e − ½ (q_eᵀ Q_k q_e) e_x in its reference
    frame (the field of :meth:`projeq.RitzBeam.slice_field`): J_k = [E, −r̃_k, Φ_r,k] with
    Φ_r,k = Ψ_k − e_x (Q_k q_e)ᵀ and c_k = ω̃ ṙ_k + ω̃ v_k − (q̇_eᵀ Q_k q̇_e) e_x − g (B(25),
    docs/theory.md §10); written into M[:n_y, :n_y] and h[:n_y]. Compiled twin of
    :class:`projeq.subsystems.beam.integrals.Quadrature` (plus the beam's restoring force)."""
    k_e = q_e.shape[0]
    n_y = 6 + k_e
    M[:n_y, :n_y] = 0.0
    h[:n_y] = 0.0
    J, Qq = np.zeros((3, n_y), M.dtype), np.empty(k_e, M.dtype)
    for a in range(3):
        J[a, a] = 1.0
    w0, w1, w2 = twist[3], twist[4], twist[5]
    for k in range(m.shape[0]):  # scalars only: no temporaries per station
        m_k = m[k]
        quadratic, rate = 0.0, 0.0
        for i in range(k_e):
            Qq[i], Qqd = 0.0, 0.0
            for l in range(k_e):
                Qq[i] += Q[k, i, l] * q_e[l]
                Qqd += Q[k, i, l] * q_e_dot[l]
            quadratic += Qq[i] * q_e[i]
            rate += Qqd * q_e_dot[i]
        for i in range(k_e):
            J[0, 6 + i] = Psi[k, 0, i] - Qq[i]
            J[1, 6 + i] = Psi[k, 1, i]
            J[2, 6 + i] = Psi[k, 2, i]
        p0, p1, p2, d0, d1, d2 = _image(Psi[k], J, q_e, q_e_dot)  # Ψ q_e and ṙ = Φ_r q̇_e
        r0_, r1, r2 = r0[k, 0] - 0.5 * quadratic + p0, r0[k, 1] + p1, r0[k, 2] + p2
        J[0, 4], J[0, 5], J[1, 3], J[1, 5], J[2, 3], J[2, 4] = r2, -r1, -r2, r0_, r1, -r0_  # −r̃
        # c = ω̃ ṙ + ω̃ (v + ω̃ r + ṙ) − g = ω̃ u − g with u = v + ω̃ r + 2 ṙ
        u0 = twist[0] + w1 * r2 - w2 * r1 + 2.0 * d0
        u1 = twist[1] + w2 * r0_ - w0 * r2 + 2.0 * d1
        u2 = twist[2] + w0 * r1 - w1 * r0_ + 2.0 * d2
        c0 = w1 * u2 - w2 * u1 - g[0] - rate
        c1 = w2 * u0 - w0 * u2 - g[1]
        c2 = w0 * u1 - w1 * u0 - g[2]
        for a in range(n_y):
            h[a] -= m_k * (J[0, a] * c0 + J[1, a] * c1 + J[2, a] * c2)
            for b in range(a, n_y):
                M[a, b] += m_k * (J[0, a] * J[0, b] + J[1, a] * J[1, b] + J[2, a] * J[2, b])
    for a in range(n_y):
        for b in range(a + 1, n_y):
            M[b, a] = M[a, b]
    for i in range(k_e):
        for l in range(k_e):
            h[6 + i] -= K_e[i, l] * (q_e[l] + damping * q_e_dot[l])


def _image(P, J, q_e, q_e_dot):
    """(P q_e, J[:, 6:] q̇_e) as six scalars: a station's field (3 × n_e) at q_e and the rate
    that the elastic columns of its Jacobian J (3 × n_y) give."""
    p0, p1, p2, d0, d1, d2 = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    for i in range(q_e.shape[0]):
        p0 += P[0, i] * q_e[i]
        p1 += P[1, i] * q_e[i]
        p2 += P[2, i] * q_e[i]
        d0 += J[0, 6 + i] * q_e_dot[i]
        d1 += J[1, 6 + i] * q_e_dot[i]
        d2 += J[2, 6 + i] * q_e_dot[i]
    return p0, p1, p2, d0, d1, d2


def rotary_body(I, Phi_theta, T, q_e, q_e_dot, twist, M, h):
    """Adds the slices' rotary inertia (a Rayleigh beam) to M_n and h_n of :func:`elastic_body`,
    from the field of :meth:`projeq.RitzBeam.rotation_field`: at station k, I_k = diag(I[k]),
    θ = Φ_θ,k q_e + (q_eᵀ T_k q_e) e_x, ∂θ/∂q_e = Φ_θ,k + e_x ((T_k + T_kᵀ) q_e)ᵀ,
    J_ω = [0, E − θ̃, (E − ½θ̃) ∂θ/∂q_e], ω_c = J_ω ẏ, θ̇ = ∂θ/∂q_e q̇_e, τ̈ = 2 q̇_eᵀ T_k q̇_e and
    c = ω̃ θ̇ + τ̈ e_x − ½ θ × τ̈ e_x: M_n += Σ_k J_ωᵀ I_k J_ω, h_n −= Σ_k J_ωᵀ (I_k c + ω̃_c I_k ω_c)
    (docs/theory.md §10). Compiled twin of :meth:`projeq.RitzBeam._slice_rotation` and the
    rotary rows of its ``gauss_terms``. Stations with I_k = 0 (padding, or a beam without
    rotary inertia) are skipped."""
    k_e = q_e.shape[0]
    n_y = 6 + k_e
    J, f = np.zeros((3, n_y), M.dtype), np.empty(3, M.dtype)
    w0, w1, w2 = twist[3], twist[4], twist[5]
    for k in range(I.shape[0]):
        I0, I1, I2 = I[k, 0], I[k, 1], I[k, 2]
        if I0 == 0.0 and I1 == 0.0 and I2 == 0.0:
            continue
        tau, acceleration = 0.0, 0.0
        for i in range(k_e):
            T_q, q_T, T_qd = 0.0, 0.0, 0.0
            for l in range(k_e):
                T_q += T[k, i, l] * q_e[l]
                q_T += T[k, l, i] * q_e[l]
                T_qd += T[k, i, l] * q_e_dot[l]
            tau += T_q * q_e[i]
            acceleration += 2.0 * T_qd * q_e_dot[i]
            J[0, 6 + i] = Phi_theta[k, 0, i] + T_q + q_T  # ∂θ/∂q_e, turned below
            J[1, 6 + i] = Phi_theta[k, 1, i]
            J[2, 6 + i] = Phi_theta[k, 2, i]
        t0, t1, t2, d0, d1, d2 = _image(Phi_theta[k], J, q_e, q_e_dot)  # θ − τ e_x and θ̇
        t0 += tau
        for i in range(k_e):  # (E − ½θ̃) ∂θ/∂q_e
            a0, a1, a2 = J[0, 6 + i], J[1, 6 + i], J[2, 6 + i]
            J[0, 6 + i] = a0 - 0.5 * (t1 * a2 - t2 * a1)
            J[1, 6 + i] = a1 - 0.5 * (t2 * a0 - t0 * a2)
            J[2, 6 + i] = a2 - 0.5 * (t0 * a1 - t1 * a0)
        J[0, 3], J[0, 4], J[0, 5] = 1.0, t2, -t1  # E − θ̃
        J[1, 3], J[1, 4], J[1, 5] = -t2, 1.0, t0
        J[2, 3], J[2, 4], J[2, 5] = t1, -t0, 1.0
        o0 = J[0, 3] * w0 + J[0, 4] * w1 + J[0, 5] * w2
        o1 = J[1, 3] * w0 + J[1, 4] * w1 + J[1, 5] * w2
        o2 = J[2, 3] * w0 + J[2, 4] * w1 + J[2, 5] * w2
        for i in range(k_e):
            o0 += J[0, 6 + i] * q_e_dot[i]
            o1 += J[1, 6 + i] * q_e_dot[i]
            o2 += J[2, 6 + i] * q_e_dot[i]
        c0 = w1 * d2 - w2 * d1 + acceleration
        c1 = w2 * d0 - w0 * d2 - 0.5 * acceleration * t2
        c2 = w0 * d1 - w1 * d0 + 0.5 * acceleration * t1
        f[0] = I0 * c0 + o1 * I2 * o2 - o2 * I1 * o1  # I c + ω̃_c I ω_c
        f[1] = I1 * c1 + o2 * I0 * o0 - o0 * I2 * o2
        f[2] = I2 * c2 + o0 * I1 * o1 - o1 * I0 * o0
        for a in range(3, n_y):
            h[a] -= J[0, a] * f[0] + J[1, a] * f[1] + J[2, a] * f[2]
            for b in range(3, n_y):
                M[a, b] += J[0, a] * I0 * J[0, b] + J[1, a] * I1 * J[1, b] + J[2, a] * I2 * J[2, b]


def hub_motion(kind, axis, angles, given, orientation, gravity, A, r, w, zeta, g):
    """The relative motion of a hub whose motion is given, on the ground at rest: A = A_Jn,
    r = r_Jn, w = F⁶ θ̇ (ẏ's twist), ζ = F⁶ θ̈, and g_n = (A_pJ A_Jn)ᵀ g. A Revolute or
    Prismatic ``kind`` about ``axis`` at ``angles`` = (θ, θ̇, θ̈) (A_Jn by
    :func:`_relative_rotation`, r_Jn = e θ for a prismatic hub: a Prescribed joint), FIXED
    (angles zero), or GIVEN: A, r, w, ζ of the joint's own ``relative_values`` in ``given``."""
    r[:] = 0.0
    w[:] = 0.0
    zeta[:] = 0.0
    g[:] = 0.0
    if kind == GIVEN:
        for a in range(3):
            r[a] = given[GIVEN_R + a]
            for b in range(3):
                A[a, b] = given[GIVEN_A + 3 * a + b]
        w[:] = given[GIVEN_W : GIVEN_W + 6]
        zeta[:] = given[GIVEN_ZETA : GIVEN_ZETA + 6]
    else:
        _relative_rotation(kind, axis, angles[0], A)
        first = 3 if kind == REVOLUTE else 0  # F⁶ = [0; e] or [e; 0]
        for a in range(3 if kind != FIXED else 0):
            w[first + a], zeta[first + a] = axis[a] * angles[1], axis[a] * angles[2]
            if kind == PRISMATIC:
                r[a] = axis[a] * angles[0]
    for b in range(3):  # g_n = (A_pJ A_Jn)ᵀ g
        for a in range(3):
            g[b] += (orientation[a, 0] * A[0, b] + orientation[a, 1] * A[1, b] + orientation[a, 2] * A[2, b]) * gravity[a]


def hub_beam(kind, axis, angles, given, orientation, offset, gravity, m, r0, Psi, Q, K_e, damping, I, Phi_theta, T, x,
             pivot_min, M, h, L, frame, x_dot):
    """q̈_e = M_ee⁻¹ (h_e − M_eR ζ) of one elastic body on a hub whose motion is given, its
    reference frame moving with ẏ = (w, q̇_e) and ÿ = (ζ, q̈_e) — B(14) projected on q̇_e
    (:mod:`projeq.assembly.beam_fast`); the hub's motion by :func:`hub_motion`, M_n and h_n by
    :func:`elastic_body` and :func:`rotary_body` (left in ``M`` and ``h``), M_ee = L Lᵀ by
    Cholesky into ``L``. The frame's pose and twist (the ground at rest) into ``frame``
    (6 × 3): R = A_pJ A_Jn (rows 0–2), r = r_pJ + A_pJ r_Jn with the joint's ``offset`` r_pJ
    (row 3), w (rows 4–5); g_n = Rᵀ g. The state x = (q_e, q̇_e), written: ẋ = (q̇_e, q̈_e)
    (q̇ = ṡ for elastic coordinates). Returns −1; 0 when a pivot of M_ee is not above
    ``pivot_min``; 1 when x or ẋ is not finite (ẋ written as far as it got; nothing else
    when x is not)."""
    dtype = M.dtype  # of the workspace: float, or complex under the complex step
    k_e, A, r_Jn = x.shape[0] // 2, np.empty((3, 3), dtype), np.empty(3, dtype)
    w, zeta, g = np.empty(6, dtype), np.empty(6, dtype), np.empty(3, dtype)
    for i in range(2 * k_e):
        if not np.isfinite(x[i]):
            return 1
    q_e, q_e_dot, q_e_ddot = x[:k_e], x[k_e:], x_dot[k_e:]
    x_dot[:k_e] = q_e_dot
    hub_motion(kind, axis, angles, given, orientation, gravity, A, r_Jn, w, zeta, g)
    for a in range(3):
        frame[3, a] = offset[a] + orientation[a, 0] * r_Jn[0] + orientation[a, 1] * r_Jn[1] + orientation[a, 2] * r_Jn[2]
        frame[4, a], frame[5, a] = w[a], w[3 + a]
        for b in range(3):
            frame[a, b] = orientation[a, 0] * A[0, b] + orientation[a, 1] * A[1, b] + orientation[a, 2] * A[2, b]
    elastic_body(m, r0, Psi, Q, K_e, damping, q_e, q_e_dot, w, g, M, h)
    rotary_body(I, Phi_theta, T, q_e, q_e_dot, w, M, h)
    for i in range(k_e):
        q_e_ddot[i] = h[6 + i] - dot6(M[6 + i], zeta)
    for i in range(k_e):
        for j in range(i + 1):  # the lower triangle, which the factorization reads
            L[i, j] = M[6 + i, 6 + j]
    if not cholesky(L, k_e, pivot_min):
        return 0
    cholesky_solve(L, k_e, q_e_ddot)
    for i in range(k_e):
        if not np.isfinite(q_e_ddot[i]):
            return 1
    return -1


def hub_beam_jacobian(kind, axis, angles, given, orientation, offset, gravity, m, r0, Psi, Q, K_e, damping, I, Phi_theta,
                      T, x, step, pivot_min, M, h, L, frame, J):
    """∂ẋ/∂x of :func:`hub_beam` at the real state x by the complex step, column k =
    Im ẋ(x + i step e_k) / step (Squire & Trapp, SIAM Review 40, 1998), all n_x columns in
    one call on a complex workspace (``M``, ``h``, ``L``, ``frame``: complex128); written into J.
    Returns :func:`hub_beam`'s status (−1: every column written)."""
    n_x = x.shape[0]
    z, z_dot = np.empty(n_x, M.dtype), np.empty(n_x, M.dtype)
    for k in range(n_x):
        z[:] = x
        z[k] += 1j * step
        status = hub_beam(kind, axis, angles, given, orientation, offset, gravity, m, r0, Psi, Q, K_e, damping, I,
                          Phi_theta, T, z, pivot_min, M, h, L, frame, z_dot)
        if status >= 0:
            return status
        for i in range(n_x):
            J[i, k] = z_dot[i].imag / step
    return -1


def port_motion(r0, Psi, Q, angles, offset, q_e, q_e_dot, A, r, F, zeta):
    """The frame at a station of an elastic body relative to its reference frame:
    A = R_z(a) R_y(b) R_x(β) with a = v′, b = −w′ and the torsion β (``angles`` · q_e),
    r = r₀ + Ψ q_e − ½ (q_eᵀ Q q_e) e_x + A c, F = [[Aᵀ Φ_r − c̃ Φ_ω], [Φ_ω]] with
    Φ_ω = R_xᵀ (−sin b ∂a, ∂b, cos b ∂a) + e_x ∂β, and ζ = Ḟ q̇_e:
    [−Ω × Aᵀ ṙ − (q̇_eᵀ Q q̇_e) Aᵀ e_x − c × α; α] with Ω = Φ_ω q̇_e and
    α = R_xᵀ (−cos b, 0, −sin b) ȧ ḃ − β̇ e_x × R_xᵀ (−sin b ȧ, ḃ, cos b ȧ) (Ȧ = A Ω̃,
    Ṙ_xᵀ = −β̇ ẽ_x R_xᵀ). Compiled twin of :meth:`projeq.subsystems.beam.beam.BeamPort.relative`
    (whose Ḟ q̇_e is a complex step)."""
    k_e = q_e.shape[0]
    a_, b_, beta, a_dot, b_dot, beta_dot, quadratic, rate = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    Phi_r, r_dot = np.empty((3, k_e), A.dtype), np.zeros(3, A.dtype)
    for i in range(k_e):
        a_ += angles[0, i] * q_e[i]
        b_ += angles[1, i] * q_e[i]
        beta += angles[2, i] * q_e[i]
        a_dot += angles[0, i] * q_e_dot[i]
        b_dot += angles[1, i] * q_e_dot[i]
        beta_dot += angles[2, i] * q_e_dot[i]
        Qq, Qqd = 0.0, 0.0
        for l in range(k_e):
            Qq += Q[i, l] * q_e[l]
            Qqd += Q[i, l] * q_e_dot[l]
        quadratic += Qq * q_e[i]
        rate += Qqd * q_e_dot[i]
        for a in range(3):
            Phi_r[a, i] = Psi[a, i] - (Qq if a == 0 else 0.0)
    ca, sa, cb, sb, cx, sx = np.cos(a_), np.sin(a_), np.cos(b_), np.sin(b_), np.cos(beta), np.sin(beta)
    A[0, 0], A[0, 1], A[0, 2] = ca * cb, -sa, ca * sb  # R_z R_y, then turned by R_x below
    A[1, 0], A[1, 1], A[1, 2] = sa * cb, ca, sa * sb
    A[2, 0], A[2, 1], A[2, 2] = -sb, 0.0, cb
    for a in range(3):
        y_, z_ = A[a, 1], A[a, 2]
        A[a, 1], A[a, 2] = cx * y_ + sx * z_, cx * z_ - sx * y_
    for a in range(3):
        r[a] = r0[a] + A[a, 0] * offset[0] + A[a, 1] * offset[1] + A[a, 2] * offset[2]
        for i in range(k_e):
            r[a] += Psi[a, i] * q_e[i]
            r_dot[a] += Phi_r[a, i] * q_e_dot[i]
    r[0] -= 0.5 * quadratic
    Phi_w, c_w, v_rel, Omega = np.empty(3, A.dtype), np.empty(3, A.dtype), np.empty(3, A.dtype), np.empty(3, A.dtype)
    for i in range(k_e):  # Φ_ω = R_xᵀ (−sin b ∂a, ∂b, cos b ∂a) + e_x ∂β
        w1, w2 = angles[1, i], cb * angles[0, i]
        Phi_w[0], Phi_w[1], Phi_w[2] = -sb * angles[0, i] + angles[2, i], cx * w1 + sx * w2, cx * w2 - sx * w1
        c_w[:] = 0.0
        add_cross(offset, Phi_w, c_w)
        for a in range(3):
            F[a, i] = A[0, a] * Phi_r[0, i] + A[1, a] * Phi_r[1, i] + A[2, a] * Phi_r[2, i] - c_w[a]
            F[3 + a, i] = Phi_w[a]
    alpha = zeta[3:]
    w1, w2 = b_dot, cb * a_dot  # R_xᵀ (−sin b ȧ, ḃ, cos b ȧ): Ω without β̇
    turned1, turned2 = cx * w1 + sx * w2, cx * w2 - sx * w1
    Omega[0], Omega[1], Omega[2] = -sb * a_dot + beta_dot, turned1, turned2
    for a in range(3):
        v_rel[a] = A[0, a] * r_dot[0] + A[1, a] * r_dot[1] + A[2, a] * r_dot[2]
        zeta[a] = -rate * A[0, a]
    add_cross(v_rel, Omega, zeta[:3])  # − Ω × Aᵀ ṙ
    alpha[0] = -cb * a_dot * b_dot  # R_xᵀ (−cos b, 0, −sin b) ȧ ḃ − β̇ e_x × R_xᵀ(…)
    alpha[1] = -sx * sb * a_dot * b_dot + beta_dot * turned2
    alpha[2] = -cx * sb * a_dot * b_dot - beta_dot * turned1
    add_cross(alpha, offset, zeta[:3])  # − c × α


def _relative_rotation(kind, e, x, A):
    """A_Jn: cos θ E + sin θ ẽ + (1 − cos θ) e eᵀ for a revolute joint, else E (Rodrigues'
    E + sin θ ẽ + (1 − cos θ) ẽ² with ẽ² = e eᵀ − E; compiled twin of :func:`projeq.spatial.rodrigues`)."""
    c, s = (np.cos(x), np.sin(x)) if kind == REVOLUTE else (1.0, 0.0)
    for a in range(3):
        for b in range(3):
            A[a, b] = (1.0 - c) * e[a] * e[b] + (c if a == b else 0.0)
    A[0, 1] -= s * e[2]
    A[1, 0] += s * e[2]
    A[0, 2] += s * e[1]
    A[2, 0] -= s * e[1]
    A[1, 2] -= s * e[0]
    A[2, 1] += s * e[0]


def chain_matrix_into(A_np, r, T):
    """T = [[A_np, −A_np r̃], [0, A_np]] written into T[:6, :6] (the columns of −A_np r̃ are
    A_np (e_j × r)); compiled twin of :func:`projeq.spatial.chain_matrix`."""
    T[:6, :6] = 0.0
    for a in range(3):
        for b in range(3):
            T[a, b] = T[a + 3, b + 3] = A_np[a, b]
        T[a, 3] = A_np[a, 2] * r[1] - A_np[a, 1] * r[2]  # −A r̃ e_x = A (e_x × r)
        T[a, 4] = A_np[a, 0] * r[2] - A_np[a, 2] * r[0]
        T[a, 5] = A_np[a, 1] * r[0] - A_np[a, 0] * r[1]


def add_cross(a, b, out):
    """out += a × b of two 3-vectors, without a temporary (the form the per-body loops use:
    numba allocates every array a function returns)."""
    out[0] += a[1] * b[2] - a[2] * b[1]
    out[1] += a[2] * b[0] - a[0] * b[2]
    out[2] += a[0] * b[1] - a[1] * b[0]


def add_motion_cross(u, w, zeta):
    """ζ += u × w, the motion cross product of two twists (v, ω):
    (ω_u × v_w + v_u × ω_w, ω_u × ω_w)."""
    add_cross(u[3:], w[:3], zeta[:3])
    add_cross(u[:3], w[3:], zeta[:3])
    add_cross(u[3:], w[3:], zeta[3:])


def _rigid_h(m, r_c, I_c, twist, g_body, out, work):
    """h = [m g − ω̃ p ; r̃_c (m g − ω̃ p) − ω̃ I_c ω], p = m (v + ω × r_c) (docs/theory.md §3), written
    into ``out`` (``work``: 2 × 3 scratch for v_c = v + ω × r_c and I_c ω); compiled twin of
    :func:`projeq.subsystems.rigid.rigid_h`."""
    omega, v_c, L_c = twist[3:], work[0], work[1]
    force, moment = out[:3], out[3:]
    v_c[:] = twist[:3]
    add_cross(omega, r_c, v_c)
    for a in range(3):
        L_c[a] = I_c[a, 0] * omega[0] + I_c[a, 1] * omega[1] + I_c[a, 2] * omega[2]
        force[a] = 0.0
        moment[a] = 0.0
    add_cross(v_c, omega, force)  # −ω̃ v_c, then m (g − ω̃ v_c) = m g − ω̃ p
    for a in range(3):
        force[a] = m * (g_body[a] + force[a])
    add_cross(r_c, force, moment)
    add_cross(L_c, omega, moment)  # − ω̃ I_c ω


def passes(index, T, zeta, F, M_n, M_hat, h_hat, pivot_min, s_ddot):
    """Backward and forward pass of docs/theory.md §6 for bodies with ``n_y[n]`` describing
    velocities (6, or 6 + n_e for an elastic body) and joints with ``n_cols[n]`` minimal
    velocities (the first n_cols columns of F[n]; with an elastic body's q̇_e); writes s̈.

    Backward: U = M̂_n F_n, D_n = F_nᵀ U = L Lᵀ (Cholesky), M̄_n = M̂_n − U D_n⁻¹ Uᵀ,
    h̄_n = c − U D_n⁻¹ F_nᵀ c with c = ĥ_n − M̂_n ζ_n; M̂_p += T_npᵀ M̄_n T_np, ĥ_p += T_npᵀ h̄_n.
    Forward: a = T_np ÿ_p + ζ_n, s̈_n = D_n⁻¹ (F_nᵀ ĥ_n − Uᵀ a), ÿ_n = a + F_n s̈_n.
    ``M_hat`` (a workspace) starts as a copy of M_n, ``h_hat`` enters as h_n; both are
    overwritten (``h_hat`` may have a ground row N that collects, never read). Returns −1, or the index of the first body
    with a pivot of D_n (a squared diagonal entry of L) not above ``pivot_min[n]`` (one bound per joint, relative
    to the mass it carries: :func:`projeq.assembly.linalg.mass_scales`).
    """
    N, width, depth = index.shape[0], M_hat.shape[1], F.shape[2]
    n_cols, n_y, parent, s_index = index[:, N_COLS], index[:, N_Y], index[:, PARENT], index[:, S_INDEX]
    rows = _rows
    M_hat[:] = M_n
    dtype = M_hat.dtype  # of the workspace: float, or complex under the complex step
    U, L, f_h = np.zeros((N, width, depth), dtype), np.zeros((N, depth, depth), dtype), np.zeros((N, depth), dtype)
    c, g, MT = np.empty(width, dtype), np.empty(depth, dtype), np.empty((width, max(width, depth)), dtype)
    for n in range(N - 1, -1, -1):  # backward: leaves → root
        M, k, m = M_hat[n], n_cols[n], rows(n_y, n)
        for a in range(m):
            c[a] = h_hat[n, a] - dot_first(M[a], zeta[n], m)
        if k > 0:
            for a in range(m):
                for j in range(k):
                    U[n, a, j] = dot_first(M[a], F[n, :, j], m)
            for i in range(k):
                for j in range(k):
                    L[n, i, j] = dot_first(F[n, :, i], U[n, :, j], m)  # D_n, factored in place
                f_h[n, i] = dot_first(F[n, :, i], h_hat[n], m)
                g[i] = dot_first(F[n, :, i], c, m)
            if not cholesky(L[n], k, pivot_min[n]):
                return n
            cholesky_solve(L[n], k, g)  # D_n⁻¹ F_nᵀ c
            for a in range(m):
                for j in range(k):
                    c[a] -= U[n, a, j] * g[j]
            for j in range(k):  # M̄ = M̂ − (U L⁻ᵀ)(U L⁻ᵀ)ᵀ, one column of U L⁻ᵀ at a time
                for a in range(m):
                    total = U[n, a, j]
                    for i in range(j):
                        total -= MT[a, i] * L[n, j, i]
                    MT[a, j] = total / L[n, j, j]
            for a in range(m):
                for b in range(m):
                    total = 0.0
                    for j in range(k):
                        total += MT[a, j] * MT[b, j]
                    M[a, b] -= total
        p = parent[n]
        if p >= 0 and m == 6 and rows(n_y, p) == 6:
            _add_congruence(T[n], M, c, MT, M_hat[p], h_hat[p])
        elif p >= 0:
            _add_congruence_general(T[n], M, c, MT, m, rows(n_y, p), M_hat[p], h_hat[p])
    y_ddot = np.zeros((N, width), dtype)
    for n in range(N):  # forward: root → leaves
        p, k, m = parent[n], n_cols[n], rows(n_y, n)
        a = y_ddot[n]
        for i in range(m):
            a[i] = zeta[n, i] + (dot_first(T[n, i], y_ddot[p], rows(n_y, p)) if p >= 0 else 0.0)
        if k > 0:
            for j in range(k):
                g[j] = f_h[n, j] - dot_first(U[n, :, j], a, m)
            cholesky_solve(L[n], k, g)
            for j in range(k):
                s_ddot[s_index[n] + j] = g[j]
                for i in range(m):
                    a[i] += F[n, i, j] * g[j]
    return -1


def tree_accelerations(t, index, geometry, inertia, gravity, laws, constants, x, n_q, given, elastic, port, T, zeta,
                       F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, s_ddot):
    """s̈ of the order-n kernel at the time t and the state x = (q, ṡ) (real, or complex for a complex
    step) into s_ddot: :func:`chain_terms`, the loads of the force laws' rows ``laws``, ``constants``
    (:func:`projeq.assembly.loads.add_loads`, bound by :func:`state_kernels`) and :func:`passes`
    on a workspace of x's dtype (T ... twist). For trees whose kinematics the kernel computes
    itself (no joint of kind GIVEN) and whose laws all have compiled rows. Returns −1, or where
    the evaluation failed: the :func:`passes` index of the first singular pivot, or n_x + the row
    of a law that cannot be evaluated (a spring-damper whose points coincide)."""
    chain_terms(index, geometry, inertia, gravity, x[:n_q], x[n_q:], given, elastic, port, T, zeta, F, M_n, h_hat,
                R, r_O, twist)
    if laws.shape[0]:
        q, s_dot = x[:n_q], x[n_q:]
        failed = add_loads(laws, constants, index, t, q, s_dot, q, s_dot, R, r_O, twist, F, T, h_hat)  # noqa: F821
        if failed >= 0:
            return x.shape[0] + failed
    return passes(index, T, zeta, F, M_n, M_hat, h_hat, pivot_min, s_ddot)


def tree_state_derivative(t, index, geometry, inertia, gravity, laws, constants, x, n_q, given, elastic, port, T,
                          zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, x_dot):
    """ẋ = (q̇, s̈) = (ṡ, s̈) at the time t and the real state x = (q, ṡ) into x_dot in one call
    (:func:`tree_accelerations`; q̇ = ṡ by :func:`_rates`: K = E for the trees it takes; with joints of
    kind GIVEN, :func:`projeq.assembly.given.given_state_derivative`), the right-hand side of
    :func:`projeq.simulate` without Python between the kernels. Returns −1, or where the
    evaluation failed (:func:`tree_accelerations`' index) or x or ẋ is not finite: a
    non-negative number (the caller's checked evaluation then raises, naming the cause)."""
    failed = tree_accelerations(t, index, geometry, inertia, gravity, laws, constants, x, n_q, given, elastic, port,
                                T, zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, x_dot[n_q:])
    if failed >= 0:
        return failed
    _rates(index, elastic, given, x, n_q, x_dot)
    for i in range(x.shape[0]):
        if not (np.isfinite(x[i]) and np.isfinite(x_dot[i])):
            return x.shape[0] + laws.shape[0]
    return -1


def _rates(index, elastic, given, x, n_q, x_dot):
    """x_dot[:n_q] ← q̇ = ṡ at x = (q, ṡ) (K = E of every joint); the one-call kernels of trees with
    joints of kind GIVEN take :func:`projeq.assembly.given.given_rates` under this name."""
    for i in range(n_q):
        x_dot[i] = x[n_q + i]


def tree_jacobian(t, index, geometry, inertia, gravity, laws, constants, x, n_q, step, given, elastic, port, T,
                  zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, J):
    """∂s̈/∂x of the order-n kernel at the time t and the real state x = (q, ṡ) by the complex step, column
    k = Im s̈(x + i step e_k) / step (Squire & Trapp, SIAM Review 40, 1998):
    :func:`tree_accelerations` n_x times in one call on a complex workspace (T ... twist:
    complex128); written into J (n_s × n_x). Returns −1, or the first failed evaluation's
    index (:func:`tree_accelerations`)."""
    n_x = x.shape[0]
    z, s_ddot = np.empty(n_x, T.dtype), np.empty(J.shape[0], T.dtype)
    for k in range(n_x):
        z[:] = x
        z[k] += 1j * step
        failed = tree_accelerations(t, index, geometry, inertia, gravity, laws, constants, z, n_q, given, elastic,
                                    port, T, zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, s_ddot)
        if failed >= 0:
            return failed
        for i in range(J.shape[0]):
            J[i, k] = s_ddot[i].imag / step
    return -1


def gauss_form(index, T, zeta, F, M_n, h, M, b):
    """M = Σ J_nᵀ M_n J_n and b = Σ J_nᵀ (M_n ζ̄_n − h_n) of the Gauss form M s̈ + b = 0
    (docs/theory.md §5) from the kernel's T_np, ζ_n, F_n, M_n and h_n, without the dense J_n,
    for bodies with ``n_y[n]`` describing velocities (6, or 6 + n_e for an elastic body).

    b: the Newton–Euler recursion at s̈ = 0 — ζ̄_n = T_np ζ̄_p + ζ_n root → leaves,
    f_n = M_n ζ̄_n − h_n gathered leaves → root (f_p += T_npᵀ f_n), b_n = F_nᵀ f_n. M: the
    composite bodies M^c_n = M_n + Σ_c T_cnᵀ M^c_c T_cn, M_nn = F_nᵀ M^c_n F_n, and for
    each ancestor i of n, M_in = F_iᵀ T_{..i}ᵀ M^c_n F_n with U = M^c_n F_n carried up
    by U ← T_jpᵀ U (Featherstone (2008), *Rigid Body Dynamics Algorithms*, §5.3 and
    §6.2, Tables 5.1 and 6.2). Order N d (d: the tree's depth). Writes M (n × n) and b (n).
    """
    N, width = index.shape[0], M_n.shape[1]
    n_cols, n_y, parent, s_index = index[:, N_COLS], index[:, N_Y], index[:, PARENT], index[:, S_INDEX]
    rows = _rows
    dtype = M.dtype  # of the workspace: float, or complex under the complex step
    zeta_bar, f, M_c = np.zeros((N, width), dtype), np.zeros((N, width), dtype), M_n.copy()
    U, V, MT = np.zeros((width, width), dtype), np.zeros((width, width), dtype), np.empty((width, width), dtype)
    bias_rates(index, T, zeta, zeta_bar)
    for n in range(N):  # f_n
        m = rows(n_y, n)
        for a in range(m):
            f[n, a] = dot_first(M_n[n, a], zeta_bar[n], m) - h[n, a]
    for n in range(N - 1, -1, -1):  # leaves → root: b_n, M^c_p += T_npᵀ M^c_n T_np, f_p += T_npᵀ f_n
        p, m = parent[n], rows(n_y, n)
        for j in range(n_cols[n]):
            b[s_index[n] + j] = dot_first(F[n, :, j], f[n], m)
        if p >= 0 and m == 6 and rows(n_y, p) == 6:
            _add_congruence(T[n], M_c[n], f[n], MT, M_c[p], f[p])
        elif p >= 0:
            _add_congruence_general(T[n], M_c[n], f[n], MT, m, rows(n_y, p), M_c[p], f[p])
    M[:, :] = 0.0
    for n in range(N):
        k, m = n_cols[n], rows(n_y, n)
        if k == 0:
            continue
        for a in range(m):
            for j in range(k):
                U[a, j] = dot_first(M_c[n, a], F[n, :, j], m)
        i = n
        while i >= 0:  # M_in = F_iᵀ U, then U ← T_ipᵀ U
            m_i, p = rows(n_y, i), parent[i]
            for r in range(n_cols[i]):
                for j in range(k):
                    M[s_index[i] + r, s_index[n] + j] = M[s_index[n] + j, s_index[i] + r] = dot_first(F[i, :, r], U[:, j], m_i)
            if p >= 0:
                for a in range(rows(n_y, p)):
                    for j in range(k):
                        V[a, j] = dot_first(T[i, :, a], U[:, j], m_i)
                U[:, :k] = V[:, :k]
            i = p


def bias_rates(index, T, zeta, zeta_bar):
    """zeta_bar ← ζ̄_n = T_np ζ̄_p + ζ_n root → leaves: the bodies' ÿ_n at s̈ = 0 (docs/theory.md §4)."""
    n_y, parent = index[:, N_Y], index[:, PARENT]
    for n in range(index.shape[0]):
        p = parent[n]
        for a in range(_rows(n_y, n)):
            zeta_bar[n, a] = zeta[n, a] + (dot_first(T[n, a], zeta_bar[p], _rows(n_y, p)) if p >= 0 else 0.0)


def projected_accelerations(M_all, b_all, P, pivot_min, M, s_ddot):
    """s̈ = −M⁻¹ b with M = Pᵀ M_all P and b = Pᵀ b_all (shared minimal velocities: ṡ_all = P ṡ,
    B(14) projected once more), M factored by Cholesky in place (``M``: n × n workspace).
    Returns −1, or 0 when a pivot of M (a squared diagonal entry of its factor) is not above
    ``pivot_min``."""
    n_all, n = P.shape
    M[:, :] = 0.0
    s_ddot[:] = 0.0
    _add_congruence_general(P, M_all, b_all, np.empty((n_all, n), M.dtype), n_all, n, M, s_ddot)  # Pᵀ M_all P, Pᵀ b_all
    for i in range(n):
        s_ddot[i] = -s_ddot[i]
    if not cholesky(M, n, pivot_min):
        return 0
    cholesky_solve(M, n, s_ddot)
    return -1


def cholesky(D, k, pivot_min):
    """D[:k, :k] = L Lᵀ in place (L in the lower triangle); False if a pivot L_jj² is not
    above ``pivot_min``."""
    for j in range(k):
        pivot = D[j, j]
        for i in range(j):
            pivot -= D[j, i] * D[j, i]
        if not pivot.real > pivot_min:  # the real part: a complex step leaves the sign where it is
            return False
        D[j, j] = np.sqrt(pivot)
        for i in range(j + 1, k):
            total = D[i, j]
            for l in range(j):
                total -= D[i, l] * D[j, l]
            D[i, j] = total / D[j, j]
    return True


def cholesky_solve(L, k, b):
    """b[:k] ← (L Lᵀ)⁻¹ b[:k] by two triangular solves."""
    for i in range(k):
        total = b[i]
        for l in range(i):
            total -= L[i, l] * b[l]
        b[i] = total / L[i, i]
    for i in range(k - 1, -1, -1):
        total = b[i]
        for l in range(i + 1, k):
            total -= L[l, i] * b[l]
        b[i] = total / L[i, i]


def dot6(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5]


def _rows(n_y, n):
    """n_y of body n (the rows of its M_n, ẏ_n)."""
    return n_y[n]


def _six(n_y, n):
    """n_y = 6 of every body of a rigid tree: :func:`_rows` of the rigid kernel, a constant the
    compiler unrolls the passes' loops over."""
    return 6


def dot_first(a, b, m):
    """Σ a_i b_i over the first m entries (m = 6 unrolled)."""
    if m == 6:
        return dot6(a, b)
    total = 0.0
    for i in range(m):
        total += a[i] * b[i]
    return total


def _add_congruence(T, M, c, MT, M_p, h_p):
    """M_p += Tᵀ M T and h_p += Tᵀ c (T's lower-left block is zero)."""
    for a in range(6):
        for b in range(6):
            MT[a, b] = M[a, 0] * T[0, b] + M[a, 1] * T[1, b] + M[a, 2] * T[2, b] + (
                M[a, 3] * T[3, b] + M[a, 4] * T[4, b] + M[a, 5] * T[5, b])
    for a in range(6):
        rows = 3 if a < 3 else 6  # column a < 3 of T is zero below row 3
        for b in range(6):
            total = 0.0
            for i in range(rows):
                total += T[i, a] * MT[i, b]
            M_p[a, b] += total
        total = 0.0
        for i in range(6):
            total += T[i, a] * c[i]
        h_p[a] += total


def _add_congruence_general(T, M, c, MT, m, m_p, M_p, h_p):
    """M_p += Tᵀ M T and h_p += Tᵀ c for T of m × m_p (an elastic body or its parent)."""
    for a in range(m):
        for b in range(m_p):
            total = 0.0
            for i in range(m):
                total += M[a, i] * T[i, b]
            MT[a, b] = total
    for a in range(m_p):
        for b in range(m_p):
            total = 0.0
            for i in range(m):
                total += T[i, a] * MT[i, b]
            M_p[a, b] += total
        total = 0.0
        for i in range(m):
            total += T[i, a] * c[i]
        h_p[a] += total


def kernel(compiled: bool = True, rigid: bool = False):
    """(chain_terms, passes): compiled by numba (ValueError if it is not installed), or with
    ``compiled=False`` the interpreted functions of this module. ``rigid=True``: the passes
    for trees whose bodies all have n_y = 6, compiled with that size a constant (the same
    source; 1.5–2× faster on chain(100) than with the sizes read per body)."""
    if not compiled:
        return chain_terms, passes
    if not has_numba():
        raise ValueError(
            "compiled: numba is not installed (pip install numba); compiled=False runs the same "
            "kernel interpreted, method='auto' picks the best evaluator available"
        )
    compiled_kernels = _compiled()
    return compiled_kernels["chain_terms"], compiled_kernels["rigid_passes" if rigid else "passes"]


def rows_kinematics(index, geometry, inertia, gravity, q_rows, s_rows, given, elastic, port, T, zeta, F, M, h, R,
                    r_O, twist, bodies, twists, R_rows, r_rows):
    """:func:`chain_terms` at each row (q_rows[k], s_rows[k]) of a run's output, keeping what the rows'
    energies need: every body's twist (twists[k]) and the poses R_n, r_n of ``bodies`` (R_rows[k],
    r_rows[k]); the other arguments are chain_terms' workspace."""
    for k in range(q_rows.shape[0]):
        chain_terms(index, geometry, inertia, gravity, q_rows[k], s_rows[k], given, elastic, port, T, zeta, F, M, h,
                    R, r_O, twist)
        for n in range(twists.shape[1]):
            for i in range(6):
                twists[k, n, i] = twist[n, i]
        for j in range(bodies.shape[0]):
            for i in range(3):
                r_rows[k, j, i] = r_O[bodies[j], i]
                for c in range(3):
                    R_rows[k, j, i, c] = R[bodies[j], i, c]


def rows_kernel(compiled: bool = True):
    """:func:`rows_kinematics`, compiled by numba (as :func:`kernel`, calling its compiled chain_terms)
    or with ``compiled=False`` the interpreted function."""
    if not compiled:
        return rows_kinematics
    kernel(True)  # the same refusal without numba
    return _compiled_rows_kernel()


@functools.cache
def _compiled_rows_kernel():
    return jit(rows_kinematics, kernels={"chain_terms": _compiled()["chain_terms"]})[0]


def state_kernels(loads, compiled: bool = True, rigid: bool = False):
    """(:func:`tree_state_derivative`, :func:`tree_jacobian`), compiled by numba (as :func:`kernel`,
    with the same ``rigid`` passes) or with ``compiled=False`` interpreted, calling the force laws'
    loop ``add_loads`` of ``loads`` (the module :mod:`projeq.assembly.loads`, compiled or
    interpreted alike; it imports this module, so the caller hands it in) by name, as the
    compiled kernels call each other (:func:`_jit`)."""
    if not compiled:
        namespace = {**globals(), "add_loads": loads.add_loads}
        namespace["tree_accelerations"] = types.FunctionType(tree_accelerations.__code__, namespace)
        return tuple(types.FunctionType(f.__code__, namespace, f.__name__) for f in (tree_state_derivative,
                                                                                       tree_jacobian))
    kernel(True)  # the same refusal without numba
    return _compiled_state_kernels(loads)["rigid" if rigid else "general"]


_CALLEES = (_relative_rotation, chain_matrix_into, add_cross, add_motion_cross, _rigid_h, dot6, dot_first, _rows, bias_rates,
            _add_congruence, _add_congruence_general, cholesky, cholesky_solve, _image, elastic_body, rotary_body,
            port_motion, hub_motion, _rates)


@functools.cache
def _compiled():
    """{name: kernel}: chain_terms, passes and the rigid trees' passes (:func:`kernel`) compiled by
    numba, once per process (and cached on disk; numba compiles each for the dtype it is called
    with, float64 or complex128, on first use)."""
    chain, general = _jit(chain_terms, passes)
    rigid = _jit(passes, names=("rigid_passes",), _rows=_six)[0]
    return {"chain_terms": chain, "passes": general, "rigid_passes": rigid}


@functools.cache
def _compiled_state_kernels(loads):
    """{"general" | "rigid": (tree_state_derivative, tree_jacobian)} with either passes
    (:func:`state_kernels`), calling the compiled chain_terms, passes and loads loop; cached on
    disk as :func:`jit` caches (under a digest that sees the loads loop's edits: a cached kernel
    holds the code of those it calls)."""
    compiled = _compiled()
    found = {}
    for variant, passes_ in (("general", compiled["passes"]), ("rigid", compiled["rigid_passes"])):
        callees = {"chain_terms": compiled["chain_terms"], "passes": passes_, "add_loads": loads.kernel(True)}
        prefix = "" if variant == "general" else "rigid_"
        found[variant] = jit(tree_state_derivative, tree_jacobian, callees=(tree_accelerations,), kernels=callees,
                             names=(f"{prefix}tree_state_derivative", f"{prefix}tree_jacobian"))
    return found


def gauss_form_kernel(compiled: bool = True, rigid: bool = False):
    """(:func:`gauss_form`, :func:`projected_accelerations`), compiled by numba (as
    :func:`kernel`, with the same ``rigid`` variant: n_y = 6 a constant; ValueError without
    numba) or with ``compiled=False`` the interpreted functions."""
    if not compiled:
        return gauss_form, projected_accelerations
    kernel(True)  # the same refusal without numba
    return _compiled_gauss_form(rigid)


def hub_beam_kernel(compiled: bool = True):
    """:func:`hub_beam`, compiled by numba (as :func:`kernel`; ValueError without it) or with
    ``compiled=False`` the interpreted function."""
    if not compiled:
        return hub_beam
    kernel(True)  # the same refusal without numba
    return _compiled_hub_beam()[0]


def hub_beam_jacobian_kernel(compiled: bool = True):
    """:func:`hub_beam_jacobian`, compiled by numba (as :func:`kernel`) or with ``compiled=False``
    the interpreted function."""
    if not compiled:
        return hub_beam_jacobian
    kernel(True)  # the same refusal without numba
    return _compiled_hub_beam()[1]


@functools.cache
def _compiled_hub_beam():
    kernel = _jit(hub_beam)[0]
    return kernel, _jit(hub_beam_jacobian, kernels={"hub_beam": kernel})[0]


@functools.cache
def _compiled_gauss_form(rigid: bool):
    if rigid:
        return _jit(gauss_form, names=("rigid_gauss_form",), _rows=_six)[0], _compiled_gauss_form(False)[1]
    return _jit(gauss_form, projected_accelerations)


def jit(*functions, callees=(), kernels=None, names=None, **replaced):
    """``functions`` compiled by numba as this module's kernels are (:func:`_jit`): with their
    module's names, this module's callees, ``callees`` (the plain functions they call besides,
    compiled with them) and the compiled ``kernels`` they call by name. numba's disk cache checks
    the file of a compiled function only, so each is cached under its name (or that of
    ``names``: one function compiled twice with other kernels) and a digest (:func:`_digest`) of
    this module's source, its callees' and its compiled kernels' (the source of their modules —
    their constants too — and their names, which carry the digest of their own callees): an
    edit to any, in another file than the function's, compiles it anew. ``replaced``: another
    function under a callee's name (:func:`_jit`), for a variant of the same source."""
    compiled = [k.py_func for k in (kernels or {}).values() if hasattr(k, "py_func")]
    modules = dict.fromkeys(sys.modules[f.__module__] for f in compiled)
    digest = _digest(*callees, *modules, names="".join(f.__qualname__ for f in compiled))
    return _jit(*functions, names=tuple(f"{name}_{digest}" for name in names or [f.__name__ for f in functions]),
                callees=callees, kernels=kernels, **replaced)


def _digest(*sources, names: str = "") -> str:
    """12 hex digits of SHA-1 over this module's source, those of ``sources`` (functions or
    modules) and ``names``."""
    text = Path(__file__).read_text() + "".join(inspect.getsource(f) for f in sources) + names
    return hashlib.sha1(text.encode()).hexdigest()[:12]


def _jit(*functions, names=(), callees=(), kernels=None, **replaced):
    """The ``functions`` compiled by numba (cached on disk, under ``names`` if given).

    Compiled code resolves the functions it calls in its globals, so the functions are
    compiled as copies whose globals are a copy of this module's namespace (and of the
    functions' own module's) holding numba's versions of their callees (``replaced``: another
    function under a callee's name, as :func:`_six` for ``_rows`` in the rigid passes;
    ``callees``: more of them) and the compiled ``kernels`` they call by name (the Jacobians
    call the kernels' own dispatchers: each specialization is compiled once, and shared);
    the functions stay plain Python (nothing rebound)."""
    numba = _numba()
    namespace = {**globals(), **functions[0].__globals__}

    def rebound(f, name=None):
        copy = types.FunctionType(f.__code__, namespace, name or f.__name__, f.__defaults__, f.__closure__)
        copy.__qualname__ = name or f.__qualname__  # numba's disk cache is keyed by it
        return copy

    for f in _CALLEES + callees:
        namespace[f.__name__] = numba.extending.register_jitable(rebound(replaced.get(f.__name__, f)))
    namespace.update(kernels or {})
    jit = numba.njit(cache=True)
    return tuple(jit(rebound(f, name)) for f, name in zip(functions, names or (None,) * len(functions)))

"""An independent derivation of the Whipple bicycle with sympy.physics.mechanics.KanesMethod.

Used by the tests and by ``benchmarks/bicycle_effort.py`` to check projeq's bicycle
(``projeq.scenes.bicycle``), which is built on a different route: Projection Equation of a
tree, constraints as equations resolved by coordinate partitioning. Here, as in Kane &
Levinson's and Moore's treatment:

- coordinates q1 yaw, q2 roll, q3 pitch, q4 rear wheel, q5 steer, q6 front wheel (the rear
  contact's position is ignorable and left out), speeds u_i = q̇_i;
- the rear no-slip condition is built into the velocities (the rear wheel's material
  contact point dn is at rest: every velocity is carried from it by the two-point formula);
- ``KanesMethod`` forms Kane's equations Fr + Fr* = 0 in the six speeds, M(q) u̇ = f(q, u);
- the front no-slip condition, three components of the front contact's velocity
  V(q) u = 0, makes u1, u3, u6 dependent: u_dep = A_rs u_ind. It enters through Kane's
  nonholonomic generalized forces, F̃_r = F_r + Σ_s F_s A_sr (Kane & Levinson,
  Dynamics: Theory and Applications, 1985), evaluated numerically: Cᵀ(f − M u̇) = 0 with C = ∂u/∂u_ind, completed by
  V u̇ = −V̇ u. (Handing the constraints to ``KanesMethod`` itself, which eliminates the
  dependent speeds symbolically, gave 1.45 million operations and 4–5 times the
  derivation time here; this way it is 1e5 operations.) The front contact's height is the
  configuration constraint that fixes q3;
- gravity on the four mass centres; MJPR's Table 1 geometry (x forward, z down).

The equations are linearised numerically about upright straight running at speed v:
q3 is solved from the configuration constraint, u1, u3, u6 from the velocity constraints,
and u̇ as above; the Jacobian of (q̇2, q̇5, u̇2, u̇5) by (q2, q5, u2, u5) at constant
u4 = −v/r_R is taken by Richardson-extrapolated central differences (the scheme of
``projeq.linearize``, applied to different equations).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.optimize
import sympy as sp
import sympy.physics.mechanics as me

PARAMETERS = ("w", "c", "lam", "g", "r_R", "m_R", "I_Rxx", "I_Ryy", "x_B", "z_B", "m_B", "I_Bxx", "I_Byy",
              "I_Bzz", "I_Bxz", "x_H", "z_H", "m_H", "I_Hxx", "I_Hyy", "I_Hzz", "I_Hxz", "r_F", "m_F",
              "I_Fxx", "I_Fyy")


@dataclass
class KaneBicycle:
    """The lambdified Kane model: the front contact's height ``holonomic(q)``, the front
    no-slip rows ``velocity_jacobian(q)`` = V and ``velocity_rate(q, u)`` = V̇ u,
    ``mass_matrix(q)`` and ``forcing(q, u)`` of Kane's M(q) u̇ = f(q, u) in all six
    speeds, and the derivation's cost (seconds, ``sympy.count_ops`` if requested)."""

    holonomic: object
    velocity_jacobian: object
    velocity_rate: object
    mass_matrix: object
    forcing: object
    derivation_seconds: float
    operations: int


def derive(values: dict, stages: dict | None = None, count: bool = False) -> KaneBicycle:
    """Kane's equations of the Whipple bicycle (see the module docstring) with the
    parameters ``values`` ({name: float}, names ``PARAMETERS``) as numbers from the start
    (smaller expressions); ``stages`` receives the cumulative seconds after each stage,
    ``count`` adds the operation count."""
    started = time.perf_counter()
    stages = {} if stages is None else stages
    q = me.dynamicsymbols("q1:7")
    u = me.dynamicsymbols("u1:7")
    P = {k: sp.Float(values[k]) for k in PARAMETERS}
    N = me.ReferenceFrame("N")
    A = N.orientnew("A", "Axis", [q[0], N.z])  # yaw
    B = A.orientnew("B", "Axis", [q[1], A.x])  # roll
    C = B.orientnew("C", "Axis", [q[2], B.y])  # pitch: the rear frame
    D = C.orientnew("D", "Axis", [q[3], C.y])  # rear wheel
    e_s = sp.sin(P["lam"]) * C.x + sp.cos(P["lam"]) * C.z  # steer axis, pointing down
    E = C.orientnew("E", "Axis", [q[4], e_s])  # fork
    F = E.orientnew("F", "Axis", [q[5], E.y])  # front wheel
    for frame, parent, axis, k in ((A, N, N.z, 0), (B, A, A.x, 1), (C, B, B.y, 2), (D, C, C.y, 3),
                                   (E, C, e_s, 4), (F, E, E.y, 5)):
        frame.set_ang_vel(parent, u[k] * axis)

    dn = me.Point("dn")  # rear wheel's material contact point, at rest (rolling)
    dn.set_vel(N, 0)
    do = dn.locatenew("do", -P["r_R"] * B.z)
    bo = do.locatenew("bo", P["x_B"] * C.x + (P["z_B"] + P["r_R"]) * C.z)
    ce = do.locatenew("ce", (P["w"] + P["c"]) * C.x + P["r_R"] * C.z)  # steer axis at the ground
    fo = ce.locatenew("fo", -P["c"] * E.x - P["r_F"] * E.z)
    ho = ce.locatenew("ho", (P["x_H"] - P["w"] - P["c"]) * E.x + P["z_H"] * E.z)
    down = E.y.cross(A.z.cross(E.y))
    fn = fo.locatenew("fn", P["r_F"] * down / sp.sqrt(1 - me.dot(A.z, E.y) ** 2))
    do.v2pt_theory(dn, N, D)
    for point, base, frame in ((bo, do, C), (ce, do, C), (fo, ce, E), (ho, ce, E), (fn, fo, F)):
        point.v2pt_theory(base, N, frame)

    holonomic = me.dot(fn.pos_from(dn), A.z)
    v_fn = fn.vel(N)
    velocity = sp.Matrix([me.dot(v_fn, A.x), me.dot(v_fn, A.y), me.dot(v_fn, A.z)])
    bodies = [
        me.RigidBody("R", do, D, P["m_R"], (me.inertia(D, P["I_Rxx"], P["I_Ryy"], P["I_Rxx"]), do)),
        me.RigidBody("B", bo, C, P["m_B"], (me.inertia(C, P["I_Bxx"], P["I_Byy"], P["I_Bzz"], 0, 0, P["I_Bxz"]), bo)),
        me.RigidBody("H", ho, E, P["m_H"], (me.inertia(E, P["I_Hxx"], P["I_Hyy"], P["I_Hzz"], 0, 0, P["I_Hxz"]), ho)),
        me.RigidBody("F", fo, F, P["m_F"], (me.inertia(F, P["I_Fxx"], P["I_Fyy"], P["I_Fxx"]), fo)),
    ]
    loads = [(body.masscenter, body.mass * P["g"] * N.z) for body in bodies]
    kane = me.KanesMethod(N, q_ind=list(q), u_ind=list(u), kd_eqs=[q[k].diff() - u[k] for k in range(6)])
    stages["kinematics"] = time.perf_counter() - started
    kane.kanes_equations(bodies, loads)
    M, f = kane.mass_matrix, kane.forcing
    stages["kanes_equations"] = time.perf_counter() - started
    u_vec = sp.Matrix(u)
    V = velocity.jacobian(u_vec)
    rates = {qi.diff(): ui for qi, ui in zip(q, u)}
    V_dot_u = (V.diff(me.dynamicsymbols._t) * u_vec).xreplace(rates)  # V̇ u (u̇ terms: V u̇)
    q, u = list(q), list(u)
    model = KaneBicycle(
        holonomic=sp.lambdify([q], holonomic, cse=True),
        velocity_jacobian=sp.lambdify([q], V, cse=True),
        velocity_rate=sp.lambdify([q, u], V_dot_u, cse=True),
        mass_matrix=sp.lambdify([q], M, cse=True),
        forcing=sp.lambdify([q, u], f, cse=True),
        derivation_seconds=0.0,
        operations=0,
    )
    stages["lambdify"] = time.perf_counter() - started
    model.derivation_seconds = stages["lambdify"]
    if count:
        model.operations = int(sp.count_ops(M) + sp.count_ops(f) + sp.count_ops(V) + sp.count_ops(V_dot_u))
        stages["count_ops"] = time.perf_counter() - started
    return model


INDEPENDENT, DEPENDENT = [1, 3, 4], [0, 2, 5]  # u2 roll, u4 rear wheel, u5 steer; u1 yaw, u3 pitch, u6 front wheel


def pitch(model: KaneBicycle, roll: float, steer: float) -> float:
    """q3 from the configuration constraint (front contact on the ground), Brent in ±0.5 rad."""
    def height(q3):
        return model.holonomic([0.0, roll, q3, 0.0, steer, 0.0])

    return scipy.optimize.brentq(height, -0.5, 0.5, xtol=1e-15)


def accelerations(model: KaneBicycle, q: np.ndarray, u_ind: np.ndarray) -> np.ndarray:
    """u̇ of the constrained bicycle at q (q3 consistent) and the independent speeds.

    Kane's equations with non-holonomic constraints: with u_dep = A_rs u_ind
    (A_rs = −V_dep⁻¹ V_ind from the front no-slip rows V u = 0) the nonholonomic
    generalized forces are Cᵀ(f − M u̇) = 0 with C = ∂u/∂u_ind = [E; A_rs] (rows permuted),
    completed by the differentiated constraints V u̇ = −V̇ u."""
    V = np.asarray(model.velocity_jacobian(q), dtype=float)
    A_rs = -np.linalg.solve(V[:, DEPENDENT], V[:, INDEPENDENT])
    C = np.zeros((6, 3))
    C[INDEPENDENT], C[DEPENDENT] = np.eye(3), A_rs
    u = C @ u_ind
    M = np.asarray(model.mass_matrix(q), dtype=float)
    f = np.asarray(model.forcing(q, u), dtype=float).ravel()
    V_dot_u = np.asarray(model.velocity_rate(q, u), dtype=float).ravel()
    return np.linalg.solve(np.vstack((C.T @ M, V)), np.concatenate((C.T @ f, -V_dot_u)))


def lateral_state_matrix(model: KaneBicycle, speed: float, r_R: float) -> np.ndarray:
    """Jacobian of (q̇2, q̇5, u̇2, u̇5) by x = (q2, q5, u2, u5) at x = 0, u4 = −v/r_R."""
    from projeq.analysis.differentiation import jacobian

    def x_dot(x):
        roll, steer, roll_rate, steer_rate = x
        q = np.array([0.0, roll, pitch(model, roll, steer), 0.0, steer, 0.0])
        u_dot = accelerations(model, q, np.array([roll_rate, -speed / r_R, steer_rate]))
        return np.array([roll_rate, steer_rate, u_dot[1], u_dot[4]])

    return jacobian(x_dot, np.zeros(4))


def eigenvalues(model: KaneBicycle, speed: float, r_R: float) -> np.ndarray:
    """The four roll/steer eigenvalues of upright straight running at ``speed``."""
    return np.linalg.eigvals(lateral_state_matrix(model, speed, r_R)).astype(complex)


def stability_limits(eigenvalues_at) -> tuple[float, float]:
    """(weave speed, capsize speed): where the oscillatory pair's real part and the
    capsize (real, near zero) eigenvalue's real part cross zero, by Brent's method
    in the brackets [3, 5] and [5.5, 7] m/s (for MJPR's benchmark bicycle)."""
    def weave(v):
        lam = eigenvalues_at(v)
        return lam[np.abs(lam.imag) > 1e-9].real.max()

    def capsize(v):
        lam = eigenvalues_at(v)
        return lam[np.abs(lam.imag) <= 1e-9].real.max()

    return (scipy.optimize.brentq(weave, 3.0, 5.0, xtol=1e-10),
            scipy.optimize.brentq(capsize, 5.5, 7.0, xtol=1e-10))

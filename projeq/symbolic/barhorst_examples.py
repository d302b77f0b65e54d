"""Barhorst's three examples in every input form his formulation study needs, from one kinematic source.

A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems — another perspective on the
canonical equations of motion", §3: the particle with ẏ − y² ẋ = 0 (§3.1), the disk rolling without
slip with an eccentric mass (§3.2) and the planar quick-return mechanism (§3.3). Each :class:`Example`
holds the bodies' poses r(q), R(q) in the inertial frame N, the potential V and the constraints
A(q) q̇ = 0; from them come

* L = T − V and A for the multiplier forms (Hamilton's canonical equations with multipliers, his eq. 7)
  and the Lagrangian canonical form (eqs. 45–52): :meth:`Example.multiplier_system`;
* the bodies' velocities in speeds u with q̇ = K u for the projective forms (Kane's form with dependent
  speeds, eqs. 15–16, i.e. the Projection Equation, and the projective canonical form, eqs. 28–37):
  :meth:`Example.bodies`, each body in its own frame (v = Rᵀṙ, ω̃ = RᵀṘ, ω_IR = ω).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cache

import numpy as np
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from .algebra import rotation_x, rotation_y, rotation_z, trig_normal
from .lagrange import MultiplierSystem, multiplier_system
from .projection import Body, t

__all__ = ["Example", "PoseBody", "barhorst_particle", "rolling_disk", "quick_return"]


@dataclass(frozen=True)
class PoseBody:
    """A body by its mass centre r(q) and orientation R(q) (body → N; None: a point mass), mass ``m``,
    central inertia ``I_c`` in the body frame, a non-potential force ``f`` in N at the mass centre and
    torque ``M`` in the body frame (expressions in q, q̇); gravity is the example's. ``omega``: the
    angular velocity in the body frame in q, q̇ (default: from ω̃ = RᵀṘ, each entry in the
    sin² + cos² = 1 normal form of :func:`~projeq.symbolic.algebra.trig_normal`, the expressions
    trigsimp gives in a fraction of its time; the examples give Barhorst's own expressions)."""

    m: object
    r: sp.Matrix
    R: sp.Matrix | None = None
    I_c: sp.Matrix = field(default_factory=lambda: sp.zeros(3, 3))
    f: sp.Matrix = field(default_factory=lambda: sp.zeros(3, 1))
    M: sp.Matrix = field(default_factory=lambda: sp.zeros(3, 1))
    omega: sp.Matrix | None = None


@dataclass(frozen=True)
class Example:
    """One of Barhorst's examples: coordinates ``q``, rates ``q_dot`` (plain symbols), ``bodies``
    (:class:`PoseBody`), the ``gravity`` vector in N, velocity constraints A(q) q̇ = 0 (``A``), position
    constraints Φ(q) = 0 whose Jacobian is A (``phi``, holonomic examples only), ``values`` of the
    parameters."""

    name: str
    q: tuple
    q_dot: tuple
    bodies: tuple
    gravity: sp.Matrix
    A: sp.Matrix
    values: dict
    phi: sp.Matrix | None = None

    def _rates(self, body: PoseBody):
        """(ṙ in N, ω in the body frame) in q, q̇."""
        r_dot = body.r.jacobian(self.q) * sp.Matrix(self.q_dot)
        if body.R is None:
            return r_dot, sp.zeros(3, 1)
        if body.omega is not None:
            return r_dot, sp.Matrix(body.omega)
        R_dot = sum((body.R.diff(qi) * qd for qi, qd in zip(self.q, self.q_dot)), sp.zeros(3, 3))
        W = (body.R.T * R_dot).applyfunc(lambda e: trig_normal(e, self.q))
        return r_dot, sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])

    @property
    def V(self) -> sp.Expr:
        """V = −Σ m g·r (Barhorst eqs. 61, 102, 110)."""
        return -sum((body.m * self.gravity.dot(body.r) for body in self.bodies), sp.S.Zero)

    @property
    def T(self) -> sp.Expr:
        """T = Σ ½ m ṙ·ṙ + ½ ωᵀ I_c ω (Barhorst eqs. 60, 101, 111)."""
        T = sp.S.Zero
        for body in self.bodies:
            r_dot, omega = self._rates(body)
            T += body.m * r_dot.dot(r_dot) / 2 + (omega.T * body.I_c * omega)[0] / 2
        return T

    def generalized_forces(self) -> sp.Matrix:
        """Q = Σ (∂ṙ/∂q̇)ᵀ f + (∂ω/∂q̇)ᵀ M (Barhorst eq. 2) of the non-potential loads."""
        Q = sp.zeros(len(self.q), 1)
        for body in self.bodies:
            r_dot, omega = self._rates(body)
            Q += r_dot.jacobian(self.q_dot).T * body.f + omega.jacobian(self.q_dot).T * body.M
        return Q

    def multiplier_system(self) -> MultiplierSystem:
        """L = T − V, Q and A q̇ = 0 in q(t) for :func:`projeq.symbolic.multiplier_system`."""
        q_t = dynamicsymbols([str(qi) for qi in self.q])
        to_t = {**dict(zip(self.q_dot, [qi.diff(t) for qi in q_t])), **dict(zip(self.q, q_t))}
        L, Q, A = ((self.T - self.V).xreplace(to_t), self.generalized_forces().xreplace(to_t),
                   self.A.xreplace(to_t))
        return multiplier_system(L, q_t, t, A=A, Q=Q, parameters=self.values)

    def bodies_in(self, u, K) -> list[Body]:
        """The bodies for the projective forms with speeds ``u`` and q̇ = K u: v = Rᵀṙ, ω, f + m g, M in
        each body's frame (R turning with ω, B(10); a point mass in N)."""
        on_u = dict(zip(self.q_dot, sp.Matrix(K) * sp.Matrix(u)))
        out = []
        for body in self.bodies:
            r_dot, omega = self._rates(body)
            R = sp.eye(3) if body.R is None else body.R
            out.append(Body(v_c=(R.T * r_dot).xreplace(on_u), omega=omega.xreplace(on_u),
                            m=body.m, I_c=body.I_c, f=(R.T * (body.f + body.m * self.gravity)).xreplace(on_u), M=body.M.xreplace(on_u),
                            omega_IR=omega.xreplace(on_u)))
        return out

    def energy_function(self):
        """E(q, q̇) = T + V, compiled: the one energy every formulation is measured with."""
        E = (self.T + self.V).xreplace({k: sp.Float(v) for k, v in self.values.items()})
        return sp.lambdify([self.q, self.q_dot], E, modules="numpy", cse=True)

    def constraint_function(self):
        """(A q̇, Φ(q) or None), compiled: the velocity and position constraint residuals."""
        numbers = {k: sp.Float(v) for k, v in self.values.items()}
        velocity = sp.lambdify([self.q, self.q_dot], (self.A * sp.Matrix(self.q_dot)).xreplace(numbers),
                               modules="numpy")
        position = None if self.phi is None else sp.lambdify([self.q], self.phi.xreplace(numbers), modules="numpy")
        return velocity, position


m, g = sp.symbols("m g", positive=True)


@cache
def barhorst_particle() -> Example:
    """§3.1: a particle of mass m in the x–y plane under gravity −g n̂2 with ẏ − y² ẋ = 0 (53),
    m = 1, g = 10 (his run from (2, 2) at rest)."""
    x, y = q = sp.symbols("x y")
    q_dot = sp.symbols("x_dot y_dot")
    body = PoseBody(m, sp.Matrix([x, y, 0]))
    return Example("barhorst_particle", q, q_dot, (body,), sp.Matrix([0, -g, 0]), sp.Matrix([[-y**2, 1]]),
                   {m: 1.0, g: 10.0})


R_disk, m_r, m_s, I_d, J_d, ecc_h, ecc_e, ecc_r, T_f = sp.symbols("R m_r m_s I J h e r T_f")


def disk_speeds(q, q_dot) -> sp.Matrix:
    """Barhorst's general speeds (93): u1..u3 the disk's angular velocity in its frame C, u4 = q̇4, u5 = q̇5."""
    q2, q3 = q[1], q[2]
    d1, d2, d3, d4, d5 = q_dot
    return sp.Matrix([d2 * sp.cos(q3) - d1 * sp.cos(q2) * sp.sin(q3), sp.sin(q2) * d1 + d3,
                      sp.cos(q2) * sp.cos(q3) * d1 + sp.sin(q3) * d2, d4, d5])


@cache
def rolling_disk(m_disk: float = 0.030, radius: float = 0.015, m_ecc: float = 0.001, I: float | None = None,
                 J: float | None = None, ecc=None, g_value: float = 9.81, drag: float = 0.0) -> Example:
    """§3.2 (eqs. 88–105): the disk (mass m_r, radius R, inertia diag(I, J, I) in C, J about its axis ĉ2)
    rolling without slip, with an eccentric point mass m_s at (h, e, r) in C from the centre and the air
    drag torque −T_f (u_i |u_i|) about C's axes (104). q = (q1 heading, q2 tilt, q3 roll, q4, q5 contact
    point), C = R_z(q1) R_x(q2) R_y(q3), centre at (q4, q5, 0) + R b̂3 (99), constraints (97)
    q̇4 − R cos q1 q̇3 = 0, q̇5 − R sin q1 q̇3 = 0. Defaults: projeq's scene ``rolling_disk`` (his values
    in SI, a uniform disk I = m R²/4, J = m R²/2, m_s at r = 0.95 R, e = h = 0)."""
    q = sp.symbols("q1:6")
    q_dot = sp.symbols("q1_dot q2_dot q3_dot q4_dot q5_dot")
    q1, q2, q3, q4, q5 = q
    B = rotation_z(q1) * rotation_x(q2)
    C = B * rotation_y(q3)
    r_G = sp.Matrix([q4, q5, 0]) + R_disk * B[:, 2]
    r_s = r_G + C * sp.Matrix([ecc_h, ecc_e, ecc_r])
    omega_C = disk_speeds(q, q_dot)[:3, :]
    drag_torque = -T_f * omega_C.applyfunc(lambda w: w * sp.Abs(w))
    disk = PoseBody(m_r, r_G, C, sp.diag(I_d, J_d, I_d), M=drag_torque, omega=omega_C)
    mass = PoseBody(m_s, r_s, None)
    A = sp.Matrix([[0, 0, -R_disk * sp.cos(q1), 1, 0], [0, 0, -R_disk * sp.sin(q1), 0, 1]])
    ecc = (0.0, 0.0, 0.95 * radius) if ecc is None else ecc
    values = {R_disk: radius, m_r: m_disk, m_s: m_ecc, I_d: m_disk * radius**2 / 4 if I is None else I,
              J_d: m_disk * radius**2 / 2 if J is None else J, ecc_h: ecc[0], ecc_e: ecc[1], ecc_r: ecc[2],
              g: g_value, T_f: drag}
    return Example("rolling_disk", q, q_dot, (disk, mass), sp.Matrix([0, 0, -g]), A, values)


def disk_kinematics(speeds: str):
    """(u, K) with q̇ = K u for the disk: ``"body"`` u = (u1, u2, u3) of eq. (93) with K of (95)–(97);
    ``"q_dot"`` u = (q̇1, q̇2, q̇3) (Barhorst §3.2.3)."""
    q1, q2, q3 = sp.symbols("q1:4")
    u = sp.symbols("u1:4")
    if speeds == "body":
        c2, s3, c3, t2 = sp.cos(q2), sp.sin(q3), sp.cos(q3), sp.tan(q2)
        rates = sp.Matrix([[-s3 / c2, 0, c3 / c2], [c3, 0, s3], [s3 * t2, 1, -c3 * t2]])
    elif speeds == "q_dot":
        rates = sp.eye(3)
    else:
        raise ValueError(f"speeds: expected 'body' or 'q_dot', got {speeds!r}")
    return u, sp.Matrix.vstack(rates, R_disk * sp.cos(q1) * rates[2, :], R_disk * sp.sin(q1) * rates[2, :])


A_len, H_len, m_a, m_b, T_m, T_d = sp.symbols("A H m_a m_b T_m T_d")


@cache
def quick_return(torques: bool = False) -> Example:
    """§3.3 (Fig. 9, eqs. 106–111): crank (mass m_a, length H) about a_o at the origin, angle q1;
    slotted follower (mass m_b, length B = A + 1.5 H) about b_o = (A, 0), angle q2; the crank pin at q3
    along the slot (massless slider). Both links uniform slender rods (centroidal moments m L²/12, as
    projeq's scene ``quick_return``; the paper leaves A_i33, B_i33 open). Loop Φ = (c1, c2) of (107),
    A = ∂Φ/∂q (108); gravity along −n̂2, V of (110). ``torques``: the motor torque T_m on the crank
    and the load torque T_d on the follower as symbols (valued 0, his run; else left out)."""
    q = sp.symbols("q1:4")
    q_dot = sp.symbols("q1_dot q2_dot q3_dot")
    q1, q2, q3 = q
    B_len = A_len + sp.Rational(3, 2) * H_len
    crank = PoseBody(m_a, H_len / 2 * sp.Matrix([sp.cos(q1), sp.sin(q1), 0]), rotation_z(q1),
                     sp.diag(0, 0, m_a * H_len**2 / 12), M=sp.Matrix([0, 0, T_m if torques else 0]),
                     omega=sp.Matrix([0, 0, q_dot[0]]))
    follower = PoseBody(m_b, sp.Matrix([A_len, 0, 0]) + B_len / 2 * sp.Matrix([sp.cos(q2), sp.sin(q2), 0]),
                        rotation_z(q2), sp.diag(0, 0, m_b * B_len**2 / 12), M=sp.Matrix([0, 0, T_d if torques else 0]),
                        omega=sp.Matrix([0, 0, q_dot[1]]))
    phi = sp.Matrix([A_len - H_len * sp.cos(q1) + q3 * sp.cos(q2), q3 * sp.sin(q2) - H_len * sp.sin(q1)])
    values = {A_len: 1.0, H_len: 1.0 / 3.0, m_a: 0.5, m_b: 1.0, g: 9.81, **({T_m: 0.0, T_d: 0.0} if torques else {})}
    return Example("quick_return", q, q_dot, (crank, follower), sp.Matrix([0, -g, 0]), phi.jacobian(q), values, phi)


def quick_return_start(values: dict | None = None) -> np.ndarray:
    """Barhorst's initial configuration q1 = 9π/20, q2 = 2.80729, q3 = 1.0034 (Fig. 9, printed to 5
    digits) with (q2, q3) solved from the loop Φ = 0 at that q1 (his energy 3.22155 J at rest)."""
    values = values or quick_return().values
    A, H = values[A_len], values[H_len]
    q1 = 9 * np.pi / 20
    x, y = H * np.cos(q1) - A, H * np.sin(q1)  # the pin seen from b_o
    return np.array([q1, np.arctan2(y, x), np.hypot(x, y)])

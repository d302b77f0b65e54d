"""The knife-edge disc and Barhorst's particle in the input forms of the Lagrange/Hamilton and
canonical modules (for the tests, the formulation benchmark and comparisons).

Same bodies as projeq's scenes ``knife_edge_disc`` (Orsino (2020) slides 28–37) and
``barhorst_particle`` (Barhorst §3.1), written as L, A for :func:`multiplier_system` and as
bodies for :func:`projective_canonical`.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from .canonical import CanonicalForm, projective_canonical
from .lagrange import MultiplierSystem, multiplier_system
from .projection import Body, t

__all__ = ["DISC_UNITS", "central_disc", "hamel_disc", "lecture_disc", "lecture_disc_state", "particle",
           "projection_disc", "projective_disc"]

m, g, r, I, J = sp.symbols("m g r I J", positive=True)
DISC_UNITS = {m: 1.0, g: 1.0, r: 1.0, I: 0.25, J: 0.5}  # the scene's defaults: μ = 1/4, ν = 1/2


def _disc_K(q) -> sp.Matrix:
    """q̇ = K u for q = (x, y, z, ψ, ϕ, θ), u = (ψ̇, ϕ̇, θ̇): slide 30's A q̇ = 0 solved for ẋ, ẏ, ż."""
    s, c, psi, phi = sp.sin, sp.cos, q[3], q[4]
    return sp.Matrix([[-r * c(psi) * s(phi), -r * c(phi) * s(psi), -r * c(psi)],
                      [-r * s(psi) * s(phi), r * c(psi) * c(phi), -r * s(psi)],
                      [0, r * s(phi), 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])


@cache
def lecture_disc() -> MultiplierSystem:
    """Slides 29–31: q = (x, y, z, ψ, ϕ, θ) of the centre G and the angles, n̂z down, L = T + m g z,
    rolling constraints A q̇ = 0 (slide 30, including the integrable ż − r ϕ̇ sϕ = 0)."""
    x, y, z, psi, phi, th = q = dynamicsymbols("x y z psi phi theta")
    d, s, c = (lambda f: f.diff(t)), sp.sin, sp.cos
    L = (m * (d(x) ** 2 + d(y) ** 2 + d(z) ** 2) + I * d(psi) ** 2 * c(phi) ** 2 + I * d(phi) ** 2
         + J * (d(th) + d(psi) * s(phi)) ** 2) / 2 + m * g * z
    A = [[1, 0, 0, r * c(psi) * s(phi), r * c(phi) * s(psi), r * c(psi)],
         [0, 1, 0, r * s(psi) * s(phi), -r * c(psi) * c(phi), r * s(psi)],
         [0, 0, 1, 0, -r * s(phi), 0]]
    return multiplier_system(L, q, t, A=A, parameters=DISC_UNITS)


def lecture_disc_state(system) -> tuple[np.ndarray, np.ndarray]:
    """(q, q̇) in the lecture's six coordinates from the scene's initial state (z = −r cos ϕ, r = 1)."""
    q, q_dot = system.q0, system.q_dot(system.q0, system.s_dot0)
    return (np.array([q[0], q[1], -np.cos(q[3]), q[2], q[3], q[4]]),
            np.array([q_dot[0], q_dot[1], np.sin(q[3]) * q_dot[3], q_dot[2], q_dot[3], q_dot[4]]))


def _disc_in_E(q, u) -> Body:
    """The disc as one body of B(10) in E = R_z(ψ) R_x(ϕ) (slide 29), for q = (x, y, z, ψ, ϕ, θ) and
    u = (ψ̇, ϕ̇, θ̇): v_G and gravity turned into E, ω and the inertia diag(I, J, I) in E, E turning
    with ω_E = ω − θ̇ ê2 (so I_c is constant in E although the disc spins)."""
    s, c, psi, phi = sp.sin, sp.cos, q[3], q[4]
    R_E = sp.rot_axis3(-psi) * sp.rot_axis1(-phi)  # E's axes in N (sympy's rot_axis turns frames, hence −)
    return Body(v_c=R_E.T * (_disc_K(q) * sp.Matrix(u))[:3, :], omega=[u[1], u[2] + s(phi) * u[0], c(phi) * u[0]],
                m=m, I_c=sp.diag(I, J, I), f=R_E.T * sp.Matrix([0, 0, m * g]),
                omega_IR=[u[1], s(phi) * u[0], c(phi) * u[0]])


@cache
def projective_disc() -> CanonicalForm:
    """Barhorst's projective canonical form of the disc in E (:func:`_disc_in_E`)."""
    q = sp.symbols("x y z psi phi theta")
    u = sp.symbols("u1:4")
    return projective_canonical([_disc_in_E(q, u)], q, u, _disc_K(q), t, DISC_UNITS)


def projection_disc():
    """The disc by the Projection Equation B(10) with Bremer's free choice of the reference frame:
    R = E (:func:`_disc_in_E`), the rolling constraints already in the velocities (slide 30). Same
    coordinates and speeds as :func:`hamel_disc` and the scene ``knife_edge_disc``: q = (x, y, ψ, ϕ, θ)
    (z = −r cos ϕ eliminated), ṡ = (ψ̇, ϕ̇, θ̇). Returns the Gauss form with parameters m, g, r, I, J."""
    from .projection import projection_equation

    x, y, z, psi, phi, theta = q6 = sp.symbols("x y z psi phi theta")
    s = sp.symbols("psi_d phi_d theta_d")
    K = _disc_K(q6).extract([0, 1, 3, 4, 5], [0, 1, 2])  # without the ż row
    return projection_equation({"disc": _disc_in_E(q6, s)}, (x, y, psi, phi, theta), s, K, (I, J, g, m, r))


@cache
def particle() -> MultiplierSystem:
    """Barhorst's particle (Barhorst §3.1): L = m(ẋ² + ẏ²)/2 − m g y with ẏ − y² ẋ = 0, m = 1, g = 10."""
    x, y = q = dynamicsymbols("x y")
    return multiplier_system((x.diff(t) ** 2 + y.diff(t) ** 2) / 2 - 10 * y, q, t, A=[[-y**2, 1]])


def _disc_speeds_K(q) -> sp.Matrix:
    """q̇ = K ṡ for the scene's q = (x, y, ψ, ϕ, θ) and ṡ = (ψ̇, ϕ̇, θ̇, c₁, c₂): the rolling rows of slide
    30 (z = −r cos ϕ eliminated), with c₁, c₂ the rolling constraints' violations added to ẋ, ẏ."""
    x, y, psi, phi, th = q
    K_rolling = _disc_K([x, y, None, psi, phi, th])  # rows ẋ, ẏ, ż, ψ̇, ϕ̇, θ̇ from (ψ̇, ϕ̇, θ̇)
    return sp.Matrix.hstack(K_rolling.extract([0, 1, 3, 4, 5], [0, 1, 2]), sp.eye(5)[:, :2])


@cache
def central_disc():
    """The disc as Bremer's Central Equation B(2) (:func:`projeq.symbolic.central.central_equation`): the
    body of :func:`projection_disc` in R = E, with the speeds ṡ = (ψ̇, ϕ̇, θ̇, c₁, c₂) of :func:`hamel_disc`
    and c₁ = c₂ = 0 the rolling constraints."""
    from .central import central_equation

    q = x, y, psi, phi, th = sp.symbols("x y psi phi theta")
    s = sp.symbols("psi_d phi_d theta_d c_1 c_2")
    K = _disc_speeds_K(q)
    q_dot = K * sp.Matrix(s)
    R_E = sp.rot_axis3(-psi) * sp.rot_axis1(-phi)
    v_G = R_E.T * sp.Matrix([q_dot[0], q_dot[1], r * sp.sin(phi) * q_dot[3]])
    in_E = _disc_in_E([x, y, None, psi, phi, th], s[:3])
    disc = Body(v_c=v_G, omega=in_E.omega, m=m, I_c=in_E.I_c, f=in_E.f, omega_IR=in_E.omega_IR)
    return central_equation({"disc": disc}, q, s, K.inv().applyfunc(sp.simplify), s[3:], (I, J, g, m, r))


def hamel_disc(constraints_first: bool = False):
    """The disc by Hamel's equations B(3) in the scene's q = (x, y, ψ, ϕ, θ): speeds
    ṡ = H q̇ = (ψ̇, ϕ̇, θ̇, c₁, c₂) with c₁, c₂ the rolling constraints of slide 30 (z = −r cos ϕ
    eliminated), T and the weight's generalised forces Q = Kᵀ ∂(m g z)/∂q in these speeds; c₁ = c₂ = 0
    inserted *after* the derivation. Returns the Gauss form in (ψ̇, ϕ̇, θ̇) with parameters m, g, r, I, J.

    ``constraints_first=True`` inserts c₁ = c₂ = 0 into T *before* the derivation — the mistake
    Bremer warns against for the car (B(8) text): ∂T/∂c_ν vanish, and with them the terms
    (∂T/∂c_ν) ṡ_μ β_ν^{μ,n} of B(3)."""
    from .hamel import hamel_equations
    from .projection import GaussForm

    q = sp.symbols("x y psi phi theta")
    s = sp.symbols("psi_d phi_d theta_d c_1 c_2")
    s_ddot = sp.symbols("psi_dd phi_dd theta_dd c_1_d c_2_d")
    x, y, psi, phi, th = q
    K = _disc_speeds_K(q)
    H = K.inv().applyfunc(sp.simplify)
    q_dot = K * sp.Matrix(s)
    z_dot = r * sp.sin(phi) * q_dot[3]
    T = (m * (q_dot[0] ** 2 + q_dot[1] ** 2 + z_dot**2) + I * q_dot[2] ** 2 * sp.cos(phi) ** 2 + I * q_dot[3] ** 2
         + J * (q_dot[4] + q_dot[2] * sp.sin(phi)) ** 2) / 2
    if constraints_first:
        T = T.subs({s[3]: 0, s[4]: 0})
    Q = K.T * sp.Matrix([0, 0, 0, m * g * r * sp.sin(phi), 0])  # −∂V/∂q, V = −m g z = m g r cos ϕ
    residual = hamel_equations(T, q, s, H, Q, s_ddot, parameters=(m, g, r, I, J))
    residual = residual[:3, :].subs({s[3]: 0, s[4]: 0, s_ddot[3]: 0, s_ddot[4]: 0})
    M, rhs = sp.linear_eq_to_matrix(list(residual), list(s_ddot[:3]))
    return GaussForm(M, rhs, q, s[:3], K[:, :3], parameters=(I, J, g, m, r))

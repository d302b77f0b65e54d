"""Accelerations of a closed loop at any speed (issue 16): sympy's four-bar linkage
(``test_four_bar_linkage_with_manual_constraints`` in sympy/physics/mechanics/tests/
test_jointsmethod.py: links l1 … l4 = 0.13, 0.24, 0.21, 0.34 m of line density ρ = 997 kg/m,
link 1 the ground, no gravity, its state q = (2.1, 0.66554…, 2.52740…), u = (0.2, …)) at
1, 1/10, 1/100 and 1/1000 of its rates.

Without gravity the accelerations are quadratic in the rates, so they shrink by up to 1e-6;
so does the constraints' second time derivative γ. A fixed-step difference of γ has a fixed
absolute error (measured: 8.5e-9, 5.5e-7, 1.1e-4, 6e-3 relative at these speeds); projeq's γ
(complex step inside a fourth-order stencil on each normalised direction,
``ConstrainedSystem.gamma``) keeps the relative accuracy.

Reference: Kane's method (sympy.physics.mechanics.KanesMethod with the loop closure as
configuration constraints and its time derivative as velocity constraints, as in sympy's
test), its mass matrix and forcing evaluated with mpmath at 40 digits and solved there; it
is checked against the mass matrix printed in sympy's test. Tolerance 9.6e-13 relative to
the largest acceleration (measured ≤ 9.5e-14 at the four speeds; the issue's target was 1e-10).
"""

from functools import cache

import mpmath
import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me

import projeq as pq
from projeq.constraints.partitioned import ConstrainedSystem

LENGTHS, RHO = (0.13, 0.24, 0.21, 0.34), 997.0
Q_SYMPY = (2.1, 0.6655470375077588, 2.527408138024188)  # satisfies the loop closure (sympy's test)
U1 = 0.2  # the crank rate of sympy's test (u2, u3 follow from the velocity constraints)


def _open_chain():
    """sympy's three moving links on their hinges (frames A2 … A4 turned by u1 … u3 about z):
    (q, u, p, N, bodies, loop closure fh, kinematic equations)."""
    q = me.dynamicsymbols("q1:4")
    u = me.dynamicsymbols("u1:4")
    l1, l2, l3, l4, rho = p = sp.symbols("l1:5 rho")
    N = me.ReferenceFrame("N")
    frames = [N]
    for i in range(3):
        frame = frames[-1].orientnew(f"A{i + 2}", "Axis", (q[i], frames[-1].z))
        frame.set_ang_vel(frames[-1], u[i] * frames[-1].z)
        frames.append(frame)
    origin = me.Point("O")  # link 1's mass centre, at rest
    origin.set_vel(N, 0)
    hinge = origin.locatenew("J1", l1 / 2 * N.x)
    hinge.set_vel(N, 0)
    bodies = []
    for frame, length, name in zip(frames[1:], (l2, l3, l4), ("L2", "L3", "L4")):
        centre = hinge.locatenew(f"C{name}", length / 2 * frame.x)
        centre.v2pt_theory(hinge, N, frame)
        inertia = me.inertia(frame, 0, 0, rho * length**3 / 12)
        bodies.append(me.RigidBody(name, centre, frame, rho * length, (inertia, centre)))
        hinge_next = hinge.locatenew(f"J{name}", length * frame.x)
        hinge_next.v2pt_theory(hinge, N, frame)
        hinge, last_centre = hinge_next, centre
    loop = last_centre.pos_from(origin) + l1 / 2 * N.x + l4 / 2 * frames[3].x
    t = me.dynamicsymbols._t
    kd_eqs = [qi.diff(t) - ui for qi, ui in zip(q, u)]
    return q, u, p, N, bodies, sp.Matrix([loop.dot(N.x), loop.dot(N.y)]), kd_eqs


@cache
def kane_reference():
    """(mass matrix, forcing) of Kane's equations with the constraint rows, lambdified for
    mpmath: M(q, p) u̇ = f(q, u, p)."""
    q, u, p, N, bodies, fh, kd_eqs = _open_chain()
    t = me.dynamicsymbols._t
    fhd = fh.diff(t).subs({qi.diff(t): ui for qi, ui in zip(q, u)})
    kane = me.KanesMethod(N, q_ind=[q[0]], u_ind=[u[0]], q_dependent=q[1:], u_dependent=u[1:],
                          kd_eqs=kd_eqs, configuration_constraints=fh, velocity_constraints=fhd)
    kane.kanes_equations(bodies, [])
    mass = sp.lambdify((q, p), kane.mass_matrix, modules="mpmath")
    forcing = sp.lambdify((q, u, p), kane.forcing, modules="mpmath")
    return mass, forcing


@cache
def tree_reference():
    """The open chain's Kane equations M_tree(q, p) u̇ = f_tree(q, u, p) (no constraint) and the
    closure's Jacobian Φ_q(q, p), lambdified for mpmath: the constraint forces λ of the closed
    loop solve M_tree u̇ − f_tree = Φ_qᵀ λ (Lagrange's equations of the first kind)."""
    q, u, p, N, bodies, fh, kd_eqs = _open_chain()
    kane = me.KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=kd_eqs)
    kane.kanes_equations(bodies, [])
    mass = sp.lambdify((q, p), kane.mass_matrix, modules="mpmath")
    forcing = sp.lambdify((q, u, p), kane.forcing, modules="mpmath")
    return mass, forcing, sp.lambdify((q, p), fh.jacobian(q), modules="mpmath")


def reference_u_dot(q, u, digits: int = 40) -> np.ndarray:
    """u̇ of Kane's equations at the float state (q, u), solved with ``digits`` digits."""
    mass, forcing = kane_reference()
    with mpmath.workdps(digits):
        p = [mpmath.mpf(v) for v in (*LENGTHS, RHO)]
        qm, um = [mpmath.mpf(v) for v in q], [mpmath.mpf(v) for v in u]
        u_dot = mpmath.lu_solve(mpmath.matrix(mass(qm, p)), mpmath.matrix(forcing(qm, um, p)))
        return np.array([float(v) for v in u_dot])


def reference_multipliers(q, u, digits: int = 40) -> np.ndarray:
    """λ of M_tree u̇ − f_tree = Φ_qᵀ λ at the float state (q, u), with u̇ from Kane's
    equations of the closed loop, all with ``digits`` digits (the least-squares solution of
    the three rows, consistent to those digits)."""
    mass, forcing, phi_q = tree_reference()
    u_dot = reference_u_dot(q, u, digits)
    with mpmath.workdps(digits):
        p = [mpmath.mpf(v) for v in (*LENGTHS, RHO)]
        qm, um = [mpmath.mpf(v) for v in q], [mpmath.mpf(v) for v in u]
        residual = mpmath.matrix(mass(qm, p)) * mpmath.matrix([mpmath.mpf(v) for v in u_dot]) \
            - mpmath.matrix(forcing(qm, um, p))
        A = mpmath.matrix(phi_q(qm, p))
        lam = mpmath.lu_solve(A * A.T, A * residual)
        return np.array([float(v) for v in lam])


def four_bar() -> ConstrainedSystem:
    """The same linkage in projeq: links 2–4 on revolute joints about z (frames at their
    hinges), the loop closed at link 1's far end (−l1/2, 0) by Φ(q) = 0."""
    l1, l2, l3, l4 = LENGTHS

    def rod(length):
        return pq.PlanarBody(RHO * length, (length / 2, 0.0, 0.0), RHO * length**3 / 12, "xy")

    tree = pq.System({"L2": rod(l2), "L3": rod(l3), "L4": rod(l4)},
                     {"L2": pq.Revolute(axis="z", r_pn=(l1 / 2, 0.0, 0.0)),
                      "L3": pq.Revolute(parent="L2", axis="z", r_pn=(l2, 0.0, 0.0)),
                      "L4": pq.Revolute(parent="L3", axis="z", r_pn=(l3, 0.0, 0.0))})

    def closure(q, t):
        a1, a2, a3 = q[0], q[0] + q[1], q[0] + q[1] + q[2]
        return [l1 + l2 * np.cos(a1) + l3 * np.cos(a2) + l4 * np.cos(a3),
                l2 * np.sin(a1) + l3 * np.sin(a2) + l4 * np.sin(a3)]

    return ConstrainedSystem(tree, phi=closure, independent=[0], q0=Q_SYMPY)


def test_reference_is_sympys_four_bar():
    """The reference's mass matrix is the one printed in sympy's test (16 digits): 100 ε of its largest
    entry (measured 2.8e-14 of 34.5; was 1e-10)."""
    mass, _ = kane_reference()
    printed = [[3.452709815256506e+01, 7.003948798374735e+00, -4.939690970641498e+00],
               [-2.203792703880936e-14, 2.071702479957077e-01, 2.842917573033711e-01],
               [-1.300000000000123e-01, -8.836934896046506e-03, 1.864891330060847e-01]]
    M = np.array(mass(list(Q_SYMPY), [*LENGTHS, RHO]).tolist(), dtype=float)
    assert np.abs(M - np.array(printed)).max() < 100 * np.finfo(float).eps * np.abs(printed).max()


@pytest.mark.parametrize("scale", [1.0, 1e-1, 1e-2, 1e-3], ids=lambda s: f"rates×{s:g}")
def test_accelerations_keep_relative_accuracy(scale):
    system = four_bar()
    q = system.q0
    s_dot = np.array([U1 * scale])
    u = system.tree_velocities(q, s_dot)
    s_ddot_tree = system.accelerations_tree(q, s_dot)[0]
    reference = reference_u_dot(q, u)
    error = np.abs(s_ddot_tree - reference).max() / np.abs(reference).max()
    assert error < 9.6e-13, (scale, error)


@pytest.mark.parametrize("scale", [1.0, 1e-2, 1e-3], ids=lambda s: f"rates×{s:g}")
def test_reactions_keep_relative_accuracy(scale):
    """The loop's constraint forces λ (``reactions`` along a short run) against Lagrange's
    equations of the first kind at 40 digits (:func:`reference_multipliers`), at sympy's
    rates, 1/100 and 1/1000 of them, where λ ∝ rates² is 1e-6 as large: 5.2e-12 relative to the
    largest |λ| at each speed (issue 16: the reactions keep their accuracy at low speed;
    measured 5.2e-13, 4.7e-13, 3.3e-13; was 1e-10)."""
    system = four_bar()
    result = pq.simulate(system, 0.01, s_dot0=[U1 * scale], n_points=3, rtol=1e-12, atol=1e-14)
    lam = pq.reactions(system, result)
    reference = np.array([reference_multipliers(q, system.tree_velocities(q, s_dot, t))
                          for t, q, s_dot in zip(result.t, result.q, result.s_dot)])
    error = np.abs(lam - reference).max() / np.abs(reference).max()
    assert error < 5.2e-12, (scale, error)

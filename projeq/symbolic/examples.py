"""Symbolic models used by tests, benchmarks and comparisons: inputs for B(10)."""

import sympy as sp

from .projection import Body

__all__ = ["n_link_pendulum", "chain_parameters", "kane_pendulum", "lagrange_pendulum"]

PENDULUM_PARAMETERS = sp.symbols("m l J J_a g", positive=True)


def n_link_pendulum(n: int):
    """Velocity expressions of ``projeq.scenes.chain(n)`` for :func:`projection_equation`.

    n uniform links (mass m, length l, inertia J across and J_a along the link about its
    mass centre) hanging along −z from revolute joints about +y; q_k the relative joint
    angles, ṡ = q̇, gravity g along −z; everything in the inertial frame (ω_IR = 0).
    Returns ``(bodies, q, s, parameters)`` with parameters (m, l, J, J_a, g).

    >>> bodies, q, s, parameters = n_link_pendulum(2)
    >>> bodies["link1"].omega
    (0, s_1, 0)
    """
    if int(n) != n or n < 1:
        raise ValueError(f"n: number of links must be a positive integer, got {n!r}")
    n = int(n)
    q = sp.symbols(f"q_1:{n + 1}")
    s = sp.symbols(f"s_1:{n + 1}")
    m, l, J, J_a, g = parameters = PENDULUM_PARAMETERS
    bodies, joint, theta, omega_y = {}, sp.zeros(3, 1), 0, 0
    for k in range(n):
        theta, omega_y = theta + q[k], omega_y + s[k]
        A = sp.rot_axis2(theta).T  # rotation about +y by θ (sympy's rot_axis2 is the transpose)
        e = A * sp.Matrix([0, 0, -1])  # unit vector along the link, joint → tip
        r_c = joint + l / 2 * e
        bodies[f"link{k + 1}"] = Body(
            v_c=r_c.jacobian(q) * sp.Matrix(s), omega=(0, omega_y, 0), m=m,
            I_c=A * sp.diag(J, J, J_a) * A.T, f=(0, 0, -m * g),
        )
        joint = joint + l * e
    return bodies, q, s, parameters


def chain_parameters(n: int) -> dict:
    """``parameters`` for ``gauss_form(projeq.scenes.chain(n), ...)`` that make it the
    pendulum of :func:`n_link_pendulum`: links of mass m, length l, inertia diag(J, J, J_a)
    about the mass centre, gravity g along −z."""
    m, l, J, J_a, g = PENDULUM_PARAMETERS
    out = {"gravity": (0, 0, -g)}
    for k in range(1, n + 1):
        out |= {f"link{k}.m": m, f"link{k}.r_c": (0, 0, -l / 2), f"link{k}.I_c": sp.diag(J, J, J_a)}
        if k > 1:
            out[f"link{k}.r_pn"] = (0, 0, -l)
    return out


def _mechanics_pendulum(n: int):
    """The same pendulum in sympy.physics.mechanics: frames rotated about N.y by relative
    angles q_k, rigid links with central inertia (J, J, J_a), gravity −g N.z."""
    from sympy.physics import mechanics as me

    q, u = me.dynamicsymbols(f"q1:{n + 1}"), me.dynamicsymbols(f"u1:{n + 1}")
    m, l, J, J_a, g = PENDULUM_PARAMETERS
    N = me.ReferenceFrame("N")
    joint = me.Point("O")
    joint.set_vel(N, 0)
    frame, links, loads = N, [], []
    for k in range(n):
        frame = frame.orientnew(f"A{k}", "Axis", (q[k], frame.y))
        frame.set_ang_vel(N, sum((u_j * N.y for u_j in u[: k + 1]), 0 * N.y))
        centre = joint.locatenew(f"C{k}", -l / 2 * frame.z)
        centre.v2pt_theory(joint, N, frame)
        links.append(me.RigidBody(f"B{k}", centre, frame, m, (me.inertia(frame, J, J, J_a), centre)))
        loads.append((centre, -m * g * N.z))
        joint = joint.locatenew(f"P{k}", -l * frame.z)
        joint.v2pt_theory(centre, N, frame)
    return N, q, u, links, loads


def kane_pendulum(n: int):
    """KanesMethod for the n-link pendulum: ``(q, u, M, forcing)`` with M u̇ = forcing, u = q̇."""
    from sympy.physics import mechanics as me

    N, q, u, links, loads = _mechanics_pendulum(n)
    kane = me.KanesMethod(N, q_ind=q, u_ind=u, kd_eqs=[q_k.diff() - u_k for q_k, u_k in zip(q, u)])
    kane.kanes_equations(links, loads)
    return q, u, kane.mass_matrix, kane.forcing


def lagrange_pendulum(n: int):
    """LagrangesMethod for the n-link pendulum: ``(q, q̇, M, forcing)`` with M q̈ = forcing.
    The angular velocities set for Kane (in u) are replaced by q̇ here."""
    from sympy.physics import mechanics as me

    N, q, u, links, loads = _mechanics_pendulum(n)
    q_dot = [q_k.diff(me.dynamicsymbols._t) for q_k in q]
    for body in links:
        body.frame.set_ang_vel(N, body.frame.ang_vel_in(N).subs(dict(zip(u, q_dot))))
    for body in links:
        body.masscenter.set_vel(N, body.masscenter.vel(N).subs(dict(zip(u, q_dot))))
    lagrange = me.LagrangesMethod(me.Lagrangian(N, *links), q, forcelist=loads, frame=N)
    lagrange.form_lagranges_equations()
    return q, q_dot, lagrange.mass_matrix, lagrange.forcing

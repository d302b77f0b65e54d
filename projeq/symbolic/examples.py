"""Symbolic models used by tests, benchmarks and comparisons: inputs for B(10)."""

import sympy as sp

from .projection import Body

__all__ = ["n_link_pendulum"]


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
    m, l, J, J_a, g = parameters = sp.symbols("m l J J_a g", positive=True)
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

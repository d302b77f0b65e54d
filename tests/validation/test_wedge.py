"""Particle sliding on a movable inclined plane: Problem 3 of
the Lagrange seminars.

The wedge (mass M) slides on a prismatic joint along the horizontal x axis; the particle
(mass m) slides on a prismatic joint *of the wedge* along e = (cos α, 0, −sin α), the
unit vector down the plane. The coordinates are the seminars' x (wedge) and x' (particle
along the plane, relative to the wedge), eqs. (11)–(12).
"""

import numpy as np
import pytest

import projeq as pq
from _linear import in_request_units

G = 9.81

# Algebraic identities from one 2×2 solve: exact to a few ulps, so 100 ε (measured at most 3.8e-16
# relative, and 1.8e-15 m/s² in eqs. (20); was 1e-12).
ALGEBRAIC = 100 * np.finfo(float).eps

CASES = [(np.radians(30.0), 1.0, 3.0), (np.radians(60.0), 2.0, 0.5), (np.radians(10.0), 0.3, 10.0)]
IDS = ["30deg-m<M", "60deg-m>M", "10deg-heavy-wedge"]


def wedge_system(alpha, m, M):
    e = (np.cos(alpha), 0.0, -np.sin(alpha))
    # the wedge is a spatial body whose mass centre is off its joint: a body that only
    # translates must not feel its inertia tensor or the place of its mass centre
    wedge = pq.RigidBody(M, r_c=(0.3, 0.0, 0.2), I_c=pq.inertia.box(M, 1.0, 0.4, 0.6))
    return pq.System(
        subsystems={"wedge": wedge, "particle": pq.PointMass(m)},
        joints={
            "wedge": pq.Prismatic(axis="x"),
            "particle": pq.Prismatic(parent="wedge", axis=e, r_pn=(0.0, 0.0, 0.6)),
        },
        gravity=(0.0, 0.0, -G),
    )


def wedge_accelerations(alpha, m, M, g=G):
    """(ẍ, ẍ') of Problem 3, eqs. (21) and (22).

    The extraction lost the sign of (21); it follows from the first of eqs. (20),
    (m + M) ẍ = −m cos α ẍ': the wedge recoils against the particle's horizontal motion.
    """
    x_ddot = -g * np.sin(alpha) * np.cos(alpha) / ((m + M) / m - np.cos(alpha) ** 2)
    xp_ddot = g * np.sin(alpha) / (1 - m * np.cos(alpha) ** 2 / (m + M))
    return x_ddot, xp_ddot


def horizontal_momentum(alpha, m, M, s_dot):
    """m (ẋ + ẋ' cos α) + M ẋ: the constant of motion (19) of Problem 3."""
    return m * (s_dot[..., 0] + s_dot[..., 1] * np.cos(alpha)) + M * s_dot[..., 0]


@pytest.mark.parametrize("alpha, m, M", CASES, ids=IDS)
def test_wedge_accelerations(alpha, m, M):
    """Problem 3, eqs. (14), (20), (21), (22) of the Lagrange seminars.

    Mass matrix of T (14): [[M + m, m cos α], [m cos α, m]]; accelerations (21)–(22) at
    any state (they are constant); Lagrange's equations (20) hold.
    """
    system = wedge_system(alpha, m, M)
    x_ddot, xp_ddot = wedge_accelerations(alpha, m, M)
    c = np.cos(alpha)
    rng = np.random.default_rng(3)
    for q, s_dot in zip(rng.normal(size=(3, 2)), rng.normal(size=(3, 2))):
        np.testing.assert_allclose(system.mass_matrix(q), [[M + m, m * c], [m * c, m]], rtol=ALGEBRAIC)
        s_ddot = system.accelerations(q, s_dot)
        np.testing.assert_allclose(s_ddot, [x_ddot, xp_ddot], rtol=ALGEBRAIC)
        # eqs. (20), scaled by the size of their terms (m + M) g
        residual = [m * (s_ddot[0] + s_ddot[1] * c) + M * s_ddot[0],
                    s_ddot[1] + s_ddot[0] * c - G * np.sin(alpha)]
        np.testing.assert_allclose(residual, [0.0, 0.0], rtol=0, atol=ALGEBRAIC * (m + M) * G)
        # the recursive evaluator (order n) and the dense Gauss form agree
        np.testing.assert_allclose(system.accelerations(q, s_dot, method="dense"), s_ddot, rtol=ALGEBRAIC)


@pytest.mark.parametrize("alpha, m, M", CASES, ids=IDS)
def test_wedge_momentum_conserved(alpha, m, M):
    """Problem 3, eqs. (19), (21), (22) of the Lagrange seminars,
    integrated from a moving start: the horizontal momentum (19) stays constant and the
    coordinates follow x(t) = x0 + v0 t + ½ ẍ t² (constant accelerations (21)–(22)).
    """
    system = wedge_system(alpha, m, M)
    x_ddot, xp_ddot = wedge_accelerations(alpha, m, M)
    q0, s_dot0 = np.array([0.1, 0.2]), np.array([0.7, -0.4])
    rtol, atol = 1e-10, 1e-12
    res = pq.simulate(system, 1.0, q0=q0, s_dot0=s_dot0, method="DOP853", rtol=rtol, atol=atol)
    t = res.t[:, None]
    ref_q = q0 + s_dot0 * t + 0.5 * np.array([x_ddot, xp_ddot]) * t**2
    # quadratics are integrated exactly by DOP853, so only round-off remains: measured 1.5e-4 units
    # of the request over the three cases (the bound was 5, as in scipy's solve_ivp tests)
    assert in_request_units(res.q, ref_q, rtol, atol).max() < 1.5e-3
    # P is linear in ṡ with coefficients (M + m, m cos α): each velocity may be off by
    # 5 request units, so |ΔP| ≤ 5 Σ |c_i| (atol + rtol |ṡ_i|)
    P = horizontal_momentum(alpha, m, M, res.s_dot)
    coeff = np.array([M + m, m * np.cos(alpha)])
    bound = 5 * (np.abs(coeff) * (atol + rtol * np.abs(res.s_dot))).sum(axis=1)
    assert np.all(np.abs(P - P[0]) <= bound)

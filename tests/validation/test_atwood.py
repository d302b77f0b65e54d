"""Atwood machines: Problems 1 and 2 of the Lagrange seminars.

The rope is inextensible and does not slip: projeq models it by *coupled* joints (one
joint's coordinate is a fixed linear combination of others), evaluated by the dense
Gauss form.
"""

import numpy as np
import pytest

import projeq as pq
from _linear import in_request_units

G = 9.81

# Algebraic identities (one linear solve of a 1×1 or 2×2 Gauss form): exact up to a few
# ulps of the largest term, so 100 ε of it. Measured: ẍ 8.9e-16 at g, M 0 to 1 ulp, V 3.6e-15 at 40 J,
# the double machine's s̈ 1.8e-15 at g and eq. (8) 7.1e-15 at 39 N (was 1e-12).
ALGEBRAIC = 100 * np.finfo(float).eps

# (m1, m2, pulley mass, pulley radius): heavier left, heavier right, balanced (ẍ = 0),
# and a heavy pulley whose inertia dominates the denominator of eq. (4).
ATWOOD_CASES = [(2.0, 1.0, 0.5, 0.1), (1.0, 3.0, 2.0, 0.25), (1.5, 1.5, 1.0, 0.2), (1.0, 1.2, 20.0, 0.5)]
ATWOOD_IDS = ["m1>m2", "m1<m2", "balanced", "heavy-pulley"]


def atwood_acceleration(m1, m2, I, a, g=G):
    """ẍ = (m1 − m2) g / (m1 + m2 + I/a²): Problem 1, eq. (4) (x = depth of mass 1)."""
    return (m1 - m2) * g / (m1 + m2 + I / a**2)


@pytest.mark.parametrize("m1, m2, pulley_mass, a", ATWOOD_CASES, ids=ATWOOD_IDS)
def test_atwood_scene_acceleration(m1, m2, pulley_mass, a):
    """Problem 1, eqs. (2)–(4) of the Lagrange seminars: the claim of
    ``pq.scenes.atwood``'s docstring, ẍ₁ = (m1 − m2) g / (m1 + m2 + I/a²) downwards for
    mass 1, with I = ½ M a² of the disk pulley.

    The scene's coordinate is the pulley angle θ, and mass 1 rises by a θ, so the depth of
    mass 1 is x = −a θ (+ const): ẍ = −a θ̈ at any state (the acceleration is constant).
    The mass matrix is that of the kinetic energy (2), T = ½ (m1 + m2 + I/a²) ẋ²,
    i.e. M_θθ = (m1 + m2) a² + I, and the potential (2) confirms the sign convention.
    """
    system = pq.scenes.atwood(m1, m2, pulley_mass, a, G)
    I = 0.5 * pulley_mass * a**2  # uniform disk about its axis, as the scene's docstring says
    x_ddot = atwood_acceleration(m1, m2, I, a)
    rng = np.random.default_rng(0)
    for theta, theta_dot in rng.normal(size=(4, 2)):
        theta_ddot = system.accelerations([theta], [theta_dot])[0]
        # scale g: for the balanced machine ẍ = 0 and a relative error is meaningless
        assert abs(-a * theta_ddot - x_ddot) <= ALGEBRAIC * G
        M = system.mass_matrix([theta])
        assert M[0, 0] == pytest.approx((m1 + m2) * a**2 + I, rel=ALGEBRAIC, abs=0)
        # V = m1 g z1 + m2 g z2 with z1 = −1 + a θ (mass 1 rises), z2 = −1 − a θ; eq. (2)
        # up to the constant and the choice x = −a θ
        V = system.energy([theta], [0.0])[1]
        V_ref = G * (m1 * (-1 + a * theta) + m2 * (-1 - a * theta))
        assert V == pytest.approx(V_ref, rel=ALGEBRAIC, abs=ALGEBRAIC * G)


@pytest.mark.parametrize("m1, m2, pulley_mass, a", ATWOOD_CASES, ids=ATWOOD_IDS)
def test_atwood_scene_simulated_fall(m1, m2, pulley_mass, a):
    """Problem 1, eq. (4) of the Lagrange seminars, integrated: from
    rest x(t) = ½ ẍ t², i.e. θ(t) = −ẍ t² / (2a), and the energy (2) is conserved.
    """
    system = pq.scenes.atwood(m1, m2, pulley_mass, a, G)
    x_ddot = atwood_acceleration(m1, m2, 0.5 * pulley_mass * a**2, a)
    rtol, atol = 1e-10, 1e-12
    res = pq.simulate(system, 1.5, q0=[0.0], s_dot0=[0.0], method="DOP853", rtol=rtol, atol=atol)
    theta_ref = -x_ddot * res.t**2 / (2 * a)
    # a quadratic in t is integrated exactly by an 8th-order method: only round-off is
    # left, far below the request: measured 4.0e-5 request units over the four cases (was 5, as
    # in scipy's solve_ivp tests)
    assert in_request_units(res.q[:, 0], theta_ref, rtol, atol).max() < 4e-4
    # energy: round-off only (measured 6.2e-16 of the energy scale; was 1e-10)
    assert res.energy_drift < 100 * np.finfo(float).eps


# --- Problem 2: double Atwood machine -----------------------------------------------------
#
# Seed coordinates: x = depth of m1 below the fixed pulley, x' = depth of m2 below the
# movable pulley; constraints (5): x_p = l − x, 2x + x2 + x3 = 2l + l' (massless pulleys).
# projeq model: m1 and m2 on prismatic joints (downwards) with their depths x and x2 as
# coordinates; m3 follows the rope: its depth x3 = 2l + l' − 2x − x2 is a coupled joint.
# Then x' = x2 − l + x, so ẍ' = ẍ2 + ẍ.

L_ROPE, L_ROPE2 = 1.0, 0.8


def double_atwood(m1, m2, m3):
    down = (0.0, 0.0, -1.0)
    return pq.System(
        subsystems={"m1": pq.PointMass(m1), "m2": pq.PointMass(m2), "m3": pq.PointMass(m3)},
        joints={
            "m1": pq.Prismatic(axis=down, r_pn=(-0.5, 0.0, 0.0)),
            "m2": pq.Prismatic(axis=down, r_pn=(0.45, 0.0, 0.0)),
            # coordinate −2x − x2; depth = (2l + l') + coordinate
            "m3": pq.Prismatic(axis=down, r_pn=(0.55, 0.0, -(2 * L_ROPE + L_ROPE2)),
                               coupling={"m1": -2.0, "m2": -1.0}),
        },
        gravity=(0.0, 0.0, -G),
    )


def double_atwood_accelerations(m1, m2, m3, g=G):
    """(ẍ, ẍ') of Problem 2, eqs. (9) and (10)."""
    den = m1 * m3 + 4 * m2 * m3 + m1 * m2
    return g * (m1 * m3 - 4 * m2 * m3 + m1 * m2) / den, g * 2 * m1 * (m2 - m3) / den


DOUBLE_CASES = [(1.0, 0.5, 0.5), (1.0, 2.0, 3.0), (3.0, 1.0, 0.5), (0.4, 1.0, 1.0)]
DOUBLE_IDS = ["m1=m,m2=m3=m/2(at-rest)", "1-2-3", "3-1-0.5", "light-m1"]


@pytest.mark.parametrize("m1, m2, m3", DOUBLE_CASES, ids=DOUBLE_IDS)
def test_double_atwood_accelerations(m1, m2, m3):
    """Problem 2, eqs. (6), (8), (9), (10) of the Lagrange seminars.

    The mass matrix equals that of T in (6), transformed to projeq's coordinates (x, x2)
    by (ẋ, ẋ') = P (ẋ, ẋ2), P = [[1, 0], [1, 1]]; the accelerations equal (9)–(10) and
    satisfy Lagrange's equations (8); for m1 = m, m2 = m3 = m/2 both vanish (a remark of the seminars).
    """
    system = double_atwood(m1, m2, m3)
    x_ddot, xp_ddot = double_atwood_accelerations(m1, m2, m3)
    P = np.array([[1.0, 0.0], [1.0, 1.0]])
    M_seed = np.array([[m1 + m2 + m3, m3 - m2], [m3 - m2, m2 + m3]])  # T of eq. (6)
    rng = np.random.default_rng(1)
    for q, s_dot in zip(rng.normal(size=(3, 2)), rng.normal(size=(3, 2))):
        np.testing.assert_allclose(system.mass_matrix(q), P.T @ M_seed @ P, rtol=ALGEBRAIC)
        s_ddot = system.accelerations(q, s_dot)
        got = P @ s_ddot  # (ẍ, ẍ')
        # absolute scale g: in the balanced case the accelerations are 0
        np.testing.assert_allclose(got, [x_ddot, xp_ddot], rtol=0, atol=ALGEBRAIC * G)
        # eq. (8): Lagrange's equations in the seminars' coordinates
        lhs = M_seed @ got
        np.testing.assert_allclose(lhs, [(m1 - m2 - m3) * G, (m2 - m3) * G], rtol=0,
                                   atol=ALGEBRAIC * G * (m1 + m2 + m3))


@pytest.mark.parametrize("m1, m2, m3", DOUBLE_CASES, ids=DOUBLE_IDS)
def test_double_atwood_simulated(m1, m2, m3):
    """Problem 2, eqs. (9)–(10) of the Lagrange seminars, integrated
    from rest: x(t) = x0 + ½ ẍ t² and x2(t) = x2,0 + ½ (ẍ' − ẍ) t²; the energy (6) is
    conserved.
    """
    system = double_atwood(m1, m2, m3)
    x_ddot, xp_ddot = double_atwood_accelerations(m1, m2, m3)
    q0 = np.array([0.6, 0.5])
    rtol, atol = 1e-10, 1e-12
    res = pq.simulate(system, 1.0, q0=q0, s_dot0=[0.0, 0.0], method="DOP853", rtol=rtol, atol=atol)
    ref = q0 + 0.5 * np.outer(res.t**2, [x_ddot, xp_ddot - x_ddot])
    # quadratics are integrated exactly by DOP853: round-off only (measured 4.2e-4 request units and an
    # energy drift of 6.7e-16 over the four cases; were 5 and 1e-10)
    assert in_request_units(res.q, ref, rtol, atol).max() < 4.2e-3
    assert res.energy_drift < 100 * np.finfo(float).eps


"""Two identical masses between three springs on a line: Problem 4 (Seminar 1) and its
generalisation in Seminar 6 (outer springs K, coupling spring K') of
the Lagrange seminars.

Model: walls at x = 0 and x = 3d, the masses on prismatic joints along x placed at d and
2d, so the coordinates are the seminars' displacements x1, x2 from equilibrium. The springs
are point-to-point SpringDampers of natural length d (relaxed at q = 0, the equilibrium).
Gravity acts along −z, across the motion.
"""

import numpy as np
import pytest

import projeq as pq
from _linear import normal_modes

D = 0.5  # m, wall-to-mass distance and natural length of the springs


def oscillators(m, K, K_coupling):
    wall_left, wall_right = (0.0, 0.0, 0.0), (3 * D, 0.0, 0.0)
    return pq.System(
        subsystems={"m1": pq.PointMass(m), "m2": pq.PointMass(m)},
        joints={"m1": pq.Prismatic(axis="x", r_pn=(D, 0.0, 0.0)),
                "m2": pq.Prismatic(axis="x", r_pn=(2 * D, 0.0, 0.0))},
        gravity=(0.0, 0.0, -9.81),
        forces=[
            pq.SpringDamper(None, wall_left, "m1", (0, 0, 0), K, length=D),
            pq.SpringDamper("m1", (0, 0, 0), "m2", (0, 0, 0), K_coupling, length=D),
            pq.SpringDamper("m2", (0, 0, 0), None, wall_right, K, length=D),
        ],
    )


# (m, K, K'): Problem 4 has K' = K; Seminar 6, Fig. 11.3.2 uses K = 4, K' = 1.
CASES = [(1.0, 10.0, 10.0), (0.3, 4.0, 1.0)]
IDS = ["P4-equal-springs", "seminar6-K4-K'1"]

# The spring forces are exactly linear in q on a line, so the central differences of
# _linear.stiffness carry only round-off, eps·|b|/h ≈ 1e-16·(K ℓ)/1e-5 ≈ 1e-11 of K: measured 1.2e-12
# (K), 5.4e-13 (ω²), 5.6e-12 (mode shapes) relative; 10 times the largest (was 1e-9).
LINEARISATION = 6e-11


@pytest.mark.parametrize("m, K, Kc", CASES, ids=IDS)
def test_coupled_oscillator_modes(m, K, Kc):
    """Problem 4, eqs. (23)–(30), and Seminar 6, eqs. (6), (7), (20), (23), (25) of
    the Lagrange seminars.

    T = m E (6), V = [[K + K', −K'], [−K', K + K']] (7); ω₁² = K/m with the in-phase mode
    (1, 1) and ω₂² = (K + 2K')/m with the opposite-phase mode (1, −1) (for K' = K:
    √(k/m), √(3k/m) of eq. (30)).
    """
    system = oscillators(m, K, Kc)
    q_eq = np.zeros(2)
    # q = 0 is an equilibrium: no acceleration (round-off of ℓ − ℓ₀ ≈ eps·d at most)
    np.testing.assert_allclose(system.accelerations(q_eq, [0.0, 0.0]), 0.0, atol=1e-13 * K * D / m)
    omega2, modes, M, Kmat = normal_modes(system, q_eq)
    np.testing.assert_allclose(M, m * np.eye(2), rtol=1e-12)  # exact: a point mass's M is m E
    np.testing.assert_allclose(Kmat, [[K + Kc, -Kc], [-Kc, K + Kc]], rtol=LINEARISATION)
    np.testing.assert_allclose(omega2, [K / m, (K + 2 * Kc) / m], rtol=LINEARISATION)
    # mode shapes: a11 = a21 and a12 = −a22, eqs. (23) and (25)
    v1, v2 = modes[:, 0] / modes[0, 0], modes[:, 1] / modes[0, 1]
    np.testing.assert_allclose(v1, [1.0, 1.0], rtol=LINEARISATION)
    np.testing.assert_allclose(v2, [1.0, -1.0], rtol=LINEARISATION)


@pytest.mark.parametrize("m, K, Kc", CASES, ids=IDS)
def test_coupled_oscillator_beats(m, K, Kc):
    """Seminar 6, eqs. (34)–(36) of the Lagrange seminars: released
    from rest with x1(0) = 0, x2(0) = a, the masses beat,
    x1 = ½ a (cos ω₁t − cos ω₂t), x2 = ½ a (cos ω₁t + cos ω₂t), over one beat period
    2π/(ω₂ − ω₁) (energy passes from mass 2 to mass 1 and back).
    """
    system = oscillators(m, K, Kc)
    w1, w2 = np.sqrt(K / m), np.sqrt((K + 2 * Kc) / m)
    a = 0.1 * D
    rtol, atol = 1e-10, 1e-12
    t_end = 2 * np.pi / (w2 - w1)
    res = pq.simulate(system, t_end, q0=[0.0, a], s_dot0=[0.0, 0.0], method="DOP853", rtol=rtol, atol=atol)
    t = res.t[:, None]
    ref = 0.5 * a * np.hstack((np.cos(w1 * t) - np.cos(w2 * t), np.cos(w1 * t) + np.cos(w2 * t)))
    # the error of a linear oscillation grows with the number of periods (here ≤ 4 fast
    # periods); measured in units of the request with the amplitude a as the scale of q
    # (the reference passes through 0), within 5 units as in scipy's solve_ivp tests
    err = np.abs(res.q - ref) / (atol + rtol * a)
    assert err.max() < 5
    # energy is quadratic in the state: state errors of 5 request units change it by ≤ 10 rtol
    assert res.energy_drift < 10 * rtol

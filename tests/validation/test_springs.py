"""Masses on springs, Problem 10 of the Lagrange seminars: an upper
mass 2m hangs from a fixed frame on a spring (stiffness k, natural length l1), a lower
mass m hangs from it on a second spring (k, l2); vertical motion only.

Model: both masses on prismatic joints from the ground pointing *down* (axis −z, gravity
along −z), so the coordinates are the seminars' depths y1, y2 below the suspension point;
the springs are point-to-point SpringDampers (ground–upper, upper–lower).
"""

import numpy as np

import projeq as pq
from _linear import in_request_units, normal_modes

G = 9.81
M, K, L1, L2 = 0.5, 40.0, 0.6, 0.5  # kg, N/m, m, m
DOWN = (0.0, 0.0, -1.0)


def two_masses():
    return pq.System(
        subsystems={"upper": pq.PointMass(2 * M), "lower": pq.PointMass(M)},
        joints={"upper": pq.Prismatic(axis=DOWN), "lower": pq.Prismatic(axis=DOWN, r_pn=(0.0, 0.0, 0.0))},
        gravity=(0.0, 0.0, -G),
        forces=[
            pq.SpringDamper(None, (0.0, 0.0, 0.0), "upper", (0.0, 0.0, 0.0), K, length=L1),
            pq.SpringDamper("upper", (0.0, 0.0, 0.0), "lower", (0.0, 0.0, 0.0), K, length=L2),
        ],
    )


def equilibrium(m=M, k=K, g=G):
    """(y1⁰, y2⁰) of Problem 10, eq. (12): k y1⁰ = 3 m g + k l1, k y2⁰ = 4 m g + k l1 + k l2."""
    return np.array([3 * m * g / k + L1, 4 * m * g / k + L1 + L2])


def test_two_masses_equilibrium_and_modes():
    """Problem 10, eqs. (1), (6), (11)–(12), (14), (16)–(19) of
    the Lagrange seminars.

    At the equilibrium (12) the accelerations vanish; M = m diag(2, 1) (1); the
    stiffness of (14) is k [[2, −1], [−1, 1]]; ω² = (k/m)(1 ∓ 1/√2) (18) with mode shapes
    B/A = (2k − 2mω²)/k = ±√2 (19) (the slow mode in phase).
    """
    system = two_masses()
    y0 = equilibrium()
    # forces of size m g cancel: round-off eps·3mg/(2m) ≈ 1e-15 g (measured 3.6e-15 m/s²; was 1e-12 g)
    np.testing.assert_allclose(system.accelerations(y0, [0.0, 0.0]), 0.0, rtol=0, atol=4e-15 * G)
    omega2, modes, Mmat, Kmat = normal_modes(system, y0)
    np.testing.assert_allclose(Mmat, M * np.diag([2.0, 1.0]), rtol=1e-12)  # exact for point masses
    # springs on a line are linear in q: central differences carry only round-off
    # eps·|b|/h ≈ 1e-16·(K·1 m)/1e-5 ≈ 1e-11 of K; measured 6.6e-12 (K), 1.0e-12 (ω²), 7.9e-12 (mode
    # shapes) relative: 10 times the largest (was 1e-9)
    lin = 8e-11
    np.testing.assert_allclose(Kmat, K * np.array([[2.0, -1.0], [-1.0, 1.0]]), rtol=lin, atol=lin * K)
    omega2_ref = K / M * np.array([1 - 1 / np.sqrt(2), 1 + 1 / np.sqrt(2)])  # eq. (18)
    np.testing.assert_allclose(omega2, omega2_ref, rtol=lin)
    ratio = modes[1] / modes[0]
    np.testing.assert_allclose(ratio, (2 * K - 2 * M * omega2) / K, rtol=lin)  # eq. (19)
    np.testing.assert_allclose(ratio, [np.sqrt(2), -np.sqrt(2)], rtol=lin)


def test_two_masses_released_upper_mass():
    """Problem 10 (b), eqs. (21)–(27) of the Lagrange seminars: the
    upper mass is slowly pulled down by l (so both masses are displaced by l, eq. (22))
    and released. With the amplitudes (26), A1 = (l/2)(1 + 1/√2), A2 = (l/2)(1 − 1/√2),
    ξ1 = A1 cos ω₁t + A2 cos ω₂t and ξ2 = √2 A1 cos ω₁t − √2 A2 cos ω₂t (21), so the lower
    mass moves as y2 = y2⁰ + (1/√2 + 1/2) l cos ω₁t − (1/√2 − 1/2) l cos ω₂t (27; the
    extraction garbles the signs, which follow from (21) and (26)). Checked over two slow
    periods.
    """
    system = two_masses()
    y0 = equilibrium()
    l = 0.05
    w1, w2 = np.sqrt(K / M * (1 - 1 / np.sqrt(2))), np.sqrt(K / M * (1 + 1 / np.sqrt(2)))
    A1, A2 = l / 2 * (1 + 1 / np.sqrt(2)), l / 2 * (1 - 1 / np.sqrt(2))
    rtol, atol = 1e-10, 1e-12
    res = pq.simulate(system, 2 * 2 * np.pi / w1, q0=y0 + l, s_dot0=[0.0, 0.0], method="DOP853", rtol=rtol,
                      atol=atol)
    t = res.t
    xi1 = A1 * np.cos(w1 * t) + A2 * np.cos(w2 * t)
    xi2 = np.sqrt(2) * A1 * np.cos(w1 * t) - np.sqrt(2) * A2 * np.cos(w2 * t)
    y2_seed = (y0[1] + (1 / np.sqrt(2) + 0.5) * l * np.cos(w1 * t)
               - (1 / np.sqrt(2) - 0.5) * l * np.cos(w2 * t))
    # (27) is (21) with (26): the same numbers summed differently, round-off only
    np.testing.assert_allclose(y0[1] + xi2, y2_seed, rtol=1e-14, atol=1e-15)
    # linear oscillation over ≤ 5 fast periods: the global error stays within a few units
    # of the request; 5 as in scipy's solve_ivp tests
    assert in_request_units(res.q[:, 0], y0[0] + xi1, rtol, atol).max() < 5
    assert in_request_units(res.q[:, 1], y2_seed, rtol, atol).max() < 5
    # energy drift: 0.031 rtol measured here; the largest over rtol 3e-11 … 1e-9 and one to three slow
    # periods 0.18 rtol (rtol 1e-9, three periods), so 2 rtol (was 10 rtol)
    assert res.energy_drift < 2 * rtol

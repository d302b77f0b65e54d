"""Pendulums: Problems 7 (simple pendulum, large amplitude) and 8 (double pendulum) of
the Lagrange seminars, and energy conservation of a conservative
double pendulum over 100 periods.

Both pendulums swing in the x–z plane about revolute joints along y with gravity along
−z; the bobs are point masses at r_c = (0, 0, −l). A positive angle θ moves the bob to
x = −l sin θ, the mirror image of the seminars' figure; the equations are unchanged.
"""

import numpy as np
import pytest
from scipy.special import ellipe, ellipk

import projeq as pq
from _linear import normal_modes

G = 9.81

# Algebraic identities (2×2 solves, trigonometric terms): exact to a few ulps of the
# largest term, so 100 ε of it. Measured: the simple pendulum's θ̈ 1.8e-15 at g/l = 12.3 and M
# 1.1e-16 relative; the double pendulum's M 4.4e-16 at m l² = 0.64 and s̈ 1.4e-14 at a term scale
# of 43 (3.3e-16 of it, 1.5 ε).
ALGEBRAIC = 100 * np.finfo(float).eps


# --- Problem 7: simple pendulum -----------------------------------------------------------

M7, L7 = 1.3, 0.8


def simple_pendulum():
    return pq.System({"bob": pq.PointMass(M7, (0.0, 0.0, -L7))}, {"bob": pq.Revolute(axis="y")},
                     gravity=(0.0, 0.0, -G))


def pendulum_period(theta0, l=L7, g=G):
    """T = 4 √(l/g) K(sin(θ₀/2)): Problem 7, eq. (23). scipy's ellipk takes the parameter
    m = k² = sin²(θ₀/2)."""
    return 4 * np.sqrt(l / g) * ellipk(np.sin(theta0 / 2) ** 2)


def period_energy_sensitivity(theta0):
    """κ_E = m g l |∂ ln T/∂E| at the energy E = −m g l cos θ₀ of the swing, from eq. (23):
    with m = sin²(θ₀/2), dK/dm = (E(m) − (1 − m) K(m)) / (2 m (1 − m)) and
    dm/dE = 1/(2 m g l), so κ_E = (dK/dm) / (2 K). It grows without bound towards the
    separatrix θ₀ → π and tends to 1/8 for small swings."""
    m = np.sin(theta0 / 2) ** 2
    dK_dm = (ellipe(m) - (1 - m) * ellipk(m)) / (2 * m * (1 - m))
    return dK_dm / (2 * ellipk(m))


def measured_period(res):
    """Time between the first two downward zero crossings of θ (events)."""
    crossings = res.t_events[0]
    assert len(crossings) >= 2, f"only {len(crossings)} zero crossings of θ found"
    return crossings[1] - crossings[0]


def theta_down(t, q, s_dot):
    return q[0]


theta_down.direction = -1

AMPLITUDES = [0.1, 1.0, 2.0, 2.5, 3.0]  # rad; 3.0 is 8° short of the upright position


def test_simple_pendulum_equation_of_motion():
    """Problem 7, eqs. (1), (4), (5) of the Lagrange seminars:
    m l² θ̈ + m g l sin θ = 0, i.e. θ̈ = −(g/l) sin θ at any state; M = m l²."""
    system = simple_pendulum()
    for theta in np.linspace(-3.0, 3.0, 7):
        for theta_dot in (0.0, 2.5):
            s_ddot = system.accelerations([theta], [theta_dot])[0]
            assert s_ddot == pytest.approx(-G / L7 * np.sin(theta), rel=ALGEBRAIC, abs=ALGEBRAIC * G / L7)
            assert system.mass_matrix([theta])[0, 0] == pytest.approx(M7 * L7**2, rel=ALGEBRAIC, abs=0)


@pytest.mark.parametrize("theta0", AMPLITUDES, ids=[f"theta0={a}" for a in AMPLITUDES])
def test_simple_pendulum_period(theta0):
    """Problem 7, eq. (23) of the Lagrange seminars: the period of a
    swing of amplitude θ₀ is 4 √(l/g) K(sin(θ₀/2)), measured between the first two
    downward zero crossings of θ after release from rest at θ₀.
    """
    system = simple_pendulum()
    T_ref = pendulum_period(theta0)
    rtol, atol = 1e-10, 1e-12
    res = pq.simulate(system, 1.3 * T_ref, q0=[theta0], s_dot0=[0.0], method="DOP853", rtol=rtol, atol=atol,
                      events=[theta_down])
    # The integrator keeps local errors at rtol of the state; the computed swing is then
    # one with an energy off by a few rtol·m g l (changing T by κ_E of that, relatively)
    # and a phase off by a few rtol·T. So |ΔT| ≲ c rtol T (1 + κ_E) with c a small number:
    # 5, as in scipy's solve_ivp tests. κ_E ≈ 0.13 at 0.1 rad and 12 at 3.0 rad. Measured:
    # c = 0.054, 0.013, 0.023, 0.12, 0.65 at the five amplitudes (5 is 7.7 times the largest).
    err = abs(measured_period(res) - T_ref) / (rtol * T_ref * (1 + period_energy_sensitivity(theta0)))
    assert err < 5


def test_simple_pendulum_period_default_segments():
    """Problem 7, eq. (23) of the Lagrange seminars, as a user runs it:
    default segmentation (n_segments = 20) with 31 output times, so that the segment ends
    fall between output times. Same amplitude, tolerances and bound as
    test_simple_pendulum_period[theta0=1.0]."""
    system = simple_pendulum()
    theta0 = 1.0
    T_ref = pendulum_period(theta0)
    rtol, atol = 1e-10, 1e-12
    t_end = 1.3 * T_ref
    res = pq.simulate(system, t_end, q0=[theta0], s_dot0=[0.0], method="DOP853", rtol=rtol, atol=atol,
                      events=[theta_down], t_eval=np.linspace(0.0, t_end, 31))
    # measured 0.0127, as test_simple_pendulum_period[theta0=1.0] (whose bound 5 covers all amplitudes)
    err = abs(measured_period(res) - T_ref) / (rtol * T_ref * (1 + period_energy_sensitivity(theta0)))
    assert err < 0.13


# --- Problem 8: double pendulum ------------------------------------------------------------
#
# The scene's coordinates are q = (θ₁, θ₂) with θ₂ relative to the first rod; the seminars'
# are the absolute angles (φ, ψ) = (θ₁, θ₁ + θ₂) = P q with P = [[1, 0], [1, 1]].

M8, L8 = 1.3, 0.7
P = np.array([[1.0, 0.0], [1.0, 1.0]])


def double_pendulum(q0=(0.0, 0.0), m=M8, l=L8):
    return pq.scenes.double_pendulum(m, m, l, l, G, q0=q0)


def seed_accelerations(phi, psi, phi_dot, psi_dot, g=G, l=L8):
    """(φ̈, ψ̈) from Lagrange's equations (38) of Problem 8:
    2φ̈ + ψ̈ cos(φ − ψ) + ψ̇² sin(φ − ψ) + 2 (g/l) sin φ = 0,
    ψ̈ + φ̈ cos(φ − ψ) − φ̇² sin(φ − ψ) + (g/l) sin ψ = 0."""
    c, s = np.cos(phi - psi), np.sin(phi - psi)
    A = np.array([[2.0, c], [c, 1.0]])
    rhs = -np.array([psi_dot**2 * s + 2 * g / l * np.sin(phi), -(phi_dot**2) * s + g / l * np.sin(psi)])
    return np.linalg.solve(A, rhs)


def test_double_pendulum_equations_of_motion():
    """Problem 8, eqs. (35) and (38) of the Lagrange seminars, at random
    states: M = Pᵀ M_seed P with M_seed = m l² [[2, cos(φ − ψ)], [cos(φ − ψ), 1]] from
    T (35), and s̈ = P⁻¹ (φ̈, ψ̈) of (38); recursive and dense evaluators agree."""
    system = double_pendulum()
    rng = np.random.default_rng(8)
    for q, s_dot in zip(rng.uniform(-np.pi, np.pi, size=(5, 2)), rng.normal(scale=3.0, size=(5, 2))):
        phi, psi = P @ q
        phi_dot, psi_dot = P @ s_dot
        c = np.cos(phi - psi)
        M_seed = M8 * L8**2 * np.array([[2.0, c], [c, 1.0]])
        np.testing.assert_allclose(system.mass_matrix(q), P.T @ M_seed @ P, rtol=ALGEBRAIC,
                                   atol=ALGEBRAIC * M8 * L8**2)
        expected = np.linalg.solve(P, seed_accelerations(phi, psi, phi_dot, psi_dot))
        scale = G / L8 + np.abs(s_dot).max() ** 2  # size of the terms that are summed
        for method in ("recursive", "dense"):
            np.testing.assert_allclose(system.accelerations(q, s_dot, method=method), expected, rtol=0,
                                       atol=ALGEBRAIC * scale)


def test_double_pendulum_small_oscillations():
    """Problem 8, eqs. (40)–(52) of the Lagrange seminars: the
    linearisation about the hanging position has ω² = (g/l)(2 ∓ √2) (47), the slow mode
    in phase with B = √2 A (49), the fast one in opposition with B = −√2 A (51) (absolute
    amplitudes A of φ, B of ψ), and ω₂/ω₁ = √((2 + √2)/(2 − √2)) = 1 + √2 (52)."""
    system = double_pendulum()
    omega2, modes, _, _ = normal_modes(system, [0.0, 0.0])
    # central differences of b (sin terms): truncation h²/6 ≈ 2e-11 and round-off
    # eps·|b|/h ≈ 1e-11 relative at h = 1e-5 (_linear.FD_STEP); measured 1.7e-11 relative
    lin = 2e-10
    np.testing.assert_allclose(omega2, G / L8 * np.array([2 - np.sqrt(2), 2 + np.sqrt(2)]), rtol=lin)
    # at the hanging position every stiffness term is a sin, whose central difference is
    # (1 − h²/6) times its derivative: the truncation scales K as a whole and leaves the mode
    # shapes and the frequency ratio exact to round-off (measured 6.3e-16 and 3.7e-16 relative)
    exact = 100 * np.finfo(float).eps
    absolute = P @ modes
    np.testing.assert_allclose(absolute[1] / absolute[0], [np.sqrt(2), -np.sqrt(2)], rtol=exact)
    ratio = np.sqrt(omega2[1] / omega2[0])
    assert ratio == pytest.approx(np.sqrt((2 + np.sqrt(2)) / (2 - np.sqrt(2))), rel=exact, abs=0)
    assert ratio == pytest.approx(1 + np.sqrt(2), rel=exact, abs=0)


def test_double_pendulum_slow_mode_period():
    """Problem 8, eqs. (47) and (49) of the Lagrange seminars,
    simulated: released from rest in the slow mode, (φ, ψ) = ε (1, √2), the pendulum
    swings with the period 2π/ω₁, ω₁² = (g/l)(2 − √2).

    At a finite amplitude the period is T(ε) = T₀ (1 + c ε² + O(ε⁴)) (eq. (26) for one
    pendulum); runs at ε and 2ε and Richardson extrapolation (4 T(ε) − T(2ε))/3 remove the
    ε² term, leaving O(ε⁴) ≈ 1e-12 at ε = 1e-3, far below the integration error.
    """
    system = double_pendulum()
    T0 = 2 * np.pi / np.sqrt(G / L8 * (2 - np.sqrt(2)))
    eps, rtol = 1e-3, 1e-10

    def period(amplitude):
        q0 = np.linalg.solve(P, amplitude * np.array([1.0, np.sqrt(2)]))
        res = pq.simulate(system, 1.3 * T0, q0=q0, s_dot0=[0.0, 0.0], method="DOP853", rtol=rtol,
                          atol=rtol * amplitude, events=[theta_down])
        return measured_period(res)

    T_extrapolated = (4 * period(eps) - period(2 * eps)) / 3
    # each period is measured to a few rtol·T (see test_simple_pendulum_period, κ_E ≈ 1/8
    # here), the extrapolation weights (4 + 1)/3 ≈ 1.7; measured 0.13 rtol·T
    assert abs(T_extrapolated - T0) / (rtol * T0) < 1.3


@pytest.mark.slow
def test_double_pendulum_energy_100_periods():
    """Energy conservation of a conservative double pendulum (Problem 8 of
    the Lagrange seminars; an energy-conservation check): equal masses and lengths (m = 1 kg, l = 1 m), released from rest at
    θ₁ = 0.5 rad, θ₂ = 0 (a moderate, non-modal amplitude), integrated by DOP853 at
    rtol = 1e-11 over 100 periods of the slow small oscillation, 100 · 2π/ω₁ with
    ω₁² = (g/l)(2 − √2) (eq. (47)), i.e. 262 s. ``res.energy_drift`` (max |E − E₀| over the
    largest kinetic or potential energy) stays below 5e-11 (measured 2.6e-12).
    """
    m, l = 1.0, 1.0
    system = double_pendulum(q0=(0.5, 0.0), m=m, l=l)
    t_end = 100 * 2 * np.pi / np.sqrt(G / l * (2 - np.sqrt(2)))
    res = pq.simulate(system, t_end, method="DOP853", rtol=1e-11, atol=1e-12, n_points=2001)
    # default segmentation: its restart bug (see test_simple_pendulum_period_default_segments)
    # shifts the trajectory in time, which leaves the energy of this autonomous system alone
    assert res.success
    # About 1e4 steps (nfev/12), each with a local error ≲ rtol, accumulate like a random walk
    # to ~√1e4 · rtol = 1e-9 at most. Measured 2.6e-12 (2.7e-12 and 4.1e-12 released at θ₁ = 0.4
    # and 0.6 rad): the bound is 10 times the largest; a dissipative or energy-injecting error in
    # the Gauss form of even 1e-13 per step would exceed it
    assert res.energy_drift < 5e-11, f"energy drift {res.energy_drift:.2g} (measured 2.6e-12)"

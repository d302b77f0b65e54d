"""Identities from physics at single states (STYLE §4.8 item 3)."""

import numpy as np
import pytest

import projeq as pq
from projeq.assembly.kinematics import forward
from projeq.subsystems.rigid import rigid_h, rigid_mass_matrix

ROUND_OFF = 100 * np.finfo(float).eps  # identities that hold to round-off: 100 ε


def _mixed_tree():
    """Free, revolute, prismatic and planar joints; gravity; a spring-damper and a spring
    on a joint (conservative when the damping is zero)."""
    body = pq.RigidBody(1.3, (0.1, -0.2, 0.3), np.array([[0.5, 0.1, 0.0], [0.1, 0.6, 0.05], [0.0, 0.05, 0.4]]))
    return pq.System(
        {"base": body, "arm": body, "slider": body, "tip": body},
        {
            "base": pq.Free(),
            "arm": pq.Revolute("base", (1.0, 1.0, 0.0), (0.3, 0.0, -0.5)),
            "slider": pq.Prismatic("arm", "x", (0.0, 0.4, 0.0)),
            "tip": pq.Planar("slider", "zx", (0.2, 0.1, 0.0)),
        },
        gravity=(0.0, 0.0, -9.81),
        forces=[
            pq.SpringDamper(None, (0.0, 0.0, 1.0), "tip", (0.1, 0.0, 0.0), stiffness=20.0, length=0.5),
            pq.JointSpring("arm", 3.0),
        ],
    )


def _state(system, seed):
    rng = np.random.default_rng(seed)
    return system.normalized(rng.uniform(-1, 1, system.n_q)), rng.uniform(-1, 1, system.n_s)


@pytest.mark.parametrize("seed", range(3))
def test_kinetic_energy_from_M_equals_the_sum_over_subsystems(seed):
    """½ ṡᵀ M(q) ṡ = Σ ½ ẏ_nᵀ M_n ẏ_n for a scleronomic system (docs/theory.md §5 with J_n), to 100 ε
    (measured 2.4e-16 relative; was 1e-12 and pytest's default abs 1e-12)."""
    system = _mixed_tree()
    q, s_dot = _state(system, seed)
    kinetic, _ = system.energy(q, s_dot)
    assert 0.5 * s_dot @ system.mass_matrix(q) @ s_dot == pytest.approx(kinetic, rel=ROUND_OFF, abs=0)


@pytest.mark.parametrize("seed", range(3))
def test_power_balance_of_a_conservative_system(seed):
    """d(T + V)/dt = 0 along (q̇, s̈) without damping or drive. Central differences of step
    1e-6 in time along the state derivative: error ~ h² |E‴| + ε/h, so 1e-7 of the
    energy's rate scale (|ṡ|·|M s̈|) is a safe bound."""
    system = _mixed_tree()
    q, s_dot = _state(system, seed)
    s_ddot = system.accelerations(q, s_dot)
    q_dot = system.q_dot(q, s_dot)
    h = 1e-6

    def energy(sign):
        return sum(system.energy(system.normalized(q + sign * h * q_dot), s_dot + sign * h * s_ddot))

    rate = (energy(+1) - energy(-1)) / (2 * h)
    scale = np.abs(s_dot).max() * np.abs(system.mass_matrix(q) @ s_ddot).max()
    assert abs(rate) < 1e-7 * scale


@pytest.mark.parametrize("seed", range(3))
def test_rigid_terms_match_newton_euler_about_the_mass_centre(seed):
    """docs/theory.md §3 against Newton–Euler written independently: with v_c = v + ω × r_c,
    f = m (v̇_c + ω × v_c) − m g and M_c = I_c ω̇ + ω × I_c ω, the wrench about O is
    (f, M_c + r_c × f); it must equal M ÿ − h for any ÿ (1e-12 relative)."""
    rng = np.random.default_rng(seed)
    m, r_c = 1.7, rng.uniform(-1, 1, 3)
    A = rng.standard_normal((3, 3))
    I_c = A @ A.T + np.eye(3)
    twist, y_ddot, g = rng.standard_normal(6), rng.standard_normal(6), rng.standard_normal(3)
    v, omega, v_dot, omega_dot = twist[:3], twist[3:], y_ddot[:3], y_ddot[3:]
    v_c = v + np.cross(omega, r_c)
    v_c_dot = v_dot + np.cross(omega_dot, r_c)  # body-frame rate of v_c's components
    f = m * (v_c_dot + np.cross(omega, v_c)) - m * g
    M_c = I_c @ omega_dot + np.cross(omega, I_c @ omega)
    wrench = np.concatenate((f, M_c + np.cross(r_c, f)))
    residual = rigid_mass_matrix(m, r_c, I_c) @ y_ddot - rigid_h(m, r_c, I_c, twist, g)
    # measured 2.9e-15 relative, 1.3e-15 at a size of 6 (was 1e-12)
    assert np.allclose(residual, wrench, rtol=ROUND_OFF, atol=ROUND_OFF * np.abs(wrench).max())


def test_functional_matrix_is_the_coefficient_of_s_dot():
    """J_n = ∂ẏ_n/∂ṡ: ẏ_n is linear in ṡ for a scleronomic system, so ẏ_n(ṡ) equals
    Σ_k ṡ_k ẏ_n(e_k) exactly (B(11): 'nothing but the coefficient matrix')."""
    system = _mixed_tree()
    q, s_dot = _state(system, 0)
    columns = [forward(system, q, e, 0.0).y_dot[:-1] for e in np.eye(system.n_s)]
    combined = forward(system, q, s_dot, 0.0).y_dot[:-1]
    for n, y_dot in enumerate(combined):
        # measured 2.2e-16 (was 1e-13 and allclose's default rtol 1e-5)
        expected = sum(s_dot[k] * columns[k][n] for k in range(system.n_s))
        assert np.allclose(y_dot, expected, rtol=0, atol=ROUND_OFF)


def test_evaluators_give_identical_results_when_called_again():
    """Workspace reuse (Pinocchio's 'multiple calls'): the same inputs give bit-identical
    results, also when calls alternate with another state."""
    system = _mixed_tree()
    (q1, s1), (q2, s2) = _state(system, 1), _state(system, 2)
    for method in ("recursive", "dense"):
        first = system.accelerations(q1, s1, method=method)
        system.accelerations(q2, s2, method=method)
        assert np.array_equal(system.accelerations(q1, s1, method=method), first)

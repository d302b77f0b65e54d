"""Barhorst's canonical momentum forms (Barhorst eqs. 28–37 and 45–52) against
projeq's numeric Projection-Equation simulation, for the knife-edge disc and Barhorst's particle."""


import numpy as np
import pytest
import sympy as sp

from projeq.scenes.nonholonomic import barhorst_particle
from projeq.simulation.driver import simulate
from projeq.symbolic.canonical import lagrangian_canonical, projective_canonical
from projeq.symbolic.formulation_examples import lecture_disc, particle, projective_disc
from projeq.symbolic.projection import Body, t

from .test_lagrange import ATOL, RTOL, disc_reference

Q_DISC, U_DISC = sp.symbols("x y z psi phi theta"), sp.symbols("u1:4")  # as in projective_disc()


@pytest.mark.parametrize("form", ["lagrangian", "projective"])
def test_disc_canonical_forms_follow_the_projection_equation(form):
    """Same initial state as projeq's PE run; (x, y, ψ, ϕ, θ) agree to 6e-11 over 1 time unit (both at
    rtol = 1e-11; measured 5.9e-12 for both forms); the speeds u(p) reproduce the PE's ṡ = (ψ̇, ϕ̇, θ̇) to
    3.7e-10 (measured 3.6e-11; both were 1000 × rtol = 1e-8)."""
    reference, q0, q_dot0 = disc_reference()
    canonical = lagrangian_canonical(lecture_disc()) if form == "lagrangian" else projective_disc()
    sol = canonical.simulate(q0, q_dot0[3:], (0, reference.t[-1]), t_eval=reference.t,
                             rtol=RTOL, atol=ATOL)
    assert sol.success
    assert np.abs(sol.q[[0, 1, 3, 4, 5]].T - reference.q).max() < 6e-11
    assert np.abs(sol.u.T - reference.s_dot).max() < 3.7e-10


def test_both_momenta_are_dT_du_and_agree_at_random_states():
    """Barhorst's projective momenta (28) and Lagrangian momenta (45) both equal ∂T/∂u (the projected
    momenta); checked numerically at 5 random states (round-off: 100 ε of max |p|, measured ≤ 1.6e-16;
    was 1e-12)."""
    lagrangian, projective = lagrangian_canonical(lecture_disc()), projective_disc()
    rng = np.random.default_rng(1)
    for _ in range(5):
        q, u = rng.uniform(-1, 1, 6), rng.uniform(-2, 2, 3)
        p_l, p_p = lagrangian.momenta(0.0, q, u), projective.momenta(0.0, q, u)
        assert np.abs(p_l - p_p).max() <= 100 * np.finfo(float).eps * np.abs(p_p).max(), p_l - p_p


def test_lagrangian_kinematics_come_from_the_constraint_matrix():
    """K from A (slide 30): the dependent rows are −A_ρ⁻¹ A_λ, the same K as the projective input."""
    assert sp.simplify(lagrangian_canonical(lecture_disc()).K.subs(
        dict(zip(sp.symbols("psi_dot phi_dot theta_dot"), U_DISC))) - projective_disc().K) == sp.zeros(6, 3)


@pytest.mark.parametrize("form", ["lagrangian", "projective"])
def test_barhorst_particle_canonical_forms_follow_the_projection_equation(form):
    """Barhorst §3.1 particle from (2, 2), ẋ = 0.5: matches projeq's scene to 1.1e-9 over 0.3 s (measured
    1.09e-10 for both forms) and conserves E = ½(ẋ² + ẏ²) + 10 y to 7e-10 relative (measured 7.0e-11; both
    were 1000 × rtol = 1e-8)."""
    system = barhorst_particle(s_dot0=(0.5,))
    reference = simulate(system, 0.3, t_eval=np.linspace(0, 0.3, 16), rtol=RTOL, atol=ATOL, method="DOP853")
    if form == "lagrangian":
        canonical = lagrangian_canonical(particle(), independent=particle().q[:1])
    else:
        qx, qy, u = sp.symbols("x y u")
        body = Body(v_c=(u, qy**2 * u, 0), omega=(0, 0, 0), m=1, I_c=sp.zeros(3, 3), f=(0, -10, 0))
        canonical = projective_canonical([body], (qx, qy), (u,), [[1], [qy**2]], t)
    sol = canonical.simulate(system.q0, system.s_dot0, (0, 0.3), t_eval=reference.t, rtol=RTOL, atol=ATOL)
    energy = 0.5 * sol.u[0] ** 2 * (1 + sol.q[1] ** 4) + 10 * sol.q[1]
    assert np.abs(sol.q.T - reference.q).max() < 1.1e-9, np.abs(sol.q.T - reference.q).max()
    assert np.abs(energy - energy[0]).max() < 7e-10 * abs(energy[0]), np.abs(energy - energy[0]).max()


def test_mismatched_K_is_refused():
    with pytest.raises(ValueError, match="K: expected a 6 × 3 matrix"):
        projective_canonical([], Q_DISC, U_DISC, sp.zeros(6, 2), t)


def test_body_vectors_must_be_3_vectors():
    with pytest.raises(ValueError, match=r"bodies\[0\].v_c: expected a 3-vector"):
        projective_canonical([Body((1, 0), (0, 0, 0), 1, sp.eye(3))], Q_DISC, U_DISC, sp.zeros(6, 3), t)


def test_undeclared_symbols_are_named():
    k = sp.Symbol("k")
    with pytest.raises(ValueError, match="bodies: undeclared symbols k"):
        projective_canonical([Body((0, 0, 0), (0, 0, 0), k, sp.eye(3))], Q_DISC, U_DISC, sp.zeros(6, 3), t)


def test_inhomogeneous_constraint_gives_an_offset_J():
    """A q̇ = b with b ≠ 0 (Barhorst eqs. 10–11 with an affine term): a free unit mass with ẋ + ẏ = 1 and
    u = ẋ independent has ẏ = 1 − u, so q̇ = K u + J with K = (1, −1), J = (0, 1), p = Kᵀ ∂L/∂q̇ = 2u − 1 and
    ṗ = 0 (no force along the admissible direction (1, −1))."""
    from projeq.symbolic.lagrange import multiplier_system
    from sympy.physics.mechanics import dynamicsymbols
    qx, qy = dynamicsymbols("x y")
    system = multiplier_system((qx.diff(t) ** 2 + qy.diff(t) ** 2) / 2, [qx, qy], t, A=[[1, 1]], b=[1])
    canonical = lagrangian_canonical(system, independent=[qx])
    (u,) = canonical.u
    assert canonical.K == sp.Matrix([1, -1]) and canonical.J == sp.Matrix([0, 1])
    assert sp.expand(canonical.p[0] - (2 * u - 1)) == 0 and canonical.p_dot == sp.zeros(1, 1)


def test_initial_state_sizes_are_checked():
    with pytest.raises(ValueError, match="q0, u0: expected 6 coordinates and 3 speeds"):
        projective_disc().simulate(np.zeros(6), np.zeros(2), (0, 1))


def test_barhorst_particle_projective_equations_are_his_74_to_77():
    """Barhorst's own choice u = ẏ (A12 = 1/y², Barhorst §3.1.3): p₂ = m u₂ (1 + 1/y⁴) (74), Q₂ = −m g (76),
    P₂ = L · d/dt(n̂₂ + n̂₁/y²) = −2 m u₂²/y⁵ (77); the Lagrangian form (45) gives the same p₂ and ṗ₂."""
    qx, qy, u2, mass, grav = sp.symbols("x y u_2 m g")
    body = Body(v_c=(u2 / qy**2, u2, 0), omega=(0, 0, 0), m=mass, I_c=sp.zeros(3, 3), f=(0, -mass * grav, 0))
    projective = projective_canonical([body], (qx, qy), (u2,), [[1 / qy**2], [1]], t, {mass: 1, grav: 10})
    assert sp.simplify(projective.p[0] - mass * u2 * (1 + 1 / qy**4)) == 0
    assert sp.simplify(projective.p_dot[0] - (-mass * grav - 2 * mass * u2**2 / qy**5)) == 0
    lagrangian = lagrangian_canonical(particle(), independent=particle().q[1:])
    on_u = {lagrangian.u[0]: u2, mass: 1, grav: 10}
    assert sp.simplify((lagrangian.p[0] - projective.p[0]).subs(on_u)) == 0
    assert sp.simplify((lagrangian.p_dot[0] - projective.p_dot[0]).subs(on_u)) == 0

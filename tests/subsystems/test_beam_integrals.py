"""Precomputed shape integrals (projeq/subsystems/beam/integrals.py) against the quadrature
mode (projeq/subsystems/beam/beam.py): a second evaluation of the same integrals of B(25), one
per call at the stations, one from moments computed once. The model is polynomial in q_e,
so the two must agree to round-off at any deformation, not only to first order."""

import numpy as np
import pytest

import projeq as pq
from projeq.scenes.elastic import spin_up_beam
from projeq.subsystems import RitzBeam


def _pair(**knobs):
    args = dict(length=2.0, rho_A=1.0, EI_z=20.0, n_v=3, n_w=2, n_u=2, EA=50.0, rho_I=(1e-3, 2e-3), **knobs)
    return RitzBeam(**args), RitzBeam(precomputed_integrals=True, **args)


def _terms(beam, scale, seed=0):
    """(M_n, h_n) at q_e = scale q̂, a random motion of order one, gravity and frame."""
    rng = np.random.default_rng(seed)
    y_dot, q_hat = rng.standard_normal(beam.n_y), rng.standard_normal(beam.n_e)
    R, gravity = np.linalg.qr(rng.standard_normal((3, 3)))[0], np.array([0.0, 0.0, -9.81])
    return beam.gauss_terms(y_dot, R, gravity, scale * q_hat)


@pytest.mark.parametrize("stiffening", [True, False])
@pytest.mark.parametrize("scale", [0.0, 0.05, 0.5])
def test_precomputed_equals_quadrature_at_any_deformation(stiffening, scale):
    """Undeformed, small (v/L ~ 3 %) and large (v/L ~ 30 %, far beyond the first-order
    mode this replaces) deformations, with axial and rotary terms: equal to 100 ε of the
    terms' scale (the quadrature's own round-off; the moments are the same Gauss sums
    reordered; measured ≤ 3.5e-16 for M, 2.2e-16 for h; was 1e-12)."""
    quadrature, precomputed = _pair(stiffening=stiffening)
    (Ma, ha), (Mb, hb) = _terms(quadrature, scale), _terms(precomputed, scale)
    exact = 100 * np.finfo(float).eps
    assert np.abs(Ma - Mb).max() <= exact * np.abs(Ma).max()
    assert np.abs(ha - hb).max() <= exact * np.abs(ha).max()


def test_monomial_derivatives():
    """Z = ∂z/∂q by central differences (exact for the quadratic z: 100 ε; measured 2.5e-16, was 1e-12
    and assert_allclose's default rtol 1e-7) and Ż q̇ = d/dt (Z) q̇ = ∂/∂q (Z q̇) q̇, the same difference
    applied to Z q̇ (measured 3.1e-17)."""
    beam = _pair()[1]
    integrals, rng = beam.integrals, np.random.default_rng(1)
    q, q_dot = rng.standard_normal(beam.n_e), rng.standard_normal(beam.n_e)
    z, Z, z_dd = integrals.monomials(q, q_dot)
    z_ahead, z_behind = integrals.monomials(q + q_dot, q_dot)[0], integrals.monomials(q - q_dot, q_dot)[0]
    np.testing.assert_allclose(Z @ q_dot, 0.5 * (z_ahead - z_behind), rtol=0, atol=100 * np.finfo(float).eps)
    Z_ahead, Z_behind = integrals.monomials(q + q_dot, q_dot)[1], integrals.monomials(q - q_dot, q_dot)[1]
    np.testing.assert_allclose(z_dd, 0.5 * (Z_ahead - Z_behind) @ q_dot, rtol=0,
                               atol=100 * np.finfo(float).eps)
    assert z.shape == (integrals.n_z,) and integrals.n_z == 1 + beam.n_e + beam.n_v**2 + beam.n_w**2


def test_recursive_equals_dense_in_the_precomputed_mode():
    """docs/theory.md §5 = §6 hold for either mode (both assemblers call the same terms): 6e-12 of |s̈|
    (measured 4.8e-13; at most 5.8e-13 over 12 random states, κ(M) ≈ 6e4; was 1e-10)."""
    _, beam = _pair()
    system = pq.System(
        {"hub": pq.RigidBody(1.0, (0, 0, 0), np.diag([0.5, 0.5, 0.2])), "beam": beam},
        {"hub": pq.Revolute(axis="z"), "beam": pq.Fixed(parent="hub", r_pn=(0.1, 0, 0))},
        gravity=(0, 0, -9.81),
    )
    rng = np.random.default_rng(2)
    q, s_dot = rng.uniform(-0.05, 0.05, system.n_q), rng.uniform(-1, 1, system.n_s)
    a = system.accelerations(q, s_dot, method="recursive")
    b = system.accelerations(q, s_dot, method="dense")
    assert np.abs(a - b).max() <= 6e-12 * np.abs(b).max(), np.abs(a - b).max() / np.abs(b).max()


def test_spin_up_tip_deflection_of_both_modes():
    """A fast spin-up (Ωs = 4 rad/s in Ts = 5 s, 2 eigenfunctions per plane, 8 s) bends
    the tip by v(L) ≈ 1.2 m (v/L = 12 %, where the former first-order mode was 1.5 % off):
    both modes integrate the same equations, so their tip deflections agree to round-off, 100 ε of
    the peak (measured 1.0e-15; 5.4e-16 and 4.9e-16 at rtol 2e-6 and 5e-7: the steps coincide). The
    recursive evaluator calls each mode's own terms; the compiled hub_beam kernel, which this test
    took before, evaluates the beam's fields itself and gave both runs the same numbers (difference
    exactly 0 against the bound 1e-6 of the peak then: a test that could not fail)."""
    tips = []
    for precomputed in (False, True):
        system = spin_up_beam(
            omega_s=4.0, t_s=5.0, n_shapes=2, family="clamped_free", precomputed_integrals=precomputed
        )
        result = pq.simulate(system, 8.0, method="RK45", rtol=1e-6, atol=1e-8, n_points=41,
                             evaluator="recursive")
        tips.append(system.subsystem("beam").deflection(result, 10.0)[:, 1])
    peak = np.abs(tips[0]).max()
    assert peak > 0.5  # a large deflection indeed
    difference = np.abs(tips[0] - tips[1]).max()
    assert difference < 100 * np.finfo(float).eps * peak, difference / peak

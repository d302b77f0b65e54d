"""The independent model of the spinning beam (H. Bremer, "Problems in fast moving
non-holonomic elastic systems", B(16)–(23)): a chain of rigid slices with their rotary
inertia, joined by bending joints with springs, converged in the number of slices. It
decides between the ρI α̈ couplings of B(18), B(23) and the beam without torsional strain
(docs/theory.md, "The spinning beam's rotary inertia"); the numeric RitzBeam is checked
against the latter in tests/symbolic/test_spinning_beam.py."""

import numpy as np
import pytest

from projeq.scenes.elastic import spin_up_motion
from projeq.subsystems.beam.slice_chain import SliceChain, extrapolated_model
from projeq.symbolic import spinning_beam as sb

RHO_I = 0.05


@pytest.fixture(scope="module")
def ritz():
    return sb.ritz_models(2, rho_I_value=RHO_I)


def _spin_up(model):
    a0 = np.array([0.01, 0.0, 0.0, 0.0])
    return sb.simulate_ritz(model, spin_up_motion(3.0, 2.0), a0, np.zeros(4), 3.0)[1]


def test_spin_up_chain_converges_to_the_torsion_free_beam_not_B18_or_B23(ritz):
    """Spin-up of spin_up_motion(3, 2), ρI = 0.05, a0 = (0.01, 0, 0, 0), 3 s. The chain's
    convergence error is measured: extrapolated chains of 10/20/40 and 20/40/80 slices
    differ by 1.6e-5 (the finer one is ~10× closer: error 1.4e-6 to the torsion-free
    model). The torsion-free Ritz model lies within that error; B(18) and B(23) are 1.3e-3
    away, ~80× the error."""
    coarse, fine = (_spin_up(extrapolated_model(n, rho_I=RHO_I)) for n in (10, 20))
    error = np.max(np.abs(fine - coarse))
    assert error < 3e-5
    distance = {name: np.max(np.abs(fine - _spin_up(model))) for name, model in ritz.items()}
    assert distance["torsion_free"] < error
    assert min(distance["hamilton"], distance["projection"]) > 50 * error


def test_chain_matrices_converge_to_the_torsion_free_ritz_model(ritz):
    """Entry by entry (shortest-way joints, 20 and 40 slices, extrapolated): measured
    M 2.5e-7, G 4.5e-7, K 1.8e-5, K_c 1.9e-7, C 9.0e-7 from the torsion-free model; its C
    differs from B(23)'s and B(18)'s by ≥ 0.05."""
    chain = extrapolated_model(20, rho_I=RHO_I)
    for name, tolerance in (("M", 1e-6), ("G", 2e-6), ("K", 5e-5), ("K_c", 1e-6), ("C", 3e-6)):
        np.testing.assert_allclose(getattr(chain, name), getattr(ritz["torsion_free"], name), atol=tolerance)
    for name in ("hamilton", "projection"):
        assert np.max(np.abs(chain.C - ritz[name].C)) > 0.05


def test_revolute_joint_pairs_add_twist_of_order_dx():
    """A Cardan joint (y then z) twists its slice by ½βγ: the chain's C differs from the
    shortest-way chain's by O(Δx) — measured 7.5e-3 at 20 slices, halved at 40 — with the
    opposite sign for the other joint order (z then y; symmetric to 1.4e-11, measured 1.3e-12 of the gap
    7.5e-3; was atol 1e-9 with assert_allclose's rtol 1e-7)."""
    C = {(joint, n): SliceChain(n, rho_I=RHO_I, joint=joint).linear_model().C
         for joint, n in (("yz", 20), ("zy", 20), ("shortest", 20), ("yz", 40), ("shortest", 40))}
    gap = {n: np.max(np.abs(C["yz", n] - C["shortest", n])) for n in (20, 40)}
    assert 1.9 < gap[20] / gap[40] < 2.1
    np.testing.assert_allclose(C["yz", 20] - C["shortest", 20], C["shortest", 20] - C["zy", 20], rtol=0,
                               atol=1.4e-11)


@pytest.mark.parametrize(
    "kwargs, message",
    [({"joint": "ball"}, "joint"), ({"n_slices": 0}, "n_slices"), ({"rho_I": -1.0}, "rho_I")],
)
def test_bad_input(kwargs, message):
    with pytest.raises(ValueError, match=message):
        SliceChain(**{"n_slices": 10, **kwargs})


def test_free_rigid_slice_chain_has_the_rayleigh_beams_frequency():
    """scenes.elastic.rigid_slice_chain (projeq's RigidBody, Cardan UserJoint, JointSpring;
    no Ritz field) at rest: its lowest bending frequency tends to the Rayleigh beam's
    (RitzBeam, 8 clamped–free functions, ρI = 0.05: 3.16312 rad/s) as Δx²: measured errors
    7.24e-2 at 4 slices, 1.83e-2 at 8 (ratio 3.95); extrapolated 3.16284."""
    from projeq.analysis.linearize import linearize
    from projeq.scenes.elastic import rigid_slice_chain
    from projeq.subsystems.beam.beam import RitzBeam

    reference = RitzBeam(1.0, 1.0, 1.0, n_v=8, n_w=8, family="clamped_free", rho_I=(RHO_I, RHO_I)).first_frequency
    frequency = {}
    for n_slices in (4, 8):
        system, q0 = rigid_slice_chain(n_slices, lambda t: (0.0, 0.0, 0.0), rho_I=RHO_I)
        eigenvalues = linearize(system, q0, np.zeros(2 * n_slices)).eigenvalues()
        frequency[n_slices] = np.min(np.abs(eigenvalues.imag[np.abs(eigenvalues.imag) > 1e-6]))
    errors = [reference - frequency[n] for n in (4, 8)]
    assert 3.8 < errors[0] / errors[1] < 4.1
    assert abs((4 * frequency[8] - frequency[4]) / 3 - reference) < 1e-3


@pytest.mark.parametrize("joint", ["shortest", "yz"])
def test_linearised_matrices_are_exact(joint):
    """K_c and C by exact derivatives (the complex step through 𝕄(a)) against closed forms of
    the chain itself. Every slice axis is the centre-line tangent t_i (both joint kinds turn
    e_x into it), so (B_iᵀ e_x)ᵀ I_i (B_iᵀ e_x) = c (1 + 1/(1 + v′² + w′²)) with I_i = c diag(2, 1, 1),
    c = Δx ρI, and 𝕄_αα = m Σ (v_i² + w_i²) + that: K_c = ½ ∂²𝕄_αα/∂a² = blockdiag(K_p, K_p),
    K_p = m Σ Φ_i Φ_iᵀ − c Σ Φ′_i Φ′_iᵀ. C is linear in ρI; its part at ρI = 0 (2 C(ρI) − C(2ρI))
    is the centres' coupling ∂/∂a of m Σ (e_x × r_i) · ∂r_i/∂a = [[0, −P], [P, 0]], P = m Σ Φ_i Φ_iᵀ.
    Both to 100 ε of their largest entry (measured ≤ 1.1e-15, was 1e-13; Richardson's differences left
    1.4e-7 in K_c)."""
    chain, doubled = SliceChain(20, rho_I=RHO_I, joint=joint), SliceChain(20, rho_I=2 * RHO_I, joint=joint)
    model = chain.linear_model()
    P = chain.mass * chain.Phi @ chain.Phi.T
    K_p = P - chain.length / chain.n_slices * RHO_I * chain.Phi_x @ chain.Phi_x.T
    zero = np.zeros_like(P)
    for computed, expected in ((model.K_c, np.block([[K_p, zero], [zero, K_p]])),
                               (2 * model.C - doubled.linear_model().C, np.block([[zero, -P], [P, zero]]))):
        error = np.abs(computed - expected).max() / np.abs(expected).max()
        assert error < 100 * np.finfo(float).eps, error

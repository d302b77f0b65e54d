"""RitzBeam torsion, pinned support, shear-force probes and frequencies about a steady spin,
against closed forms (issue 6)."""

import warnings

import numpy as np
import pytest
from scipy.linalg import eigh

import projeq as pq
from projeq.analysis.linearize import linearize
from projeq.scenes.elastic import spin_up_beam
from projeq.subsystems import RitzBeam
from projeq.subsystems.beam.shapes import pinned_free_roots

L, EI, RHO_A, GI_T, RHO_I_P = 10.0, 1.4e4, 1.2, 3.0e3, 0.02


def _elastic_frequencies(beam, cols):
    """Natural frequencies of the beam on its support from the blocks ``cols`` of M_ee, K_e."""
    M, _ = beam.gauss_terms(np.zeros(beam.n_y), np.eye(3), np.zeros(3), np.zeros(beam.n_e))
    k = np.arange(cols.start, cols.stop) - 6
    return np.sqrt(eigh(beam.K_e[np.ix_(k, k)], M[6:, 6:][np.ix_(k, k)], eigvals_only=True))


def _torsion_reference(n):
    """Fixed–free shaft: ω_k = (2k − 1)π/(2L) √(GI_t/(ρI_p)) (S. S. Rao, Vibration of
    Continuous Systems, Wiley 2007, §5.6 torsional vibration of a fixed–free shaft;
    Meirovitch, Fundamentals of Vibrations, 2001, §8.7)."""
    return (2 * np.arange(1, n + 1) - 1) * np.pi / (2 * L) * np.sqrt(GI_T / RHO_I_P)


def _torsion_beam(n_beta, family):
    return RitzBeam(L, RHO_A, EI, n_v=1, n_w=1, n_beta=n_beta, GI_t=GI_T, rho_I_p=RHO_I_P, family=family)


def test_torsion_frequencies_with_the_shaft_eigenfunctions_are_exact():
    """The fixed–free sines are the torsion eigenfunctions: the first four frequencies to
    quadrature round-off (100 ε; measured 1.9e-16 relative, the bound was 1e-10)."""
    beam = _torsion_beam(4, "clamped_free")
    assert np.allclose(_elastic_frequencies(beam, beam.beta_cols), _torsion_reference(4),
                       rtol=100 * np.finfo(float).eps, atol=0.0)


def test_torsion_frequencies_with_polynomials_converge_from_above():
    """Rayleigh–Ritz with β = Σ (x/L)^k q_k: upper bounds, the first frequency's error
    falling by more than 10 per added function (n = 2 … 5)."""
    beams = [_torsion_beam(n, "polynomial") for n in range(2, 6)]
    errors = np.array([_elastic_frequencies(beam, beam.beta_cols)[0] for beam in beams]) / _torsion_reference(1)[0] - 1.0
    assert np.all(errors > -1e-12)
    assert np.all(errors[1:] < errors[:-1] / 10)


def _hub_with_twisting_beam():
    """A free hub carrying a beam with bending, torsion and rotary inertia, and a rigid
    body on an offset station of it (its pose turns with β: the port's R_x(β))."""
    beam = RitzBeam(
        2.0, 1.0, 20.0, n_v=2, n_w=2, n_beta=2, GI_t=5.0, rho_I=(1e-3, 2e-3), rho_I_p=4e-3
    )
    hub = pq.RigidBody(1.0, (0, 0, 0), np.diag([0.5, 0.5, 0.2]))
    tip = pq.RigidBody(0.2, (0.0, 0.05, 0.02), np.diag([1e-3, 2e-3, 3e-3]))
    return pq.System(
        {"hub": hub, "beam": beam, "tip": tip},
        {
            "hub": pq.Revolute(axis="z"),
            "beam": pq.Fixed(parent="hub", r_pn=(0.1, 0, 0)),
            "tip": pq.Fixed(parent="beam", r_pn=(1.8, 0.1, -0.05)),
        },
        gravity=(0, 0, -9.81),
    )


def test_energy_is_conserved_with_torsion():
    """Free hub, twisting and bending beam, offset tip body, gravity, no damping: energy
    drift below 6e-13 with DOP853 at rtol 1e-10 over 0.5 s (the conservation law checks
    the torsion's rotary-inertia terms and the port's twist kinematics together). Measured 2.2e-14
    (1.1e-14 to 5.4e-14 with q₀ = 0.005, 0.02 and the hub's rate 1, 3 rad/s; the bound was 1e-9)."""
    system = _hub_with_twisting_beam()
    q0 = np.full(system.n_q, 0.01)
    s_dot0 = np.zeros(system.n_s)
    s_dot0[0] = 2.0
    result = pq.simulate(system, 0.5, q0, s_dot0, method="DOP853", rtol=1e-10, atol=1e-12)
    assert result.energy_drift < 6e-13, result.energy_drift
    beam = system.subsystem("beam")
    assert np.ptp(beam.twist(result, 2.0)) > 1e-3  # the beam does twist


def test_recursive_equals_dense_with_torsion():
    """docs/theory.md §5 = §6 with a twisting beam carrying an offset body (relative 2.5e-13: measured
    2.2e-14, 3.8e-15, 3.6e-15 at the three states; the bound was 1e-10)."""
    system = _hub_with_twisting_beam()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, s_dot = rng.uniform(-0.1, 0.1, system.n_q), rng.uniform(-1, 1, system.n_s)
        a = system.accelerations(q, s_dot, method="recursive")
        b = system.accelerations(q, s_dot, method="dense")
        assert np.abs(a - b).max() <= 2.5e-13 * np.abs(b).max()


def test_pinned_free_roots_match_the_catalogue():
    """tan βL = tanh βL: 3.92660231, 7.06858275, 10.21017612 (R. D. Blevins, Formulas for
    Natural Frequency and Mode Shape, 1979, Table 8-1 "pinned–free"), to the table's rounding, 5e-9
    (measured 4.4e-9; the bound was allclose's default rtol 1e-5, 1e-4 here)."""
    assert np.allclose(pinned_free_roots(3), [3.92660231, 7.06858275, 10.21017612], rtol=0.0, atol=5e-9)


def _pinned_free_frequencies(family, n):
    """A beam pinned on a free revolute joint (no hub: hub inertia 0), bending in the
    plane of the joint rotation: the rigid rotation is the joint's, so the elastic
    frequencies are those of the pinned–free beam."""
    beam = RitzBeam(L, RHO_A, EI, n_v=n, n_w=0, family=family, support="pinned")
    A, _ = linearize(pq.System({"beam": beam}, {"beam": pq.Revolute(axis="z")}))
    eigenvalues = np.linalg.eigvals(A)
    return np.sort(eigenvalues.imag[eigenvalues.imag > 1e-6])


def test_pinned_free_beam_on_a_free_joint():
    """ω_k = (β_k L)² √(EI/(ρA L⁴)) with β_k L of tan βL = tanh βL (Blevins Table 8-1).
    With the pinned–free eigenfunctions the first three are exact (they are mass-orthogonal
    to the rigid rotation x): 6.5e-12 relative (measured 6.5e-13, the round-off of the exact
    linearisation and the eigenvalues; was 1e-7, set when the linearisation took central differences).
    With clamped–free functions plus the joint rotation the basis is
    complete too, and the first frequency converges from above (measured 9.6e-8 with 8
    functions; asserted < 1e-6)."""
    reference = pinned_free_roots(3) ** 2 * np.sqrt(EI / (RHO_A * L**4))
    error = np.abs(_pinned_free_frequencies("pinned_free", 3) / reference - 1).max()
    assert error < 6.5e-12, error
    clamped = _pinned_free_frequencies("clamped_free", 8)[0] / reference[0] - 1.0
    assert 0.0 < clamped < 1e-6


def test_pinned_free_family_on_a_clamped_root_is_refused():
    """Φ′(0) ≠ 0 violates the clamped root's slope condition: the functions are named."""
    with pytest.raises(ValueError, match=r"Ritz functions \[0, 1\] for v.*clamped root \(Φ′\(0\) ≠ 0\)"):
        RitzBeam(L, RHO_A, EI, n_v=2, n_w=0, family="pinned_free")


def _static_self_weight(family, n):
    """Static deflection under gravity −g e_z by K_e q = Q_e (Q_e from B(25) at rest)."""
    beam = RitzBeam(L, RHO_A, EI, n_v=0, n_w=n, family=family)
    _, h = beam.gauss_terms(np.zeros(beam.n_y), np.eye(3), np.array([0.0, 0.0, -9.81]), np.zeros(beam.n_e))
    return beam, np.linalg.solve(beam.K_e, h[6:])


def test_root_section_forces_under_self_weight():
    """Cantilever under its own weight q = ρAg: root shear −ρAgL (the outer part pulls
    down), root moment −ρAgL²/2, tip deflection −qL⁴/(8EI) (Gere & Timoshenko, Mechanics
    of Materials, App. G, case 1). The exact deflection is a quartic, so three polynomial
    functions reproduce it: round-off (measured 6.0e-15 and 5.6e-15 of the load for the shears,
    9.7e-16 for the moment, 2.2e-16 for the deflection: 6.1e-14 and 100 ε; the bounds were 1e-9)."""
    load = RHO_A * 9.81 * L
    exact = 100 * np.finfo(float).eps
    beam, q = _static_self_weight("polynomial", 3)
    assert beam.shear_force(q, 0.0)[0] == pytest.approx([0.0, -load], abs=6.1e-14 * load)
    assert beam.bending_moment(q, 0.0)[0] == pytest.approx([0.0, -load * L / 2], abs=exact * load * L)
    assert beam.deflection(q, L)[0, 2] == pytest.approx(-load * L**3 / (8 * EI), rel=exact, abs=0)
    assert beam.shear_force(q, L)[0] == pytest.approx([0.0, 0.0], abs=6.1e-14 * load)


def test_eigenfunction_ritz_shear_converges_slowly():
    """With clamped–free eigenfunctions (Φ‴(L) = 0 each, but Φ‴(0) ≠ −load/EI) the root
    shear converges like 1/n: n = 2, 4, 8 give errors 0.199, 0.101, 0.051 of the load
    (halving within 5 %), the moment like 1/n², while the tip deflection error is below
    2e-6 with 8 functions."""
    load = RHO_A * 9.81 * L
    errors = []
    for n in (2, 4, 8):
        beam, q = _static_self_weight("clamped_free", n)
        errors.append(beam.shear_force(q, 0.0)[0, 1] / -load - 1.0)
    assert errors[1] / errors[0] == pytest.approx(0.5, rel=0.05)
    assert errors[2] / errors[1] == pytest.approx(0.5, rel=0.05)
    assert abs(beam.deflection(q, L)[0, 2] / (-load * L**3 / (8 * EI)) - 1.0) < 2e-6


def test_shear_force_needs_the_third_derivative():
    """A user family giving (Φ, Φ′, Φ″) only has no shear force: say so."""

    def family(n, length):
        return lambda x: (np.array([x**2]), np.array([2 * x]), np.array([2 + 0 * x]))

    beam = RitzBeam(2.0, 1.0, 1.0, n_v=1, n_w=0, family=family)
    with pytest.raises(ValueError, match="family: derivative 3"):
        beam.shear_force(np.zeros((1, 1)), 0.0)


@pytest.mark.parametrize("eta, flap", [(3, 4.7973), (5, 6.4495)], ids=["eta=3", "eta=5"])
def test_frequencies_after_the_spin_up(eta, flap):
    """projeq.linearize on scenes.spin_up_beam at t = 20 s > Ts (steady spin Ωs, q = 0 is
    the equilibrium): flapwise ω/√(EI/(ρAL⁴)) as Wright et al. (1982) Table 1 (cited in
    test_beam.py), lead-lag √(flap² − η²). 10 eigenfunctions per plane; tolerance 6e-5
    on the flap frequency: the table's rounding plus Ritz error (< 1e-5); on the lead-lag
    one the same propagated through the square root (× flap/lag)."""
    scale = np.sqrt(EI / (RHO_A * L**4))
    system = spin_up_beam(omega_s=eta * scale, n_shapes=10, family="clamped_free")
    A, _ = linearize(system, np.zeros(system.n_q), np.zeros(system.n_s), 20.0)
    eigenvalues = np.linalg.eigvals(A)
    found = np.sort(eigenvalues.imag[eigenvalues.imag > 1e-9]) / scale
    lag = np.sqrt(flap**2 - eta**2)
    assert found[0] == pytest.approx(lag, abs=6e-5 * flap / lag)
    assert found[1] == pytest.approx(flap, abs=6e-5)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"n_beta": 1}, "GI_t"),
        ({"n_beta": 1, "GI_t": 1.0}, "rho_I_p"),
        ({"n_beta": 1, "GI_t": 0.0, "rho_I_p": 1.0}, "GI_t"),
        ({"n_beta": 1, "GI_t": 1.0, "rho_I_p": -1.0}, "rho_I_p"),
        ({"n_beta": 1.5}, "n_beta"),
        ({"support": "free"}, "support"),
        ({"rho_A": lambda x: 0 * x}, "rho_A"),
        ({"EI_y": -2.0}, "EI_y"),
        ({"n_u": 1, "EA": 0.0}, "EA"),
    ],
    ids=[
        "GI_t-missing", "rho_I_p-missing", "GI_t-zero", "rho_I_p-negative", "n_beta", "support", "rho_A-zero",
        "EI_y", "EA-zero",
    ],
)
def test_bad_torsion_and_support_input_names_the_parameter(kwargs, match):
    args = {"length": 2.0, "rho_A": 1.0, "EI_z": 1.0}
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        RitzBeam(**args)


@pytest.mark.parametrize("unused, count_name, deformation", [
    ({"EA": 50.0}, "n_u", "axial"),
    ({"GI_t": 5.0}, "n_beta", "torsional"),
], ids=["EA", "GI_t"])
def test_a_stiffness_without_ritz_functions_warns_by_name(unused, count_name, deformation):
    """Passes if EA given with n_u = 0 (GI_t with n_beta = 0) gives a UserWarning naming it and
    the count that would use it, and K_e is that of the beam without it (the stiffness has no
    effect). Before, it was dropped without a word."""
    name = next(iter(unused))
    with pytest.warns(UserWarning, match=rf"^{name}: given but unused, since {count_name} = 0 \(no {deformation} "
                                         rf"Ritz functions\); give {count_name} > 0"):
        beam = RitzBeam(2.0, 1.0, 20.0, n_v=2, n_w=1, **unused)
    np.testing.assert_array_equal(beam.K_e, RitzBeam(2.0, 1.0, 20.0, n_v=2, n_w=1).K_e)


def test_defaults_and_used_stiffnesses_are_silent():
    """Passes if neither the defaults nor EA, GI_t with their Ritz functions warn."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        RitzBeam(2.0, 1.0, 20.0, n_v=2, n_w=1)
        RitzBeam(2.0, 1.0, 20.0, n_v=2, n_w=1, n_u=1, EA=50.0, n_beta=1, GI_t=5.0, rho_I_p=1e-3)


def test_rho_I_p_without_torsion_is_the_spin_inertia():
    """Passes if ρI_p given with n_beta = 0 adds ρI_p L to the rigid beam's inertia about its
    axis x, and nothing else, in the mass matrix at rest (slices' polar moments summed along
    the beam, docs/theory.md §10): it acts, so it is accepted without a warning."""
    rho_I_p, length = 3e-3, 2.0
    plain = RitzBeam(length, 1.0, 20.0, n_v=2, n_w=1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        spinning = RitzBeam(length, 1.0, 20.0, n_v=2, n_w=1, rho_I_p=rho_I_p)
    rest = (np.zeros(plain.n_y), np.eye(3), np.zeros(3), np.zeros(plain.n_e))
    difference = spinning.gauss_terms(*rest)[0] - plain.gauss_terms(*rest)[0]
    expected = np.zeros_like(difference)
    expected[3, 3] = rho_I_p * length
    np.testing.assert_allclose(difference, expected, rtol=1e-14, atol=1e-15)

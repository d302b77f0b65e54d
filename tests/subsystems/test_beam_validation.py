"""RitzBeam against exact solutions of the continuum equations (issue 6, validation):
the spinning Rayleigh shaft (rotary inertia on) and tapered cantilevers (per-length
properties as functions of x). Each reference is computed here without the Ritz
discretisation: roots of the exact frequency determinant of the beam's differential
equation."""

import math

import numpy as np
import pytest
from scipy.linalg import eigh
from scipy.optimize import brentq
from scipy.special import iv, jv

from projeq.analysis.differentiation import DifferencesWarning
from projeq.analysis.linearize import linearize
from projeq.scenes.elastic import spinning_beam
from projeq.subsystems import RitzBeam


def _sign_changes(f, grid):
    """Roots of f on ``grid`` (bracketed by sign changes, refined by brentq)."""
    values = f(grid)
    brackets = np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))
    return np.array([brentq(f, grid[i], grid[i + 1], xtol=1e-14) for i in brackets])


# -- spinning Rayleigh shaft -------------------------------------------------------------


def _rayleigh_determinant(nu, omega, rho_I, sense):
    """Frequency determinant of the clamped–free spinning Rayleigh shaft (EI = ρA = L = 1)
    for the whirl frequency ν > 0 in the inertial frame, ``sense`` = +1 forward, −1 backward.

    The inertial-frame Rayleigh shaft ρA r̈ − ρI r̈″ + iΩ ρI_p ṙ″ + EI r'''' = 0 with
    I_p = 2I, r = Y + iZ (rotor-dynamics texts, e.g. G. Genta, Dynamics of Rotating
    Systems, Springer 2005, Rayleigh-beam rotor model; the shear-rigid limit of
    Zu & Han 1992, J. Appl. Mech. 59:S197) with r = Z(x) e^{iνt} gives
    EI Z'''' + b Z″ − ρA ν² Z = 0, b = ρI ν(ν − 2Ω sense). Z = C₁(cosh αx − cos βx) +
    C₂(sinh αx − (α/β) sin βx) is clamped at x = 0 (α², −β² the roots of EI s⁴ + b s² −
    ρAν² = 0); the free end asks EI Z″ = 0 and EI Z‴ + b Z′ = 0 (the Rayleigh beam's
    shear condition). At b = 0 the determinant is ∝ 1 + cos βL cosh βL."""
    b = rho_I * nu * (nu - 2.0 * sense * omega)
    root = np.sqrt(b * b + 4.0 * nu * nu)
    a, c = np.sqrt(0.5 * (root - b)), np.sqrt(0.5 * (root + b))
    ch, sh, co, si = np.cosh(a), np.sinh(a), np.cos(c), np.sin(c)
    moment = (a * a * ch + c * c * co, a * a * sh + a * c * si)
    shear = (a * c * c * sh - a * a * c * si, a * c * c * ch + a**3 * co)
    return (moment[0] * shear[1] - moment[1] * shear[0]) / (ch**2 * (a * a + c * c) ** 2.5)


def _rayleigh_shaft_frequencies(omega, rho_I, count=4):
    """The lowest ``count`` frequencies in the co-rotating frame, |ν − sense Ω|."""
    grid = np.linspace(1e-3, 400.0, 40001)
    found = []
    for sense in (1, -1):
        nu = _sign_changes(lambda nu: _rayleigh_determinant(nu, omega, rho_I, sense), grid)[:count]
        found.append(np.abs(nu - sense * omega))
    return np.sort(np.concatenate(found))[:count]


def _co_rotating_frequencies(omega, rho_I, n_shapes, count=4):
    A, _ = linearize(spinning_beam(omega=omega, rho_I=rho_I, n_shapes=n_shapes))
    eigenvalues = np.linalg.eigvals(A)
    return np.sort(np.abs(eigenvalues.imag[eigenvalues.imag > 1e-9]))[:count]


def test_rayleigh_shaft_determinant_reduces_to_the_euler_bernoulli_cantilever():
    """Without rotary inertia the roots are (β_k L)² of 1 + cos βL cosh βL = 0
    (Blevins (1979), Table 8-1: 3.5160153, 22.034492): 1e-7 (the catalogue's 8 digits)."""
    roots = _rayleigh_shaft_frequencies(0.0, 0.0)
    assert np.allclose(roots[::2], np.array([1.8751041, 4.6940911]) ** 2, rtol=1e-7)


@pytest.mark.parametrize("omega", [0.5, 2.0, 7.0])
def test_spinning_rayleigh_shaft_frequencies(omega):
    """scenes.spinning_beam with rotary inertia ρI = 0.01 ρA L² (radius of gyration L/10)
    against the exact co-rotating frequencies |ν − ±Ω| of the spinning Rayleigh shaft
    (see _rayleigh_determinant). Rotary inertia shifts the first four frequencies by
    0.7 % … 19 % (so the check can fail by ≥ 50× its tolerance); ten clamped–free
    eigenfunctions per plane leave a Ritz error of at most
    3.5e-5 (measured; the eigenfunctions miss the Rayleigh shear condition, so convergence
    is algebraic), asserted < 1e-4. Five functions give ~7× larger errors (measured
    1.4e-4 … 2.4e-4); asserted > 3× (convergence)."""
    exact = _rayleigh_shaft_frequencies(omega, 0.01)
    error = np.abs(_co_rotating_frequencies(omega, 0.01, 10) / exact - 1.0)
    assert error.max() < 1e-4
    assert np.abs(_rayleigh_shaft_frequencies(omega, 0.0) / exact - 1.0).min() > 50 * error.max()
    coarse = np.abs(_co_rotating_frequencies(omega, 0.01, 5) / exact - 1.0)
    assert coarse.max() > 3 * error.max()


# -- tapered cantilevers -------------------------------------------------------------------

# ω_k / √(EI₀/(ρA₀L⁴)) of the cantilever wedge (constant width, depth falling linearly to
# zero at the free end: ρA ∝ ξ, EI ∝ ξ³) and cone (ρA ∝ ξ², EI ∝ ξ⁴), ξ = 1 − x/L;
# G. Kirchhoff (1879), Monatsber. Königl. Preuss. Akad. Wiss. Berlin 815–828; tabulated by
# S. Naguleswaran (1994), J. Sound Vib. 172(3):289–304 (rounded here to 5 significant digits).
TAPERED = {"wedge": (1, 3, (5.3151, 15.207, 30.020)), "cone": (2, 4, (8.7193, 21.146, 38.454))}


def _tapered_exact(kind, count=3):
    """Kirchhoff's solutions Z = ξ^(−p/2) [C₁ J_p(2λ√ξ) + C₂ I_p(2λ√ξ)] (p = 1 wedge,
    2 cone; bounded at the tip ξ = 0) clamped at ξ = 1: J_p(z) I_(p+1)(z) + I_p(z) J_(p+1)(z)
    = 0 with z = 2λ, ω/√(EI₀/(ρA₀L⁴)) = λ² = (z/2)²."""
    p = TAPERED[kind][0]
    determinant = lambda z: jv(p, z) * iv(p + 1, z) + iv(p, z) * jv(p + 1, z)  # noqa: E731
    roots = _sign_changes(determinant, np.linspace(0.5, 20.0, 4000))
    return (roots[:count] / 2.0) ** 2


@pytest.mark.parametrize("kind", sorted(TAPERED))
def test_tapered_cantilever_frequencies(kind):
    """Per-length properties as functions of x: a wedge and a cone (L = 2, EI₀ = 3,
    ρA₀ = 1.5). The Bessel roots agree with the published 5-digit values (rounding: half
    a unit of the last digit), and nine polynomial Ritz functions reproduce the first
    three to 10× the relative error measured (Kirchhoff's modes are power series in ξ; measured
    8.8e-10 for the cone, 1.1e-10 for the wedge; the bound was rtol 1e-7 with numpy's atol 1e-8)."""
    p_mass, p_stiffness, published = TAPERED[kind]
    exact = _tapered_exact(kind)
    assert np.all(np.abs(exact - published) <= 0.5 * 10.0 ** (np.floor(np.log10(published)) - 4) + 1e-12)
    L, EI_0, rho_A_0 = 2.0, 3.0, 1.5
    rho_A, EI = (lambda x: rho_A_0 * (1 - x / L) ** p_mass), (lambda x: EI_0 * (1 - x / L) ** p_stiffness)
    beam = RitzBeam(L, rho_A, EI, n_v=9, n_w=0)
    M, _ = beam.gauss_terms(np.zeros(beam.n_y), np.eye(3), np.zeros(3), np.zeros(beam.n_e))
    omega = np.sqrt(eigh(beam.K_e, M[6:, 6:], eigvals_only=True))[:3] / np.sqrt(EI_0 / (rho_A_0 * L**4))
    error = np.abs(omega / exact - 1).max()
    assert error < {"cone": 8.8e-9, "wedge": 1.1e-9}[kind], error


# -- section forces with x-dependent stiffness ---------------------------------------------


def test_section_forces_of_a_tapered_cantilever_under_a_tip_load():
    """Statics of a cantilever under a tip load −P e_z: M(x) = −P (L − x) and Q(x) = −P
    for any EI(x) (equilibrium of the part beyond x; sign convention of beam_probes, as in
    test_beam_torsion_support's self-weight case). With EI = ĉ (L − x) the curvature
    w″ = M/EI = −P/ĉ is constant, w = −P x²/(2ĉ) lies in the span of the polynomial
    family, and K_e q = Φ_w(L) (−P) reproduces it: round-off (measured 3.3e-15 P L, 2.1e-14 P). The shear
    probe needs the slope of EI(x) here (by the complex step)."""
    L, c_hat, P = 2.0, 5.0, 3.0
    beam = RitzBeam(L, 1.0, 1.0, EI_y=lambda x: c_hat * (L - x), n_v=0, n_w=3)
    Phi_tip, _ = beam.station_data(np.array([L]))
    q = np.linalg.solve(beam.K_e, -P * Phi_tip["w"][0][:, 0])[None, :]
    for x in (0.0, 0.7, 1.5):  # measured: moment 3.3e-15 P L, shear 2.1e-14 P, deflection 2.2e-16 (relative)
        assert beam.bending_moment(q, x)[0, 1] == pytest.approx(-P * (L - x), rel=0, abs=4e-14 * P * L)
        assert beam.shear_force(q, x)[0, 1] == pytest.approx(-P, rel=0, abs=3e-13 * P)
    assert beam.deflection(q, L)[0, 2] == pytest.approx(-P * L**2 / (2 * c_hat), rel=100 * np.finfo(float).eps, abs=0)


def test_shear_force_takes_the_exact_slope_of_EI():
    """Q = −(EI′ w″ + EI w‴) with EI(x) = c e^{x/L}, EI′ = EI/L in closed form: the probe's
    slope by the complex step matches to round-off (100 ε of |Q|: measured 0, at most 4.4e-16 over three
    deformations and six stations; was 1e-13; the central difference it replaced was off by ~1e-10). w″ and w‴ of the same q come from a beam with EI = 1
    (M = w″, Q = −w‴), so the slope is the only thing compared."""
    L, c = 2.0, 5.0
    tapered = RitzBeam(L, 1.0, 1.0, EI_y=lambda x: c * np.exp(x / L), n_v=0, n_w=4)
    unit = RitzBeam(L, 1.0, 1.0, n_v=0, n_w=4)
    q = np.array([[0.3, -0.7, 0.2, 0.1]])
    for x in (0.0, 0.7, 1.5, L):
        EI = c * np.exp(x / L)
        w2, w3 = unit.bending_moment(q, x)[0, 1], -unit.shear_force(q, x)[0, 1]
        expected = -(EI / L * w2 + EI * w3)
        exact = 100 * np.finfo(float).eps
        assert tapered.shear_force(q, x)[0, 1] == pytest.approx(expected, rel=exact, abs=exact * abs(EI * w3))


def test_shear_force_of_a_real_only_EI_warns_once_and_differences():
    """An EI(x) that casts to float cannot take the complex step: one DifferencesWarning naming
    EI_y, then the central difference (~1e-10 relative) of the same closed form."""
    L, c = 2.0, 5.0

    def real_only(x):
        return np.array([c * math.exp(float(xi) / L) for xi in x])

    beam = RitzBeam(L, 1.0, 1.0, EI_y=real_only, n_v=0, n_w=4)
    unit = RitzBeam(L, 1.0, 1.0, n_v=0, n_w=4)
    q = np.array([[0.3, -0.7, 0.2, 0.1]])
    with pytest.warns(DifferencesWarning, match=r"^EI_y .*real_only") as caught:
        for x in (0.7, 1.5):
            EI = c * np.exp(x / L)
            expected = -(EI / L * unit.bending_moment(q, x)[0, 1] - EI * unit.shear_force(q, x)[0, 1])
            # EI′ by central differences: measured 1.05e-11 relative (was 1e-8)
            assert beam.shear_force(q, x)[0, 1] == pytest.approx(expected, rel=1.1e-10, abs=0)
    assert len([w for w in caught if issubclass(w.category, DifferencesWarning)]) == 1

"""RitzBeam bad input (issue 6, "Bad input"): each kind refused by a ValueError naming the
parameter (and the deformation and Ritz function where one is at fault), and the
unstiffened fast spin warned about once, at the model's own critical speed."""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.analysis.linearize import linearize
from projeq.scenes.elastic import spin_up_beam
from projeq.subsystems import RitzBeam


def _user_family(*arrays):
    """A user family returning the given arrays (functions of x) whatever n is asked for."""
    return lambda n, length: (lambda x: tuple(np.array([f(x) for f in row]) for row in arrays))


ONE = lambda x: 1.0 + 0 * x  # noqa: E731
ZERO = lambda x: 0 * x  # noqa: E731
SQUARE = (lambda x: x**2, lambda x: 2 * x, lambda x: 2 + 0 * x)  # Φ, Φ′, Φ″ of x²


@pytest.mark.parametrize(
    "kwargs, match",
    [
        # the pinned root asks Φ(0) = 0 only, and still refuses Φ = 1 + x
        (
            {"support": "pinned", "family": _user_family((lambda x: 1 + x,), (ONE,), (ZERO,))},
            r"Ritz functions \[0\] for v violate .* pinned root \(Φ\(0\) ≠ 0\)",
        ),
        # axial functions need u(0) = 0 (a user family serves all deformations)
        (
            {"n_v": 0, "n_u": 1, "EA": 1.0, "family": _user_family((ONE,), (ZERO,), (ZERO,))},
            r"Ritz functions \[0\] for u violate .*\(Φ\(0\) ≠ 0\)",
        ),
        # one function given where two are asked for
        (
            {"n_v": 2, "family": _user_family(*((f,) for f in SQUARE))},
            r"family: Φ for v has shape \(1, 5\), expected \(2, 5\)",
        ),
        ({"family": lambda n, length: (lambda x: x**2)}, r"family: shapes\(x\) for v must return"),
        ({"family": lambda n: None}, r"family: the Ritz family for v failed"),
        ({"family": {"v": "polynomial"}}, r"family: unknown Ritz family \{'v'"),
        (
            {"family": _user_family((lambda x: x**2 + np.where(x > 1.0, np.inf, 0.0),), (ONE,), (ZERO,))},
            r"family: Φ of the Ritz functions \[0\] for v is not finite",
        ),
        ({"EI_z": "stiff"}, "EI_z: expected numbers"),
        ({"rho_A": lambda x: np.ones(3)}, "rho_A: must give a finite value at each station"),
        ({"rho_I": (1e-3, 1e-3, 2e-3)}, r"rho_I: expected ρI or \(ρI_y, ρI_z\)"),
        ({"quadrature_order": 0}, "quadrature_order: expected an integer >= 1"),
        ({"quadrature_order": 7.5}, "quadrature_order: expected an integer"),
        # four functions reach degree 2·4 + 2 = 10, which 6 Gauss points integrate exactly (2·6 − 1 = 11)
        ({"n_v": 4, "quadrature_order": 5}, r"quadrature_order: 5 Gauss points .* up to degree 9 .* reach degree 10; "
                                            r"give at least 6 \(default 14\)"),
    ],
    ids=[
        "pinned-root", "axial-root", "family-count", "family-not-a-tuple", "family-signature",
        "family-dict", "family-non-finite",
        "EI-not-a-number", "rho_A-wrong-shape", "rho_I-three", "quadrature-zero", "quadrature-fraction",
        "quadrature-too-few",
    ],
)
def test_bad_beam_input_names_parameter_and_function(kwargs, match):
    args = {"length": 2.0, "rho_A": 1.0, "EI_z": 1.0, "n_v": 1, "n_w": 0}
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        RitzBeam(**args)


def test_ill_conditioned_polynomials_are_refused_with_a_remedy():
    """Monomials x², …, x¹¹ (n = 10) have a Gram matrix of condition 3e15 (the Hilbert
    matrix's growth): M_ee is singular to machine precision, so the beam is refused, the
    functions named and the eigenfunction family suggested; n = 9 and twelve clamped–free
    eigenfunctions (orthogonal) are accepted."""
    refused = r"family: the Ritz functions \['v\[1\]'.*linearly dependent.*clamped_free"
    with pytest.raises(ValueError, match=refused):
        RitzBeam(10.0, 1.2, 1.4e4, n_v=10, n_w=0)
    RitzBeam(10.0, 1.2, 1.4e4, n_v=9, n_w=0)
    RitzBeam(10.0, 1.2, 1.4e4, n_v=12, n_w=12, family="clamped_free")


def _steady_spin_eigenvalues(omega):
    """Eigenvalues of the unstiffened cantilever (L = 10, EI = 1.4e4, ρA = 1.2, in-plane
    bending only) spinning steadily at ``omega`` about z through its root."""
    beam = RitzBeam(10.0, 1.2, 1.4e4, n_v=4, n_w=0, stiffening=False)
    spin = pq.Prescribed(pq.Revolute(axis="z"), lambda t: (omega * t, omega, 0.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the warning is tested below
        A, _ = linearize(pq.System({"beam": beam}, {"beam": spin}))
    return beam, np.linalg.eigvals(A)


def test_unstiffened_critical_speed_is_the_first_bending_frequency():
    """Without stiffening the in-plane equations are M q̈ + (K_e − Ω² M) q = 0 (zero hub
    radius): stable up to Ω = ω₁ of the same Ritz model, divergent beyond (a real
    eigenvalue √(Ω² − ω₁²) > 0). The warning's critical speed is this ω₁: checked 1 %
    below and above it (growth rate above: √(1.01² − 1) ω₁ = 0.14 ω₁, measured to 1.44e-10
    relative, asserted 1.4e-9; below, the real parts are round-off of the linearisation:
    measured 9.1e-14 ω₁, asserted < 9e-13 ω₁; each bound 10× the error measured on the
    branch of issue 37, which found them 10⁴ and 10⁷ times looser)."""
    beam, _ = _steady_spin_eigenvalues(1.0)
    critical = beam.first_frequency
    exact = 3.51601527 * np.sqrt(1.4e4 / (1.2 * 1e4))  # (β₁L)² √(EI/(ρAL⁴)), Blevins (1979), Table 8-1
    assert critical == pytest.approx(exact, rel=1e-5)  # Ritz with n = 4 polynomials: 1.5e-6
    _, below = _steady_spin_eigenvalues(0.99 * critical)
    _, above = _steady_spin_eigenvalues(1.01 * critical)
    assert np.abs(below.real).max() < 9e-13 * critical, f"max |Re λ| = {np.abs(below.real).max() / critical:.3g} ω₁"
    assert above.real.max() == pytest.approx(np.sqrt(1.01**2 - 1.0) * critical, rel=1.4e-9)


def test_unstiffened_spin_up_warns_once_with_the_critical_speed():
    """A whole unstiffened spin-up past ω₁ (Ts = 1 s to Ωs = 6 rad/s > ω₁ = 3.82 rad/s
    with two functions per plane) warns exactly once per beam, naming the critical speed;
    a stiffened beam spinning at 2 ω₁ does not warn."""
    system = spin_up_beam(n_shapes=2, t_s=1.0, stiffening=False)
    critical = system.subsystem("beam").first_frequency
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")  # Python's default for RuntimeWarning: once per text and place
        pq.simulate(system, 1.2, method="RK45", rtol=1e-6, atol=1e-8)
    said = [w for w in caught if "unstable" in str(w.message)]
    assert len(said) == 1 and f"{critical:.3g} rad/s" in str(said[0].message)
    stiffened = RitzBeam(10.0, 1.2, 1.4e4, n_v=2, n_w=2)
    y_dot = np.zeros(stiffened.n_y)
    y_dot[5] = 2.0 * stiffened.first_frequency
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stiffened.gauss_terms(y_dot, np.eye(3), np.zeros(3), np.zeros(stiffened.n_e))


@pytest.mark.parametrize("x", [-1e-9, 1.0 + 1e-9, 1.5, -0.5])
def test_probe_stations_must_lie_on_the_beam(x):
    """Passes if a station a hair (1e-9 L) or far off the 1 m beam is refused by name, while the
    ends themselves are probed: Φ(0) = 0 (clamped) and the tip of Φ₁ = (x/L)² is 1."""
    beam = pq.RitzBeam(1.0, 1.0, 1.0, n_v=2, n_w=0)
    with pytest.raises(ValueError, match=r"^x: stations must lie on the beam, 0 ≤ x ≤ 1.0"):
        beam.displacement(np.array([1.0, 0.0]), [x])
    ends = beam.displacement(np.array([1.0, 0.0]), [0.0, 1.0])
    # measured exactly 1 (pytest's absolute 1e-12 dominated rel 1e-14 before)
    assert ends[0, 1] == 0.0 and ends[1, 1] == pytest.approx(1.0, rel=1e-14, abs=0)


def test_a_nan_probe_station_is_on_no_beam():
    """Passes if a station x = NaN is refused like one off the beam; before, it passed the range
    check (NaN < 0 and NaN > L are both false) and the probe returned a NaN deflection."""
    beam = pq.RitzBeam(1.0, 1.0, 1.0, n_v=2, n_w=0)
    with pytest.raises(ValueError, match=r"^x: stations must lie on the beam, 0 ≤ x ≤ 1.0, got \[nan\]"):
        beam.displacement(np.array([1.0, 0.0]), [np.nan])


@pytest.mark.parametrize("switch", ["stiffening", "precomputed_integrals"])
def test_a_switch_given_as_text_is_refused(switch):
    """Passes if stiffening="False" (text, as from a settings file: truthy) is refused by name
    instead of silently switching the option on; True and False themselves are taken."""
    with pytest.raises(ValueError, match=f"^{switch}: expected True or False, got 'False'"):
        pq.RitzBeam(1.0, 1.0, 1.0, n_v=2, n_w=0, **{switch: "False"})
    assert getattr(pq.RitzBeam(1.0, 1.0, 1.0, n_v=2, n_w=0, stiffening=False), "stiffening") is False

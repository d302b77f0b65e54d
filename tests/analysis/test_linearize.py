"""projeq.linearize and eigenvalue_sweep against closed forms.

- simple and double pendulum: ω² = g/l and ω² = (g/l)(2 ± √2) (the Lagrange seminars
  Problem 8, equal masses and lengths);
- Bremer's car (Bremer (2009) B(9)): x, y, γ are detected as ignorable and the
  straight run's A follows from linearising B(9);
- the rolling disk's critical speed (``scenes.rolling_disk_critical_speed``, from the
  linearised slide-37 equations of Orsino (2020)) found by root finding over a sweep;
- steady motions that are not equilibria of (q, ṡ) raise NotSteadyError.
"""

import numpy as np
import pytest
from scipy.optimize import brentq

import projeq as pq
from projeq.analysis.linearize import NotSteadyError, eigenvalue_sweep, linearize, state_derivative
from projeq.scenes import car, knife_edge_disc, rolling_disk, rolling_disk_critical_speed

G = 9.81
EXACT = 100 * np.finfo(float).eps  # round-off


def pendulum(m=2.0, l=0.7):
    return pq.System({"bob": pq.PointMass(m, (0.0, 0.0, -l))}, {"bob": pq.Revolute(axis="y")},
                     gravity=(0.0, 0.0, -G), q0=[0.0], s_dot0=[0.0])


def test_pendulum_matches_closed_form_beyond_central_differences():
    """Point-mass pendulum: A = [[0, 1], [−g/l, 0]] exactly and B = [0, 1/(m l²)] for a torque
    on the hinge. The Richardson-extrapolated Jacobian reaches round-off (measured 2.5e-16
    relative, B exact); plain central differences with h = 1e-6 (the first version) miss by
    ≈ 1e-11, so the bound 100 ε (was 1e-13) separates the two."""
    m, l = 2.0, 0.7
    lin = linearize(pendulum(m, l), inputs=["bob"])
    A, B = lin
    errors = (np.abs(A - [[0.0, 1.0], [-G / l, 0.0]]).max() / (G / l),
              np.abs(B.ravel() - [0.0, 1 / (m * l * l)]).max() * m * l * l)
    assert max(errors) < 100 * np.finfo(float).eps, errors
    assert lin.states == ("bob.q[0]", "bob.s_dot[0]") and lin.dropped == ()
    x0 = np.zeros(2)
    f = lambda x: state_derivative(pendulum(m, l), x, 0.0)
    central = np.array([(f(x0 + 1e-6 * e) - f(x0 - 1e-6 * e)) / 2e-6 for e in np.eye(2)]).T
    assert abs(central[1, 0] + G / l) / (G / l) > abs(A[1, 0] + G / l) / (G / l)


@pytest.mark.parametrize("l", [1.0, 0.3])
def test_double_pendulum_normal_modes(l):
    """the Lagrange seminars Problem 8: two equal masses on equal rods, ω² = (g/l)(2 ± √2). The
    eigenvalues of A are ±iω; error bound 100 ε (measured ≤ 1.1e-15; was 1e-12; plain central
    differences h = 1e-6: 1.2e-12)."""
    lin = linearize(pq.scenes.double_pendulum(l1=l, l2=l, q0=(0.0, 0.0)))
    omega2 = np.sort(-lin.eigenvalues().imag ** 2)
    expected = np.sort(-(G / l) * np.repeat([2 + np.sqrt(2), 2 - np.sqrt(2)], 2))
    error = np.abs(omega2 / expected - 1).max()
    assert error < 100 * np.finfo(float).eps, error


def test_car_drops_position_and_heading():
    """Bremer's car on a straight run v_x = v, ω_z = 0 (Bremer (2009) B(9)):
    m v̇_x − m c ω_z² = f_x, C° ω̇_z + m c v_x ω_z = M_z linearise to
    A = [[0, 0], [0, −m c v / C°]]; x, y, γ do not enter s̈ (and γ enters only ẋ, ẏ),
    so all three are dropped and the straight run is an equilibrium of (v_x, ω_z)."""
    m, C0, c, v = 1200.0, 3228.0, 1.2, 10.0
    lin = linearize(car(m, C0, c), q=[3.0, -1.0, 0.4], s_dot=[v, 0.0])
    assert lin.dropped == ("car.q[0]", "car.q[1]", "car.q[2]")
    assert lin.states == ("car.s_dot[0]", "car.s_dot[1]")
    # round-off: measured 8.9e-16 1/s (was 1e-12 of m c v / C°)
    assert np.abs(lin.A - [[0.0, 0.0], [0.0, -m * c * v / C0]]).max() < EXACT * m * c * v / C0


def test_moving_coordinates_kept_are_not_a_steady_motion():
    """Keeping the car's position (ignore=None) or dropping only its heading leaves
    ẋ = v cos γ ≠ 0 among the kept states: neither an equilibrium nor a steady motion."""
    system = car()
    with pytest.raises(NotSteadyError, match="q, s_dot: not a steady motion/equilibrium"):
        linearize(system, ignore=None)
    with pytest.raises(NotSteadyError, match=r"car.q\[0\]"):
        linearize(system, ignore=["car.q[2]"])
    A, _ = linearize(system, s_dot=[0.0, 0.0], ignore=None)  # at rest: an equilibrium
    assert A.shape == (5, 5)
    A, _ = linearize(system, ignore=None, require_steady=False)  # Jacobians anywhere on request
    # ẋ = cos γ v_x at γ = 0: ∂ẋ/∂v_x = 1 (measured exactly 1; was rel 1e-11 with pytest's abs 1e-12)
    assert A[0, 3] == pytest.approx(1.0, rel=EXACT, abs=0)


def test_body_fixed_speeds_are_flagged():
    """Barhorst's upright rolling disk in body-fixed speeds u (Barhorst §3.2): at q2 = 0 the
    roll angle q3's column of A vanishes and the kept states are at rest, but u1, u3 are
    components in the rolling frame C, so A rotates with q3 = Ω t: linearising at one q3
    would predict instability above v_c (measured λ² = 443 s⁻² at Ω = 20 rad/s). The
    caveat of the module is reported instead of misleading eigenvalues."""
    with pytest.raises(NotSteadyError, match=r"A changes by .*disk.q\[2\]"):
        linearize(rolling_disk(m_ecc=0.0), q=np.zeros(5), s_dot=[0.0, 20.0, 0.0])


def test_rolling_disk_critical_speed_by_root_finding():
    """The knife-edge disc in Euler rates (Orsino (2020) slides 28–37), upright at spin Ω:
    x, y, ψ, θ are ignorable, A is 4 × 4 with eigenvalues 0, 0, ±λ where
    λ² = [m g R − Ω² J (J + m R²)/I]/(I + m R²) (rolling_disk_critical_speed's derivation).
    Σλ_i²/2 = λ² changes sign at the critical speed: brentq on it over eigenvalue_sweep
    finds v_c to brentq's xtol 1e-14 (+ 100 ε v_c; measured 0; was 1e-9 relative); Σλ_i²/2 = λ² to 100 ε
    relative and 100 ε of m g R / I (measured ≤ 2.1e-15 relative near λ² = 0, 1.0e-15 of m g R / I, over
    six speeds; was 1e-9)."""
    m, R = 0.030, 0.015
    I, J = m * R * R / 4, m * R * R / 2

    disc = knife_edge_disc(m=m, r=R, I=I, J=J, g=G, q0=np.zeros(5))

    def build(v):
        return disc, np.zeros(5), [0.0, 0.0, -v / R]

    lam = eigenvalue_sweep(build, [0.5, 1.0])
    assert lam.shape == (2, 4)
    for v, row in zip([0.5, 1.0], lam):
        Omega = v / R
        lam2 = (m * G * R - Omega**2 * J * (J + m * R * R) / I) / (I + m * R * R)
        assert np.sum(row**2).real / 2 == pytest.approx(lam2, rel=EXACT, abs=EXACT * abs(m * G * R / I))
    v_c = brentq(lambda v: np.sum(eigenvalue_sweep(build, [v])[0] ** 2).real, 0.1, 0.4, xtol=1e-14)
    assert v_c == pytest.approx(rolling_disk_critical_speed(m, R, I, J, G), rel=0, abs=1e-14 + EXACT * v_c)


def test_bad_inputs():
    system = pendulum()
    with pytest.raises(ValueError, match="inputs: unknown joint 'wheel'"):
        linearize(system, inputs=["wheel"])
    with pytest.raises(ValueError, match="ignore: 'x' is not a coordinate"):
        linearize(system, ignore=["x"])
    with pytest.raises(ValueError, match="ignore: 5 is not a coordinate"):
        linearize(system, ignore=[5])
    with pytest.raises(ValueError, match="ignore: must be 'auto'"):
        linearize(system, ignore="all")
    with pytest.raises(ValueError, match="s_dot"):
        linearize(system, s_dot=[0.0, 1.0])


def test_sweep_with_changing_state_count_is_refused():
    """Eigenvalue rows of different lengths (here chains of one and two links) are refused."""
    with pytest.raises(ValueError, match="values: the number of kept states changes"):
        eigenvalue_sweep(lambda k: pq.scenes.chain(k, q0=np.zeros(k)), [1, 2])

"""The rolling disk's critical speed from the exact linearisation (issue 16).

Closed form (``projeq.scenes.rolling_disk_critical_speed``, the linearised angular-momentum
equations of the upright rolling disk, a classical result, e.g. Neĭmark & Fufaev, "Dynamics
of Nonholonomic Systems", 1972): the tilt obeys ϕ̈ = λ² ϕ with
λ² = (m g R − Ω² J (J + m R²)/I) / (I + m R²), so upright rolling at spin Ω is (neutrally)
stable iff v = R Ω > v_c = √(m g R³ I / (J (J + m R²))), √(g R / 3) for a uniform thin disk.

projeq: ``pq.linearize`` of the knife-edge disc (Euler-rate speeds, constant along steady
rolling) with Jacobians by the complex step. Its nonzero eigenvalue pair ±λ equals the closed
form's to round-off on both sides of v_c, and v_c itself is the root of λ²(Ω) (Brent's
method on the eigenvalues) to 1e-12 relative. Central differences gave ~1e-6 (the older
test_rolling_disk.py bound, 1e-5).
"""

from functools import cache

import numpy as np
import pytest
from scipy.optimize import brentq

import projeq as pq
from projeq.scenes import rolling_disk_critical_speed

G, M, R = 9.81, 0.030, 0.015  # Barhorst's disk in SI
I, J = M * R * R / 4, M * R * R / 2  # uniform thin disk: diameter and polar moments


@cache
def disc():
    """The disc, built once for the module (a build costs ~0.3 s, a linearisation ~5 ms; the
    tests ask for λ² 16 times): a System is frozen, linearize changes nothing in it."""
    return pq.scenes.knife_edge_disc(m=M, r=R, I=I, J=J, g=G, q0=np.zeros(5))


def tilt_rate_squared(Omega: float) -> float:
    """λ² of the linearisation at spin Ω: the square of its largest eigenvalue (real > 0
    below v_c, imaginary pair above)."""
    lam = pq.linearize(disc(), q=np.zeros(5), s_dot=[0.0, 0.0, -Omega]).eigenvalues()
    largest = lam[np.argmax(np.abs(lam))]
    return float((largest**2).real)


@pytest.mark.parametrize("factor", [0.5, 0.8, 0.95, 1.05, 1.2, 2.0])
def test_tilt_eigenvalues_equal_the_closed_form(factor):
    v_c = rolling_disk_critical_speed(M, R, I, J, G)
    Omega = factor * v_c / R
    closed = (M * G * R - Omega**2 * J * (J + M * R * R) / I) / (I + M * R * R)
    # round-off: measured at most 2.0e-15 relative over the six speeds (was 1e-12)
    assert tilt_rate_squared(Omega) == pytest.approx(closed, rel=100 * np.finfo(float).eps, abs=0)


def test_critical_speed_is_the_root_of_the_linearisation():
    v_c = rolling_disk_critical_speed(M, R, I, J, G)
    assert v_c == pytest.approx(np.sqrt(G * R / 3), rel=1e-14)
    Omega_c = brentq(tilt_rate_squared, 0.5 * v_c / R, 2.0 * v_c / R, xtol=1e-14, rtol=1e-15)
    assert R * Omega_c == pytest.approx(v_c, rel=1e-12)

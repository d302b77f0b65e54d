"""Barhorst's particles (Barhorst §3.1 and footnote 6).

- the planar particle with ẏ − y² ẋ = 0 under gravity −g n̂2, m = 1, g = 10, released at
  (2, 2) at rest (his 3.1.1–3.1.5, figures 1–3: energy 20 units, the constraint held);
- the truly non-holonomic particle in space with ẏ + z ẋ = 0 (footnote 6).
"""

import numpy as np
import pytest
from scipy.integrate import quad

import projeq as pq
from projeq.scenes import barhorst_particle, nonholonomic_particle

RNG_SEED = 5
EPS = np.finfo(float).eps


@pytest.mark.parametrize("method", ["recursive", "dense"])
def test_planar_particle_equals_barhorsts_projective_equation(method):
    """§3.1.2: with u₂ = ẏ independent, ∂v/∂u₂ = n̂2 + n̂1/y², Kane's equation is
    m u̇₂ (1 + 1/y⁴) − 2 m u₂²/y⁵ + m g = 0. projeq uses ṡ = ẋ (ẏ = y² ẋ, no singularity at
    y = 0); mapping its ẍ to ÿ = y² ẍ + 2 y ẏ ẋ must give the same u̇₂ at random states."""
    rng = np.random.default_rng(RNG_SEED)
    system = barhorst_particle()
    for _ in range(50):
        x, y = rng.uniform(-5, 5), rng.choice([-1, 1]) * rng.uniform(0.3, 3)
        xd = rng.uniform(-5, 5)
        (xdd,) = system.accelerations([x, y], [xd], method=method)
        yd = y * y * xd
        ydd = y * y * xdd + 2 * y * yd * xd
        barhorst = (2 * yd**2 / y**5 - 10.0) / (1 + 1 / y**4)
        # y² ẍ and 2 y ẏ ẋ cancel (ÿ to 6.5e-14 relative): round-off of their size, measured 2.5e-16 of
        # it (was 1e-12 relative + 1e-12)
        terms = abs(y * y * xdd) + abs(2 * y * yd * xd)
        assert ydd == pytest.approx(barhorst, rel=0, abs=100 * EPS * terms)


def test_planar_particle_motion_energy_constraint():
    """§3.1 from (2, 2) at rest, m = 1, g = 10, 10 s: E = m g y = 20 units throughout, the
    particle stays on the integral curve of ẏ = y² ẋ, y = 1/(2.5 − x) (footnote 6: the
    constraint is integrable), slides towards x → −∞ with y → 0⁺, and the constraint
    residual ẏ − y² ẋ of every output stays at round-off (Barhorst: within ±4e-5 and
    ±2e-5 for his formulations). Measured at rtol 1e-10: energy 3.2e-9, path 9.3e-11, final speed
    8.2e-12 relative (2.2e-9, 6.0e-11, 1.8e-12 over 5 s); the bounds are 10 times those (were 1e-6)."""
    system = barhorst_particle()
    res = pq.simulate(system, 10.0, rtol=1e-10, atol=1e-12)
    x, y = res.q.T
    assert res.energy[0] == pytest.approx(20.0, rel=1e-15, abs=0)  # measured 0
    # rtol 1e-10: energy and path errors of that order times the number of steps (~10³)
    assert np.abs(res.energy - 20.0).max() < 3.3e-8
    assert np.abs(y - 1 / (2.5 - x)).max() < 1e-9
    assert np.abs(res.constraint_residual).max() < 100 * EPS  # measured 0 (was 1e-12)
    assert np.all(np.diff(x) < 0) and np.all(y > 0) and y[-1] < 0.1
    speed = np.hypot(*system_rates(system, res).T)
    # energy: ½v² = g(2 − y)
    assert speed[-1] == pytest.approx(np.sqrt(2 * 10.0 * (2.0 - y[-1])), rel=1e-10, abs=0)


def system_rates(system, res):
    return np.array([system.q_dot(q, s) for q, s in zip(res.q, res.s_dot)])


def test_spatial_particle_closed_form():
    """Footnote 6, ẏ + z ẋ = 0 under gravity −g n̂3 with ṡ = (ẋ, ż): Kane's equations give
    z̈ = −g and (1 + z²) ẍ + z ż ẋ = 0, i.e. ẋ √(1 + z²) = const; then
    y(t) = y₀ − ∫ z ẋ dt. The simulation follows these closed forms, conserves energy and
    keeps the constraint residual at round-off. Measured (largest over this run and three others:
    ṡ₀ = (0.5, 3), (2, 1), 2.5 s): z 1.8e-14 (exact up to round-off: ż is linear), x 6.1e-12,
    y 1.3e-11, ẋ √(1 + z²) 5.0e-11 relative, energy drift 4.6e-13 (rtol 1e-11; a third to a tenth of
    that while each of the 20 segments cut its last step short); the bounds are 10 times those (were
    1e-8 and 1e-9)."""
    g, q0, s0 = 10.0, np.array([0.0, 0.0, 1.0]), np.array([1.0, 2.0])
    system = nonholonomic_particle(g=g, q0=q0, s_dot0=s0)
    res = pq.simulate(system, 2.0, rtol=1e-11, atol=1e-13, n_points=21)
    t = res.t
    z = q0[2] + s0[1] * t - g * t**2 / 2
    c = s0[0] * np.sqrt(1 + q0[2] ** 2)

    def xdot(tau):
        zt = q0[2] + s0[1] * tau - g * tau**2 / 2
        return c / np.sqrt(1 + zt**2)

    x = np.array([quad(xdot, 0, ti, epsabs=1e-13, epsrel=1e-13)[0] for ti in t])
    y = np.array([-quad(lambda tau: (q0[2] + s0[1] * tau - g * tau**2 / 2) * xdot(tau), 0, ti,
                        epsabs=1e-13, epsrel=1e-13)[0] for ti in t])
    assert np.allclose(res.q[:, 2], z, rtol=0, atol=2e-13)
    assert np.allclose(res.q[:, 0], x, rtol=0, atol=6.1e-11)
    assert np.allclose(res.q[:, 1], y, rtol=0, atol=1.3e-10)
    assert np.allclose(res.s_dot[:, 0] * np.sqrt(1 + res.q[:, 2] ** 2), c, rtol=5e-10, atol=0.0)
    assert res.energy_drift < 4.6e-12
    assert np.abs(res.constraint_residual).max() < 100 * EPS  # measured 0 (was 1e-12)


def test_spatial_particle_is_truly_non_holonomic():
    """Footnote 6: ẏ + z ẋ = 0 is not integrable: a closed loop in (x, z) (here a square
    driven without gravity, ṡ piecewise constant) changes y by −∮ z dx = the enclosed
    area, which would be impossible for a holonomic constraint h(x, y, z) = 0. ṡ is constant on each side,
    so the loop closes to round-off: 100 ε (measured 1.7e-16 and 0; the bounds were 1e-12 and 1e-10)."""
    system = nonholonomic_particle(g=0.0)
    q = np.zeros(3)
    for s in ([1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]):  # unit square, counter-clockwise in (x, z)
        res = pq.simulate(system, 1.0, q0=q, s_dot0=s, rtol=1e-12, atol=1e-14, n_points=2)
        q = res.q[-1]
    assert np.allclose(q[[0, 2]], 0.0, rtol=0.0, atol=100 * np.finfo(float).eps)
    assert q[1] == pytest.approx(1.0, rel=100 * np.finfo(float).eps, abs=0)  # −∮ z dx = +1 here

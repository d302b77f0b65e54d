"""IFToMM A05, the stiff flyball governor (projeq.scenes.iftomm.flyball_governor): the benchmark of
M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A benchmarking system for MBS simulation
software", Multibody System Dynamics 16 (2006) 179–190. Its published reference solution (s(t)
over 10 s) cannot be read here (no network); the model is checked against references that do not
use projeq's force law or kinematics: the relative equilibrium from the amended potential in closed
form (flyball_steady_state), the energy balance with the dampers' dissipated work computed from
the springs' length in closed form, the three evaluators against each other, and the conservation
of the angular momentum about the free shaft.
"""

import numpy as np
import pytest

import projeq as pq
from projeq.assembly.auto import pick
from projeq.scenes.iftomm import (
    FLYBALL, _flyball_geometry, flyball_balance, flyball_governor, flyball_spring_rate, flyball_steady_state,
)


def test_the_compiled_kernel_takes_the_governor_and_agrees_with_the_reference_evaluators():
    """auto picks the compiled kernel (fixed joints, two SpringDamper laws), and its accelerations
    equal the interpreted recursive and dense (Gauss form) evaluators' at random states to 1e-9
    relative."""
    system = flyball_governor()
    assert pick(system)[0] == "fast"
    rng = np.random.default_rng(5)
    for _ in range(5):
        q = system.q0 + rng.normal(scale=[1.0, 0.05, 0.2, 0.2])
        s_dot = rng.normal(scale=[6.0, 0.5, 2.0, 2.0])
        fast, recursive, dense = (system.evaluator(name).accelerations(q, s_dot, 0.0)
                                  for name in ("fast", "recursive", "dense"))
        scale = np.abs(recursive).max()
        assert np.abs(fast - recursive).max() < 1e-9 * scale and np.abs(dense - recursive).max() < 1e-9 * scale


def test_the_potential_is_gravity_and_the_two_springs_in_closed_form():
    """The model's potential energy equals V(α, s) of the closed form (flyball_steady_state's) at
    symmetric states, the springs stretched or compressed by up to 2 cm (up to 160 J each)."""
    system = flyball_governor()
    for s, alpha in [(0.5, np.pi / 6), (0.62, 0.4), (0.45, 0.55)]:
        q = np.array([0.3, s, alpha, alpha])
        V = _flyball_geometry(alpha, s)[1]
        assert system.energy(q, np.zeros(4))[1] == pytest.approx(V, rel=1e-12, abs=1e-9)


def test_the_governor_holds_its_relative_equilibrium():
    """Started at the relative equilibrium of the benchmark's angular momentum (α = 22.86°,
    s = 0.6114 m, ω = 5.587 rad/s: the slider's weight carried by the two springs, stretched by
    4.7e-5 m, the rods' centrifugal moment against gravity and the springs), the governor turns
    rigidly: over 0.5 s, s and α stay within 1e-8 of it and the shaft speed within 1e-8 rad/s."""
    steady = flyball_steady_state()
    system = flyball_governor(s0=steady["s"], alpha0=steady["alpha"], omega0=steady["omega"])
    r = pq.simulate(system, 0.5, n_points=11, method="BDF", rtol=1e-10, atol=1e-12)
    assert np.abs(r.q[:, 1] - steady["s"]).max() < 1e-8
    assert np.abs(r.q[:, 2:] - steady["alpha"]).max() < 1e-8
    assert np.abs(r.s_dot[:, 0] - steady["omega"]).max() < 1e-8
    assert np.abs(r.s_dot[:, 1:]).max() < 1e-7


def test_a_governor_off_its_equilibrium_moves():
    """The check above can fail: 1 mm above its equilibrium, the slider moves by more than 1e-4 m in
    0.1 s (the springs push it back with ~1600 N)."""
    steady = flyball_steady_state()
    system = flyball_governor(s0=steady["s"] + 1e-3, alpha0=steady["alpha"], omega0=steady["omega"])
    r = pq.simulate(system, 0.1, n_points=3, method="BDF", rtol=1e-8, atol=1e-10)
    assert np.abs(r.q[:, 1] - r.q[0, 1]).max() > 1e-4


@pytest.fixture(scope="module")
def benchmark_start():  # ~7 s CPU
    system = flyball_governor()
    return system, pq.simulate(system, 1.0, n_points=101, rtol=1e-10, atol=1e-12, dense_output=True)


def test_the_default_integrator_is_implicit_for_the_stiff_dampers(benchmark_start):
    """simulate's default sees the dampers' mode, a real eigenvalue −8117 1/s (power iteration,
    fastest_mode), and picks Radau: DOP853 would need 8117 · 10 s / 6.39 ≈ 12,700 steps for
    stability alone over the benchmark's 10 s (benchmarks/iftomm.py measures both)."""
    _, r = benchmark_start
    assert r.method == "Radau"


def test_energy_balance_with_the_dampers_work(benchmark_start):
    """From the benchmark's start, over 1 s: T + V (gravity and springs) + W_d = E₀, W_d the work
    dissipated by the two dampers, ∫ 2 C ℓ̇² dt (the two sides symmetric), ℓ̇ from the closed form of
    the springs' length along the dense output (flyball_balance). W_d is 2.5e-3 J; the balance
    holds to 1e-8 J (achieved 1.0e-9 J with Radau at rtol 1e-10)."""
    system, r = benchmark_start
    assert np.allclose(r.q[:, 2], r.q[:, 3], atol=1e-9)  # the symmetric motion the factor 2 assumes
    t = np.linspace(0.0, 1.0, 2001)
    q, s_dot = (np.array(x).T for x in r.sol(t))
    assert np.trapezoid(2 * FLYBALL["C"] * flyball_spring_rate(q, s_dot) ** 2, t) > 1e-3
    balance = flyball_balance(r)
    assert np.abs(balance).max() < 1e-8, np.abs(balance).max()


def test_the_spring_rate_is_the_derivative_of_the_spring_length():
    """flyball_spring_rate against a central difference of the closed-form length along a motion."""
    q, s_dot, h = np.array([0.0, 0.58, 0.45, 0.45]), np.array([3.0, 0.7, -1.3, -1.3]), 1e-6
    length = [_flyball_geometry(x[2], x[1])[2] for x in (q - h * s_dot, q + h * s_dot)]
    assert flyball_spring_rate(q, s_dot)[0] == pytest.approx((length[1] - length[0]) / (2 * h), rel=1e-8)


def test_the_angular_momentum_about_the_free_shaft_is_conserved(benchmark_start):
    """No torque about the shaft: I_zz(α) φ̇ (the closed form's I_zz; the relative motion in the
    shaft's plane adds none) stays at its start, 2π I_zz(30°), to 1e-8 relative, while φ̇ itself
    changes by 10 % as the balls fly out."""
    system, r = benchmark_start
    I_zz = np.array([_flyball_geometry(alpha, s)[0] for s, alpha in r.q[:, 1:3]])
    L_z = I_zz * r.s_dot[:, 0]
    assert np.abs(L_z / L_z[0] - 1).max() < 1e-8
    assert np.ptp(r.s_dot[:, 0]) > 0.1 * 2 * np.pi
    assert L_z[0] == pytest.approx(2 * np.pi * _flyball_geometry(np.pi / 6, 0.5)[0], rel=1e-14)

"""Barhorst's formulation study, its symbolic part (A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems — another perspective on the
canonical equations of motion", §2–3): general
speeds u = Y q̇ + Z (eqs. 8–11, 93), the energy-conservation condition (eq. 38/55) on his three examples, and
Hamilton's canonical equations with multipliers integrated as a DAE."""

from dataclasses import replace

import numpy as np
import pytest
import sympy as sp

from projeq.symbolic import energy_rate, lagrangian_canonical, projective_canonical, t
from projeq.symbolic import barhorst_examples as bx
from projeq.symbolic.algebra import rotation_x, rotation_z


def _energy_in_u(example, form):
    """E = T + V of the example in the form's (q, u): q̇ = K u + J."""
    J = form.J if form.J is not None else sp.zeros(len(form.q), 1)
    return (example.T + example.V).xreplace(dict(zip(example.q_dot, form.K * sp.Matrix(form.u) + J)))


@pytest.fixture(scope="module")
def disk_forms():
    """The disk's Lagrangian canonical form in his general speeds (93) and the projective canonical form
    in the same speeds."""
    example = bx.rolling_disk(drag=0.0)
    ms = example.multiplier_system()
    lagrangian = lagrangian_canonical(ms, independent=[0, 1, 2], speeds=bx.disk_speeds(ms.q, [qi.diff(t) for qi in ms.q]))
    u, K = bx.disk_kinematics("body")
    projective = projective_canonical(example.bodies_in(u, K), example.q, u, K, t, example.values)
    return example, lagrangian, projective


def test_general_speeds_give_barhorsts_K_and_the_projective_momenta(disk_forms):
    """Eq. 93 speeds u = Y q̇ (u1..u3 the disk's angular velocity in C, u4 = q̇4, u5 = q̇5) with u4, u5 dependent:
    K̄ = K_I + K_D A_DI equals Barhorst's inverse map (95)–(96) with the rolling rows (97), and the Lagrangian
    momenta (45) equal the projective momenta (28) — both are ∂T/∂u — and ṗ agrees (eqs. 36 vs 50) at
    random states (round-off: 100 ε of the largest entry, measured ≤ 2.2e-16 for p, 5.3e-16 for ṗ; were
    1e-12 and 1e-10 entrywise)."""
    example, lagrangian, projective = disk_forms
    on_u = dict(zip(lagrangian.u, projective.u))
    assert (lagrangian.K.xreplace(on_u) - projective.K).applyfunc(sp.simplify) == sp.zeros(5, 3)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, u = rng.uniform(-0.6, 0.6, 5), rng.uniform(-3, 3, 3)
        p_l, p_p = lagrangian.momenta(0.0, q, u), projective.momenta(0.0, q, u)
        eps = np.finfo(float).eps
        assert np.abs(p_l - p_p).max() <= 100 * eps * np.abs(p_p).max(), p_l - p_p
        x = np.r_[q, p_l]
        rhs_l, rhs_p = lagrangian.rhs(0.0, x), projective.rhs(0.0, x)
        assert np.abs(rhs_l - rhs_p).max() <= 100 * eps * np.abs(rhs_p).max(), rhs_l - rhs_p


def test_speeds_that_are_not_linear_or_invertible_are_refused():
    ms = bx.barhorst_particle().multiplier_system()
    x, y = ms.q
    with pytest.raises(ValueError, match="speeds: must be linear"):
        lagrangian_canonical(ms, speeds=[x.diff(t) ** 2, y.diff(t)])
    with pytest.raises(ValueError, match="speeds: Y = ∂u/∂q̇ is singular"):
        lagrangian_canonical(ms, speeds=[x.diff(t) + y.diff(t), 2 * x.diff(t) + 2 * y.diff(t)])
    with pytest.raises(ValueError, match="independent: expected positions"):
        lagrangian_canonical(ms, independent=[x], speeds=[x.diff(t), y.diff(t)])


def test_eq_38_quick_return_conserves_energy_without_drive():
    """§3.3: "Conservation of energy can be confirmed as indicated in equation 38 … with the driving and load
    torque set to zero": for the Lagrangian canonical form (112)–(116), dE/dt of eq. 38 is identically
    T_m q̇1 + T_d q̇2 (the drive's power, q̇2 = H cos(q1 − q2)/q3 q̇1 by (109)), hence 0 for T_m = T_d = 0."""
    example = bx.quick_return(torques=True)
    form = lagrangian_canonical(example.multiplier_system(), independent=[0])
    (u,) = form.u
    rate = energy_rate(form, _energy_in_u(example, form))
    q1, q2, q3 = example.q
    power = bx.T_m * u + bx.T_d * bx.H_len * sp.cos(q1 - q2) / q3 * u
    assert sp.simplify(rate - power) == 0
    assert sp.simplify(rate.subs({bx.T_m: 0, bx.T_d: 0})) == 0


@pytest.mark.parametrize("form", ["projective", "lagrangian"])
def test_eq_38_particle_energy_is_conserved(form):
    """§3.1 with u = ẏ (A12 = 1/y²): the projective canonical equations (79)–(80) and the Lagrangian ones
    (86)–(87) satisfy eq. 38 identically for E = ½ m (ẋ² + ẏ²) + m g y; a wrong energy (without the
    potential) does not."""
    example = bx.barhorst_particle()
    if form == "lagrangian":
        canonical = lagrangian_canonical(example.multiplier_system(), independent=[1])
    else:
        u, K = sp.symbols("u2:3"), sp.Matrix([[1 / example.q[1] ** 2], [1]])
        canonical = projective_canonical(example.bodies_in(u, K), example.q, u, K, t, example.values)
    E = _energy_in_u(example, canonical)
    assert sp.simplify(energy_rate(canonical, E)) == 0
    assert sp.simplify(energy_rate(canonical, E - example.V)) != 0


def test_eq_38_rolling_disk_with_and_without_drag(disk_forms):
    """§3.2: without drag eq. 38 vanishes at random states (round-off); with his air-drag torque (104),
    −T_f u_i |u_i| about C's axes, the rate equals its power −T_f Σ |u_i|³. The equations keep T_f
    as a symbol (its value enters only when compiled), so the form of the fixture serves. Round-off:
    without drag at most 9.3e-20 Σ u² (bound 1e-18 Σ u², was 1e-15), with drag 5.5e-15 relative (bound
    5.5e-14, atol 0; was rtol 1e-9 with np.isclose's atol 1e-8, 8e-7 of the power), both the largest
    over 63 random states."""
    example, form, _ = disk_forms
    rate = energy_rate(form, _energy_in_u(example, form))
    numbers = {k: sp.Float(v) for k, v in example.values.items() if k != bx.T_f}
    f = sp.lambdify([form.q, form.u, bx.T_f], rate.xreplace(numbers), modules="numpy", cse=True)
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, u = rng.uniform(-0.6, 0.6, 5), rng.uniform(-20, 20, 3)
        assert abs(f(q, u, 0.0)) < 1e-18 * np.sum(u**2)  # T ~ 1e-6 u² J here; measured ≤ 5.7e-20 Σ u²
        assert np.isclose(f(q, u, 2e-6), -2e-6 * np.sum(np.abs(u) ** 3), rtol=5.5e-14, atol=0)  # ≤ 5.4e-16


def test_hamilton_dae_particle_follows_the_integral_curve():
    """§3.1 as Barhorst's eq. 69, a DAE in (x, y, p1, p2, λ) integrated without index reduction, from (2, 2) at
    rest: the constraint integrates to y = 1/(2.5 − x) (his footnote 6), which the motion follows to 3.4e-12 over
    3 s (measured 3.4e-13), and E = ½(p1² + p2²) + 10 y stays 20 to 1.5e-10 (measured 1.46e-11, rtol 1e-9; both
    bounds were 1e-8)."""
    ms = bx.barhorst_particle().multiplier_system()
    sol = ms.simulate_dae([2.0, 2.0], [0.0, 0.0], (0, 3), rtol=1e-9, atol=1e-11)
    x, y = sol.q
    assert x[-1] < -5  # it slid down the curve
    assert np.abs(y - 1 / (2.5 - x)).max() < 3.4e-12, np.abs(y - 1 / (2.5 - x)).max()
    energy = 0.5 * (sol.p**2).sum(axis=0) + 10 * y
    assert np.abs(energy - 20).max() < 1.5e-10, np.abs(energy - 20).max()
    with pytest.raises(ValueError, match="phi: expected 1 position constraints"):
        ms.hamilton_dae(phi=[ms.q[0], ms.q[1]])


def test_angular_velocity_from_the_orientation_is_barhorsts():
    """A body given by its orientation R alone gets ω from ω̃ = RᵀṘ: for the disk's C = R_z(q1) R_x(q2)
    R_y(q3) that is Barhorst's u1..u3 of eq. (93), entry by entry; for R_z(q1) R_x(q2) the very
    expressions sympy's trigsimp gives (its time for three Euler angles is 5 s, a test's too much)."""
    example = bx.rolling_disk()
    disk = replace(example.bodies[0], omega=None)
    from_R = replace(example, bodies=(disk, *example.bodies[1:])).bodies_in(example.q_dot, sp.eye(5))[0].omega
    assert (from_R - bx.disk_speeds(example.q, example.q_dot)[:3, :]).applyfunc(sp.expand) == sp.zeros(3, 1)
    q1, q2 = example.q[:2]
    tilt = replace(disk, R=rotation_z(q1) * rotation_x(q2))
    R_dot = tilt.R.diff(q1) * example.q_dot[0] + tilt.R.diff(q2) * example.q_dot[1]
    W = (tilt.R.T * R_dot).applyfunc(lambda e: sp.trigsimp(sp.expand(e)))
    omega = replace(example, bodies=(tilt,)).bodies_in(example.q_dot, sp.eye(5))[0].omega
    assert omega == sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])


def test_lagrangian_momenta_of_3_2_4_equal_the_projective_momenta_of_3_2_2_along_a_trajectory(disk_forms):
    """Barhorst §3.2.4: the Lagrangian canonical form in the speeds (93) has the momenta of the projective
    canonical form of §3.2.2. Both forms integrated (DOP853, rtol 1e-13) from the disk of the study (tilt
    0.15 rad, q̇3 = 20 rad/s, projeq.studies.compare_barhorst) over 0.3 s: their p(t) agree to 1e-13
    relative (measured 1.0e-14; p changes by 20 % over the span; was 1e-8). At rtol 1e-10 the two differ by
    the integrators' own error, which depends on scipy's step control: 3.1e-11 measured before, 5.9e-10 with
    scipy 1.17.1 (the projective run's error 5.4e-10 against its rtol-1e-13 run), and at
    each instant of the projective run the Lagrangian p(q, u) equals it to 100 ε (measured 2.4e-16; was
    1e-13)."""
    from projeq.studies.compare_barhorst import study_formulations

    _, lagrangian, projective = disk_forms
    q0, u0 = next(f for f in study_formulations("rolling_disk")[1] if "eq. 93" in f.name).start
    times = np.linspace(0.0, 0.3, 7)
    runs = [form.simulate(q0, u0, (0.0, 0.3), t_eval=times, rtol=1e-13, atol=1e-16)
            for form in (lagrangian, projective)]
    p_l, p_p = (run.y[5:] for run in runs)
    scale = np.abs(p_p).max()
    assert np.abs(p_l - p_p).max() < 1e-13 * scale, np.abs(p_l - p_p).max() / scale
    at_states = [lagrangian.momenta(ti, qi, ui) for ti, qi, ui in zip(times, runs[1].q.T, runs[1].u.T)]
    error = np.abs(np.array(at_states).T - p_p).max() / scale
    assert error < 100 * np.finfo(float).eps, error

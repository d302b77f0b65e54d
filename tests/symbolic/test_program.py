"""Program constraints (GPME), Jarzębowska (2002) §4.2 and §6.3–6.4."""

from functools import cache

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from projeq.symbolic.program import (_gpme_gradient, nielsen_equations, program_motion_equations,
                                     pseudo_regular_precession, replace_derivatives, tzenoff_equations)

t = sp.Symbol("t")
x, y = dynamicsymbols("x y")
xd, yd, xdd, ydd = x.diff(t), y.diff(t), x.diff(t, 2), y.diff(t, 2)
T = (xd**2 + yd**2) / 2  # particle of mass m = 1 (Jarzębowska (2002) §6.4)
N = xd * ydd - xdd * yd  # the determinant of (4.3)
RTOL, ATOL = 1e-10, 1e-12


def curvature(state):
    """Signed curvature (ẋÿ − ẏẍ)/(ẋ² + ẏ²)^{3/2} of the simulated path (Jarzębowska (2002) §6.4, 1/ro_p)."""
    _, _, u, v, a, b = state
    return (u * b - v * a) / (u * u + v * v) ** 1.5


@cache
def squared_curvature_gpme(Phi):
    """Constraint (4.3), κ² = Φ², differentiated once (p = 3) as in Jarzębowska (2002)."""
    return program_motion_equations(T, [x, y], [N**2 - Phi**2 * (xd**2 + yd**2) ** 3], t, differentiate=True)


def test_seed_equation_6_34a_reproduced_symbolically():
    """(6.33) for (4.3) with forces Q_x, Q_y gives (6.34a): ÿ + (ẍ − Q_x) ẋ/ẏ = Q_y, with ẍ dependent and
    a_ρλ = ẋ/ẏ (Jarzębowska (2002) §6.4)."""
    Qx, Qy = sp.symbols("Q_x Q_y")
    gpme = program_motion_equations(T, [x, y], [N**2 - 25 * (xd**2 + yd**2) ** 3], t, Q=[Qx, Qy],
                                    parameters={Qx: 0.0, Qy: 0.0}, differentiate=True)
    assert gpme.p == 3 and gpme.dependent == (x,)
    assert sp.simplify(gpme.a[0, 0] - xd / yd) == 0
    assert sp.simplify(gpme.equations[0] - (ydd + (xdd - Qx) * xd / yd - Qy)) == 0


@pytest.mark.parametrize("p", [1, 2, 3])
def test_gradient_of_R_p_is_the_lagrange_expression(p):
    """Tsenov's identity behind (6.30): ∂R_p/∂q^(p) = d/dt ∂T/∂q̇ − ∂T/∂q − Q for every p; checked against
    Lagrange's equations of the particle in polar coordinates (T = m(ṙ² + r²θ̇²)/2)."""
    r, th = dynamicsymbols("r theta")
    m, Qr, Qt = sp.symbols("m Q_r Q_theta")
    T_polar = m * (r.diff(t) ** 2 + r**2 * th.diff(t) ** 2) / 2
    lagrange = [sp.diff(sp.diff(T_polar, qi.diff(t)), t) - sp.diff(T_polar, qi) - Qi
                for qi, Qi in ((r, Qr), (th, Qt))]
    gradient = _gpme_gradient(T_polar, [r, th], t, p, sp.Matrix([Qr, Qt]))
    assert all(sp.simplify(g - e) == 0 for g, e in zip(gradient, lagrange))


def test_constant_curvature_path_is_the_circle_of_radius_one_over_phi():
    """Fig. 1 (Φ₁ = 5): consistent initial state (speed 1, normal acceleration v²Φ₁); the radius of curvature
    of the simulated path stays 1/Φ₁ = 0.2, and the path stays on the circle about (0, 0.2) through the
    initial point. Tolerance: 100 × rtol (errors accumulate over ~2.4 revolutions)."""
    sol = squared_curvature_gpme(sp.Integer(5)).simulate([0, 0, 1, 0, 0, 5], (0, 3), np.linspace(0, 3, 31),
                                                         rtol=RTOL, atol=ATOL)
    assert sol.success
    assert np.abs(1 / curvature(sol.y) - 0.2).max() < 100 * RTOL
    assert np.abs(np.hypot(sol.y[0], sol.y[1] - 0.2) - 0.2).max() < 100 * RTOL


def test_inconsistent_initial_state_keeps_curvature_at_a_different_value():
    """Fig. 3: the initial accelerations violate (4.3) (normal acceleration 3 instead of 5 at speed 1). The
    differentiated constraint keeps κ² − Φ₁² at its initial value, so the curvature stays constant at the
    initial κ = 3, not Φ₁ = 5 ("the trajectory curvature is kept constant but its value is different")."""
    gpme = squared_curvature_gpme(sp.Integer(5))
    sol = gpme.simulate([0, 0, 1, 0, 0, 3], (0, 3), np.linspace(0, 3, 31), rtol=RTOL, atol=ATOL)
    assert sol.success
    assert np.abs(curvature(sol.y) - 3).max() < 100 * RTOL  # same accumulation as the consistent case


def test_time_varying_curvature_profile_is_followed():
    """Fig. 2 (Φ₂ = 2 sin t + 1) with (4.3) differentiated, consistent initial state, over t ∈ [0, 3.5]
    (before
    Φ₂'s first zero at 7π/6, where κ² = Φ² loses the sign and the equations degenerate): κ = Φ₂(t).
    Tolerance 1000 × rtol: κ is a ratio of the integrated accelerations and the profile is not constant."""
    sol = squared_curvature_gpme(2 * sp.sin(t) + 1).simulate([0, 0, 1, 0, 0, 1], (0, 3.5),
                                                               np.linspace(0, 3.5, 36), rtol=RTOL, atol=ATOL)
    assert sol.success
    assert np.abs(curvature(sol.y) - (2 * np.sin(sol.t) + 1)).max() < 1000 * RTOL


def test_signed_curvature_constraint_passes_through_inflection_points():
    """Signed form of (4.3), ẋÿ − ẏẍ = Φ₂ (ẋ² + ẏ²)^{3/2}: already linear in ẍ, ÿ (p = 2), regular where Φ₂
    changes sign. Over t ∈ [0, 10] (three sign changes) the curvature of the simulated path, from the
    integrated velocities differentiated by central differences (h = 1e-3), equals Φ₂(t): tolerance 2e-5 for
    the difference truncation h²/6 · max|d³v/dt³| ≈ 5e-6 (|κ| ≤ 3). With Q = 0 the GPME (6.34a) is
    ẋẍ + ẏÿ = 0, so the speed stays 1 (to 7e-9, measured 7.0e-10; was 1000 × rtol = 1e-7)."""
    Phi = 2 * sp.sin(t) + 1
    gpme = program_motion_equations(T, [x, y], [N - Phi * (xd**2 + yd**2) ** sp.Rational(3, 2)], t)
    assert gpme.p == 2
    times = np.linspace(0, 10, 10001)
    sol = gpme.simulate([0, 0, 1, 0], (0, 10), times, rtol=RTOL, atol=ATOL)
    u, v = sol.y[2], sol.y[3]
    a, b = np.gradient(u, times, edge_order=2), np.gradient(v, times, edge_order=2)
    assert np.abs(curvature([None, None, u, v, a, b]) - (2 * np.sin(times) + 1)).max() < 2e-5
    assert np.abs(np.hypot(u, v) - 1).max() < 7e-9, np.abs(np.hypot(u, v) - 1).max()


LIGHT = 2.0  # the speed of light c of the relativistic particle (T not quadratic in the velocities)


def relativistic_T(speed_squared, mass=1):
    """T = m c² (1 − √(1 − v²/c²)): Lagrange's d/dt ∂T/∂q̇ − ∂T/∂q = Q is the relativistic particle."""
    return mass * LIGHT**2 * (1 - sp.sqrt(1 - speed_squared / LIGHT**2))


@pytest.mark.parametrize("form", [nielsen_equations, tzenoff_equations])
def test_nielsen_and_tzenoff_forms_are_lagranges_for_a_non_quadratic_T(form):
    """Nielsen (5.1), ∂Ṫ/∂q̇ − 2 ∂T/∂q = Q, and Tzenoff (5.2), ½(∂T̈/∂q̈ − 3 ∂T/∂q) = Q, equal Lagrange's
    equations by the identity (6.6), which does not assume T quadratic (remark after (6.7)): the
    relativistic particle in polar coordinates, T = m c² (1 − √(1 − (ṙ² + r²θ̇²)/c²)); checked at 5 random
    states to 100 ε relative (the difference is round-off, measured ≤ 3.4e-16)."""
    r, th = dynamicsymbols("r theta")
    m, Qr, Qt = sp.symbols("m Q_r Q_theta")
    T_rel = relativistic_T(r.diff(t) ** 2 + r**2 * th.diff(t) ** 2, m)
    lagrange = [sp.diff(sp.diff(T_rel, qi.diff(t)), t) - sp.diff(T_rel, qi) - Qi
                for qi, Qi in ((r, Qr), (th, Qt))]
    equations = form(T_rel, [r, th], t, [Qr, Qt], {m: 1, Qr: 0, Qt: 0})
    names = [sp.symbols(f"r_{k} theta_{k}") for k in range(4)]
    plain = replace_derivatives(sp.Matrix([*equations, *lagrange]), [r, th], t, names)
    both = sp.lambdify([*sum(names, ()), m, Qr, Qt], plain)
    rng = np.random.default_rng(7)
    for values in rng.uniform(0.1, 0.6, (5, 11)):
        values[0] += 1  # r ≥ 1.1: speed² = ṙ² + r² θ̇² ≤ 0.36 (1 + 1.6²) < c²
        ours, reference = np.split(both(*values).ravel(), 2)
        assert np.allclose(ours, reference, rtol=100 * np.finfo(float).eps, atol=0)


def test_non_quadratic_T_program_motion_keeps_curvature_and_relativistic_energy():
    """A relativistic particle (T not quadratic, remark after (6.7)) on the signed curvature program
    constraint ẋÿ − ẏẍ = Φ (ẋ² + ẏ²)^{3/2}, Φ = 1.5, pushed by Q = (F, 0), F = 0.7, from speed 1 over 3 time
    units: the path's curvature stays Φ (to 100 ε × Φ, measured 4e-16) and the energy integral
    m c² (γ − 1) − F x of the relativistic particle stays constant (4.4e-10, measured 4.35e-11) while the
    speed changes by 0.68 — the Newtonian ½ m v² − F x drifts by 0.31, so the test tells the two T apart."""
    F, Phi = 0.7, 1.5
    gpme = program_motion_equations(relativistic_T(xd**2 + yd**2), [x, y], [N - Phi * (xd**2 + yd**2) ** 1.5],
                                    t, Q=[F, 0])
    sol = gpme.simulate([0, 0, 1, 0], (0, 3), np.linspace(0, 3, 31), rtol=1e-11, atol=1e-12)
    assert sol.success
    accelerations = np.array([gpme.rhs(ti, xi)[2:] for ti, xi in zip(sol.t, sol.y.T)]).T
    assert np.abs(curvature([*sol.y, *accelerations]) - Phi).max() < 100 * np.finfo(float).eps * Phi
    speed_squared = sol.y[2] ** 2 + sol.y[3] ** 2
    energy = LIGHT**2 * (1 / np.sqrt(1 - speed_squared / LIGHT**2) - 1) - F * sol.y[0]
    assert np.ptp(energy) < 4.4e-10 and np.ptp(np.sqrt(speed_squared)) > 0.5, np.ptp(energy)
    assert np.ptp(speed_squared / 2 - F * sol.y[0]) > 0.1


phi, psi, theta = dynamicsymbols("phi psi theta")
LAMBDA = sp.Symbol("lambda")


def printed_4_2(rate_in_radicand):
    """Jarzębowska (2002) eq. (4.2) as printed, with ``rate_in_radicand``² sin²ϑ + ϑ̇² under the 3/2 power."""
    psi_d, th_d = psi.diff(t), theta.diff(t)
    return (psi.diff(t, 2) * th_d * sp.sin(theta) - theta.diff(t, 2) * psi_d * sp.sin(theta)
            + 2 * psi_d * th_d**2 * sp.cos(theta) + psi_d**3 * sp.sin(theta) ** 2 * sp.cos(theta)
            - LAMBDA * (rate_in_radicand**2 * sp.sin(theta) ** 2 + th_d**2) ** sp.Rational(3, 2))


def test_grioli_condition_is_4_2_with_psi_dot_not_phi_dot():
    """(4.1) with the body rates (4.1a) is (4.2) exactly (symbolic, expanded) once the radicand reads
    ψ̇² sin²ϑ + ϑ̇² (= p² + q²); the printed φ̇² sin²ϑ differs wherever φ̇² ≠ ψ̇² (here by 0.3 at a state
    with φ̇ = 2, ψ̇ = 1). The regular precession (ϑ̇ = ψ̈ = ϑ̈ = 0) satisfies it iff λ = cot ϑ."""
    condition = pseudo_regular_precession(phi, psi, theta, t, LAMBDA)
    assert sp.expand(condition - printed_4_2(psi.diff(t))) == 0
    state = {psi.diff(t, 2): 0.2, theta.diff(t, 2): 0.1, phi.diff(t): 2.0, psi.diff(t): 1.0,
             theta.diff(t): 0.5, theta: 0.7, LAMBDA: 0.5}
    assert abs(float((condition - printed_4_2(phi.diff(t))).subs(state))) > 0.1
    regular = condition.subs({psi.diff(t, 2): 0, theta.diff(t, 2): 0, theta.diff(t): 0})
    (solution,) = sp.solve(regular.subs(psi.diff(t), sp.Symbol("w", positive=True)), LAMBDA)
    for angle in (0.3, 1.2, 2.5):  # cos ϑ / |sin ϑ| = cot ϑ on 0 < ϑ < π
        assert float(solution.subs(theta, angle)) == pytest.approx(1 / np.tan(angle), rel=1e-14, abs=0)  # 1 ulp at 1.2


def test_pseudo_regular_precession_keeps_the_axis_on_a_cone_of_half_angle_arccot_lambda():
    """A free symmetric body (A = 1, C = 3/2) under the program constraint (4.1)–(4.2), λ = 1/2, from a
    non-regular state (ϑ̇ = 0.3): the GPME (6.33) with p = 2. Over 5 time units ϑ varies by 0.65 and ψ̇
    by 0.06 (not a regular precession), yet the symmetry axis e = (sin ϑ sin ψ, −sin ϑ cos ψ, cos ϑ)
    stays in one plane n·e = cos β with cot β = λ — on a circular cone of half-angle arccot λ: plane
    residual < 3e-9 (measured 2.9e-10), |cos β − λ/√(1 + λ²)| < 3e-10 (measured 2.3e-11)."""
    rates = [f.diff(t) for f in (phi, psi, theta)]
    transverse = rates[1] ** 2 * sp.sin(theta) ** 2 + rates[2] ** 2
    spin = rates[1] * sp.cos(theta) + rates[0]
    T_top = transverse / 2 + sp.Rational(3, 4) * spin**2
    lam = sp.Rational(1, 2)
    constraint = pseudo_regular_precession(phi, psi, theta, t, lam)
    gpme = program_motion_equations(T_top, [phi, psi, theta], [constraint], t)
    assert gpme.p == 2
    sol = gpme.simulate([0, 0, 1.0, 2.0, 0.5, 0.3], (0, 5), np.linspace(0, 5, 51), rtol=RTOL, atol=ATOL)
    assert sol.success and np.ptp(sol.y[2]) > 0.5 and np.ptp(sol.y[4]) > 0.03
    _, ps, th = sol.y[:3]
    axis = np.array([np.sin(th) * np.sin(ps), -np.sin(th) * np.cos(ps), np.cos(th)]).T
    *_, plane = np.linalg.svd(np.hstack([axis, np.ones((len(axis), 1))]))[2]
    normal, offset = plane[:3] / np.linalg.norm(plane[:3]), -plane[3] / np.linalg.norm(plane[:3])
    assert np.abs(axis @ normal - offset).max() < 3e-9
    assert abs(abs(offset) - float(lam / sp.sqrt(1 + lam**2))) < 3e-10


def test_nonlinear_constraint_is_refused_with_the_offer_to_differentiate():
    with pytest.raises(ValueError, match="constraints: .* not linear .* differentiate=True"):
        program_motion_equations(T, [x, y], [N**2 - 25 * (xd**2 + yd**2) ** 3], t)


def test_undeclared_symbols_are_named():
    k = sp.Symbol("k")
    with pytest.raises(ValueError, match="constraints: undeclared symbols k"):
        program_motion_equations(T, [x, y], [N - k], t)


def test_mismatched_forces_are_refused():
    with pytest.raises(ValueError, match="Q: expected 2"):
        program_motion_equations(T, [x, y], [N - 1], t, Q=[0])
    with pytest.raises(ValueError, match="Q: expected 2"):
        nielsen_equations(T, [x, y], t, Q=[0])
    with pytest.raises(ValueError, match="T, Q: undeclared symbols k"):
        tzenoff_equations(sp.Symbol("k") * T, [x, y], t)


def test_coordinates_must_be_functions_of_time():
    with pytest.raises(ValueError, match="q: expected functions"):
        program_motion_equations(T, [sp.Symbol("x"), y], [N - 1], t)


def test_mixed_constraint_orders_are_refused():
    z = dynamicsymbols("z")
    with pytest.raises(ValueError, match="constraints: all must have the same order"):
        program_motion_equations(T + z.diff(t) ** 2 / 2, [x, y, z], [N - 1, z.diff(t) - 1], t)


def test_initial_state_size_is_checked():
    with pytest.raises(ValueError, match="x0: expected 6"):
        squared_curvature_gpme(sp.Integer(5)).simulate([0, 0, 1, 0], (0, 1))

"""Program constraints (GPME), Jarzębowska (2002) §4.2 and §6.3–6.4."""

from functools import cache

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols

from projeq.symbolic.program import _gpme_gradient, program_motion_equations

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
    ẋẍ + ẏÿ = 0, so the speed stays 1 (to 1000 × rtol, measured 7e-10)."""
    Phi = 2 * sp.sin(t) + 1
    gpme = program_motion_equations(T, [x, y], [N - Phi * (xd**2 + yd**2) ** sp.Rational(3, 2)], t)
    assert gpme.p == 2
    times = np.linspace(0, 10, 10001)
    sol = gpme.simulate([0, 0, 1, 0], (0, 10), times, rtol=RTOL, atol=ATOL)
    u, v = sol.y[2], sol.y[3]
    a, b = np.gradient(u, times, edge_order=2), np.gradient(v, times, edge_order=2)
    assert np.abs(curvature([None, None, u, v, a, b]) - (2 * np.sin(times) + 1)).max() < 2e-5
    assert np.abs(np.hypot(u, v) - 1).max() < 1000 * RTOL


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

"""Bremer's car (Bremer (2009) §2.1–2.2, B(5)–(12)).

The non-holonomic constraint v_y = 0 goes into F *before* the derivation (B(11)); the
Projection Equation then gives B(9) directly (B(12)). Hamel's route (B(3)–(8)) needs the
full set of velocities and gives the same only if v_y = 0 is inserted *after* it.
"""

import numpy as np
import sympy as sp

import projeq as pq
from projeq.symbolic import hamel_coefficients, hamel_equations

# random parameters and states drawn from this generator in every test
RNG_SEED = 20240607
# comparisons of two evaluations of the same closed form: round-off only, O(10) operations
# on numbers of order 10³ (m, C°): measured 1.2e-16 of the scale at most (was 1e-12)
RTOL = 100 * np.finfo(float).eps


def random_car(rng):
    m, c = rng.uniform(500, 2000), rng.uniform(0.2, 2.0)
    C0 = m * c * c + rng.uniform(200, 3000)
    f_x, f_y, M_z = rng.uniform(-3000, 3000, 3)
    return m, C0, c, f_x, f_y, M_z


def b9(m, C0, c, f_x, M_z, vx, wz, f_y=0.0):
    """B(9): [[m, 0], [0, C°]] ṡ̇ + [[0, −m c ω_z], [m c ω_z, 0]] ṡ − (f_x, M_z) = 0, with a
    lateral force f_y at the mass centre adding c f_y to the ω_z-row (B(12))."""
    M = np.diag([m, C0])
    b = np.array([[0, -m * c * wz], [m * c * wz, 0]]) @ np.array([vx, wz]) - np.array([f_x, M_z + c * f_y])
    return M, b


def b12(m, C0, c, f_x, f_y, M_z, vx, wz):
    """B(12) evaluated literally: Fᵀ {M' s̈ + ω̃ M' ṡ − (f_x, f_y, M_z)} with
    F = [[1, 0], [0, c], [0, 1]] (B(11)), M' = [[m, 0], [0, m c], [0, C^c]], C^c = C° − m c²;
    returns the (M, b) of M s̈ + b = 0."""
    Cc = C0 - m * c * c
    F = np.array([[1.0, 0.0], [0.0, c], [0.0, 1.0]])
    Mp = np.array([[m, 0.0], [0.0, m * c], [0.0, Cc]])
    W = np.array([[0.0, -wz, 0.0], [wz, 0.0, 0.0], [0.0, 0.0, 0.0]])
    return F.T @ Mp, F.T @ (W @ Mp @ np.array([vx, wz]) - np.array([f_x, f_y, M_z]))


def test_gauss_form_is_B9_and_B12_at_random_states():
    """B(9) and B(12): projeq's Gauss form M s̈ + b = 0 of ``scenes.car`` equals B(9) (and
    the literal product B(12)) for random m, C°, c, loads and states; both evaluators give
    the accelerations of B(9)."""
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(10):
        m, C0, c, f_x, f_y, M_z = random_car(rng)
        system = pq.scenes.car(m=m, C0=C0, c=c, f_x=f_x, f_y=f_y, M_z=M_z)
        for _ in range(5):
            q = rng.uniform(-5, 5, 3)
            vx, wz = rng.uniform(-20, 20), rng.uniform(-2, 2)
            M, b = system.gauss_form(q, [vx, wz])
            M9, b9_ = b9(m, C0, c, f_x, M_z, vx, wz, f_y)
            M12, b12_ = b12(m, C0, c, f_x, f_y, M_z, vx, wz)
            scale = np.abs(M9).max()
            assert np.allclose(M, M9, rtol=0, atol=RTOL * scale)
            assert np.allclose(M12, M9, rtol=0, atol=RTOL * scale)
            b_scale = np.abs(b9_).max() + np.abs(M9).max() * (vx**2 + wz**2)
            assert np.allclose(b, b9_, rtol=0, atol=RTOL * b_scale)
            assert np.allclose(b12_, b9_, rtol=0, atol=RTOL * b_scale)
            expected = np.linalg.solve(M9, -b9_)
            for method in ("recursive", "dense"):
                s_ddot = system.accelerations(q, [vx, wz], method=method)
                assert np.allclose(s_ddot, expected, rtol=0, atol=RTOL * (1 + np.abs(expected).max() + b_scale / scale))


def test_hamel_route_B3_B8_needs_v_y_until_the_end():
    """B(3)–(8) and docs/theory.md §8 with ``projeq.symbolic.hamel``: with ṡ = H(q) q̇ of B(6),
    β₂^{3,1} = −1 and β₁^{1,3} = 0 (B(7)); Hamel's equations with all three velocities,
    after inserting v_y = 0, are B(9) with f_y at the mass centre (the load of
    ``scenes.car``). Inserting v_y = 0 into T first loses the −m c ω_z² term (B(2.1) text:
    "not allowed to set v_y = 0 in advance")."""
    q = sp.symbols("x y gamma")
    vx, vy, wz = s = sp.symbols("v_x v_y omega_z")
    a_x, a_y, a_z = s_dd = sp.symbols("a_x a_y a_z")
    m, c, C0, f_x, f_y, M_z = parameters = sp.symbols("m c C0 f_x f_y M_z")
    g = q[2]
    H = sp.Matrix([[sp.cos(g), sp.sin(g), 0], [-sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
    beta = hamel_coefficients(H, q)
    assert beta[1, 2, 0] == -1  # β₂^{3,1} (1-based) = −1
    assert beta[0, 0, 2] == 0  # β₁^{1,3} = 0, B(7)
    T = m / 2 * (vx**2 + (vy + c * wz) ** 2) + (C0 - m * c**2) / 2 * wz**2  # v_c = (v_x, v_y + c ω_z)
    Q = [f_x, f_y, M_z + c * f_y]  # f at the mass centre, M_z: virtual power f·v_c + M_z ω_z

    def after_v_y_0(T):
        eqs = hamel_equations(T, q, s, H, Q, s_dd, parameters=parameters)
        return [eqs[n].subs({vy: 0, a_y: 0}) for n in (0, 2)]

    B9 = [m * a_x - m * c * wz**2 - f_x, C0 * a_z + m * c * vx * wz - M_z - c * f_y]
    assert all(sp.simplify(e - b) == 0 for e, b in zip(after_v_y_0(T), B9))
    wrong = after_v_y_0(T.subs(vy, 0))  # the wrong route: v_y = 0 in T before Hamel's equations
    assert sp.simplify(wrong[0] - B9[0]) == m * c * wz**2  # the centripetal term is lost


def test_simulation_both_evaluators_energy_and_constraint():
    """B(9) without loads: ½ m v_x² + ½ C° ω_z² is conserved (m v_x v̇_x + C° ω_z ω̇_z = 0),
    the rear axle never slides (residual of −sin γ ẋ + cos γ ẏ = 0 in every Result), and
    with c = 0 the path is the circle x = (v/ω) sin ωt, y = (v/ω)(1 − cos ωt). Measured with both
    evaluators (the same to the last digit): residual 1.1e-16, energy drift 7.2e-14, circle 1.7e-12 m;
    the largest over (v_x, ω_z) = (8, 0.5), (12, 0.2) and circles (4, 0.8), (6, 0.3): 2.2e-16, 4.2e-13,
    2.0e-11 m. Bounds 100 ε, 5e-12, 2e-10 m (were 1e-12, 1e-7, 1e-7 m)."""
    for method in ("recursive", "dense"):
        system = pq.scenes.car(s_dot0=(10.0, 0.3))
        result = pq.simulate(system, 20.0, evaluator=method, rtol=1e-10, atol=1e-12)
        assert result.constraint_residual.shape == (len(result.t), 1)
        # K ṡ satisfies the constraint identically: only round-off of sin/cos products
        assert np.abs(result.constraint_residual).max() < RTOL
        assert result.energy_drift < 5e-12, result.energy_drift
        system = pq.scenes.car(c=0.0, s_dot0=(5.0, 0.5))
        result = pq.simulate(system, 10.0, evaluator=method, rtol=1e-11, atol=1e-12)
        t = result.t
        circle = np.column_stack((10 * np.sin(0.5 * t), 10 * (1 - np.cos(0.5 * t))))
        # integration error of a 10 m circle at rtol 1e-11 over ~1 revolution
        assert np.abs(result.q[:, :2] - circle).max() < 2e-10


def test_results_of_holonomic_systems_report_an_empty_residual():
    """Issue item 1: systems without velocity constraints report an empty residual array."""
    result = pq.simulate(pq.scenes.double_pendulum(), 0.1, n_points=5)
    assert result.constraint_residual.shape == (5, 0)

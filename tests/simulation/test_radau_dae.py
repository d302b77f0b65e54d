"""Radau IIA for differential-algebraic equations (projeq.simulation.integrators.radau_dae), as used for
Hamilton's canonical equations with multipliers in A. A. Barhorst, "Generalized momenta in constrained non-holonomic systems — another perspective on the canonical equations of motion"."""

import numpy as np
import pytest

from projeq.simulation.integrators import radau_dae


def test_radau_dae_index_2_and_3_pendulum():
    """Radau IIA on a pendulum in Cartesian coordinates (x, y, u, v, λ) as an index-3 (x² + y² = 1) and an
    index-2 (x u + y v = 0) DAE against the angle ODE θ̈ = −g sin θ (DOP853, rtol 1e-12): x agrees to 1.1e-9
    after 3 s and the energy drifts < 5e-9 (measured at rtol 1e-8, index 3 and 2: x 3.0e-11 and 1.02e-10,
    energy 1.7e-10 and 4.5e-10; were 1e-7 and 1e-8)."""
    from scipy.integrate import solve_ivp

    g, theta0 = 9.81, 0.5
    reference = solve_ivp(lambda _, z: [z[1], -g * np.sin(z[0])], (0, 3), [theta0, 0], rtol=1e-12, atol=1e-12)

    def f(_, z, position):
        x, y, u, v, lam = z
        return [u, v, -x * lam, -y * lam - g, x * x + y * y - 1 if position else x * u + y * v]

    z0 = [np.sin(theta0), -np.cos(theta0), 0, 0, g * np.cos(theta0)]
    for position, index in ((True, [1, 1, 2, 2, 3]), (False, [1, 1, 2, 2, 2])):
        sol = radau_dae(lambda s, z: f(s, z, position), (0, 3), z0, mass=[1, 1, 1, 1, 0], index=index,
                        rtol=1e-8, atol=1e-10)
        assert sol.success
        x, y, u, v, _ = sol.y
        assert abs(x[-1] - np.sin(reference.y[0, -1])) < 1.1e-9, x[-1] - np.sin(reference.y[0, -1])
        energy = 0.5 * (u * u + v * v) + g * y
        assert np.abs(energy - energy[0]).max() < 5e-9, np.abs(energy - energy[0]).max()


def test_radau_dae_bad_input():
    with pytest.raises(ValueError, match="mass, index: expected 2 values"):
        radau_dae(lambda s, y: y, (0, 1), [1.0, 2.0], mass=[1.0])
    with pytest.raises(ValueError, match="t_span: expected t_end > t0"):
        radau_dae(lambda s, y: y, (1, 0), [1.0])


def test_radau_dae_newton_jacobian_is_exact_where_the_right_hand_side_takes_complex_states():
    """The Newton iterations' ∂f/∂y (integrators._dae_jacobian): for the index-3 pendulum's f the
    closed form [[0, 0, 1, 0, 0], [0, 0, 0, 1, 0], [−λ, 0, 0, 0, −x], [0, −λ, 0, 0, −y],
    [2x, 2y, 0, 0, 0]] to round-off (1e-15) by the complex step; for an f that refuses complex
    states by forward differences, to their error √ε_m ≈ 1.5e-8 (relative to max|J| = 2.5 here),
    n evaluations counted either way (test_radau_dae_index_2_and_3_pendulum runs with the exact one)."""
    from projeq.simulation.integrators import _dae_jacobian

    def f(_, z):
        x, y, u, v, lam = z
        return np.array([u, v, -x * lam, -y * lam - 9.81, x * x + y * y - 1])

    def real_only(s, z):
        if np.iscomplexobj(z):
            raise TypeError("real states only")
        return f(s, z)

    z = np.array([0.6, -0.8, 0.3, 0.2, 1.25])
    x, y, _, _, lam = z
    closed = np.array([[0, 0, 1, 0, 0], [0, 0, 0, 1, 0], [-lam, 0, 0, 0, -x], [0, -lam, 0, 0, -y],
                       [2 * x, 2 * y, 0, 0, 0]])
    for fun, exact, tol in ((f, True, 1e-15), (real_only, False, 1.5e-8 * 2.5)):
        counts = {"nfev": 0}

        def counted(s, w, fun=fun, counts=counts):
            counts["nfev"] += 1
            return np.asarray(fun(s, w), dtype=float)

        J = _dae_jacobian(fun, counted, 0.0, z, f(0.0, z), exact, counts)
        assert np.abs(J - closed).max() <= tol and counts["nfev"] == 5

"""The LU factorisations of scipy's Radau and BDF by LAPACK directly
(:func:`projeq.simulation.integrators.with_direct_lu`): the same results as scipy's own
``lu_factor``/``lu_solve``, bit for bit, which are the reference throughout."""

import warnings

import numpy as np
import pytest
import scipy.integrate
from scipy.linalg import LinAlgWarning, lu_factor, lu_solve

import projeq as pq
import projeq.simulation.integrators as integrators
from projeq.simulation.integrators import lu_factorized, lu_solved, with_direct_lu


@pytest.mark.parametrize("dtype", [float, complex])
def test_factors_and_solutions_are_scipys_bit_for_bit(dtype):
    rng = np.random.default_rng(7)
    A = rng.standard_normal((18, 18)) + (1j * rng.standard_normal((18, 18)) if dtype is complex else 0)
    b = rng.standard_normal(18) + (1j * rng.standard_normal(18) if dtype is complex else 0)
    lu, pivots = lu_factorized(A.copy())
    reference = lu_factor(A.copy(), overwrite_a=True)
    assert lu.tobytes() == reference[0].tobytes() and np.array_equal(pivots, reference[1])
    x = lu_solved((lu, pivots), b.copy())
    assert x.tobytes() == lu_solve(reference, b.copy(), overwrite_b=True).tobytes()
    # the residual of a backward-stable solve: measured 0.32 ε ‖A‖∞ ‖x‖∞ (was 1000 ε)
    assert np.abs(A @ x - b).max() < 100 * np.finfo(float).eps * np.abs(A).sum(axis=1).max() * np.abs(x).max()


def test_non_finite_and_singular_input_as_scipy():
    with pytest.raises(ValueError, match="infs or NaNs"):
        lu_factorized(np.array([[1.0, np.nan], [0.0, 1.0]]))
    with pytest.raises(ValueError, match="infs or NaNs"):
        lu_solved(lu_factor(np.eye(2)), np.array([np.inf, 0.0]))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lu_factorized(np.array([[1.0, 2.0], [2.0, 4.0]]))
    assert [str(w.message) for w in caught] == ["Diagonal number 2 is exactly zero. Singular matrix."]
    assert caught[0].category is LinAlgWarning


def van_der_pol(t, y, mu=1000.0):
    """A stiff oscillator (Hairer & Wanner, *Solving ODEs II*, §IV.1, eq. (1.5))."""
    return np.array([y[1], mu * (1 - y[0] ** 2) * y[1] - y[0]])


def trajectory(method, direct: bool):
    solver = method(van_der_pol, 0.0, np.array([2.0, 0.0]), 2.0, rtol=1e-6, atol=1e-9)
    if direct:
        with_direct_lu(solver)
    states = []
    while solver.status == "running":
        solver.step()
        states.append(solver.y.copy())
    return np.array(states), solver.nlu, solver.nfev


@pytest.mark.parametrize("method", [scipy.integrate.Radau, scipy.integrate.BDF])
def test_solver_steps_are_scipys_bit_for_bit(method):
    states, nlu, nfev = trajectory(method, direct=True)
    reference, reference_nlu, reference_nfev = trajectory(method, direct=False)
    assert states.tobytes() == reference.tobytes()
    assert (nlu, nfev) == (reference_nlu, reference_nfev) and nlu > 10


class UsersRadau(scipy.integrate.Radau):
    """A user's subclass: simulate leaves its factorisations to scipy."""


def test_simulate_factorises_directly_with_scipys_radau_only(monkeypatch):
    import projeq.simulation.driver as driver

    calls = []
    for name in ("lu_factorized", "lu_solved"):
        original = getattr(integrators, name)
        monkeypatch.setattr(integrators, name, lambda *a, f=original, n=name: calls.append(n) or f(*a))
    system, settings = pq.scenes.spin_up_beam(), {"rtol": 1e-4, "atol": 1e-6, "n_points": 21}
    direct = pq.simulate(system, 2.0, method="Radau", **settings)
    assert {"lu_factorized", "lu_solved"} <= set(calls)
    calls.clear()
    pq.simulate(system, 0.5, method=UsersRadau, **settings)
    assert calls == []
    monkeypatch.setattr(driver, "with_direct_lu", lambda solver: None)  # scipy's lu_factor and lu_solve
    reference = pq.simulate(system, 2.0, method="Radau", **settings)
    assert direct.q.tobytes() == reference.q.tobytes() and direct.s_dot.tobytes() == reference.s_dot.tobytes()
    assert (direct.nfev, direct.njev) == (reference.nfev, reference.njev)

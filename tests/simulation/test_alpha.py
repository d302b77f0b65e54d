"""The generalized-α method (projeq.simulation.alpha): its order, its damping of unresolved modes, and
its runs through simulate (Jansen, Whiting & Hulbert 2000)."""

import numpy as np
import pytest
import scipy.integrate
import scipy.linalg

import projeq as pq
from projeq.simulation.alpha import GeneralizedAlpha, coefficients

#: a lightly damped oscillator ẏ = A y (ω = 2 rad/s, ζ = 0.05): its exact solution by the matrix exponential
A = np.array([[0.0, 1.0], [-4.0, -0.2]])
Y0 = np.array([1.0, 0.0])


def _oscillator(h: float, rho_inf: float = 0.9, t_end: float = 2.0):
    return scipy.integrate.solve_ivp(lambda t, y: A @ y, (0.0, t_end), Y0, method=GeneralizedAlpha, step=h,
                                     rho_inf=rho_inf, jac=lambda t, y: A, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("rho_inf", [0.0, 0.5, 0.9, 1.0])
def test_second_order_on_a_linear_oscillator(rho_inf):
    """Against the matrix exponential at t = 2 s: halving h divides the error by 4 (second order, as
    Jansen et al. 2000 prove for γ = 1/2 + α_m − α_f): the ratios at h = 0.04 → 0.02 → 0.01 lie in
    [3.6, 4.4] (measured 4.00–4.08)."""
    exact = scipy.linalg.expm(2.0 * A) @ Y0
    errors = [np.abs(_oscillator(h, rho_inf).y[:, -1] - exact).max() for h in (0.04, 0.02, 0.01)]
    ratios = np.array(errors[:-1]) / np.array(errors[1:])
    assert np.all((ratios > 3.6) & (ratios < 4.4)), (errors, ratios)


@pytest.mark.parametrize("rho_inf", [0.0, 0.3, 0.9, 1.0])
def test_an_unresolved_mode_is_damped_at_the_spectral_radius(rho_inf):
    """y' = iω y with hω = 1e7 (a stiff undamped mode, written as a real 2 × 2 system): the amplitude
    decays as ρ∞ⁿ (the amplification's spectral radius as hω → ∞, the method's definition; with both of its
    eigenvalues −ρ∞, a Jordan block: (a + b n) ρ∞ⁿ), so that (|y₆₀| / |y₃₀|)^(1/30) lies in
    [ρ∞, 1.03 ρ∞] (2^(1/30) = 1.023); ρ∞ = 0 removes the mode in a step, ρ∞ = 1 keeps it to 1e-12."""
    B = np.array([[0.0, 1e7], [-1e7, 0.0]])
    found = scipy.integrate.solve_ivp(lambda t, y: B @ y, (0.0, 60.0), Y0, method=GeneralizedAlpha, step=1.0,
                                      rho_inf=rho_inf, jac=lambda t, y: B, rtol=1e-10, atol=1e-12,
                                      t_eval=[0.0, 2.0, 30.0, 60.0])
    amplitudes = np.linalg.norm(found.y, axis=0)
    if rho_inf == 0.0:
        assert amplitudes[1] <= 1e-6 * amplitudes[0], amplitudes
    elif rho_inf == 1.0:
        assert np.abs(amplitudes - 1.0).max() <= 1e-12, amplitudes
    else:
        rate = (amplitudes[3] / amplitudes[2]) ** (1 / 30)
        assert rho_inf <= rate <= 1.03 * rho_inf, rate


def test_coefficients_of_the_spectral_radius():
    """Jansen et al. (2000), eq. (18), (20): ρ∞ = 1 gives the trapezoidal rule's α_m = α_f = γ = 1/2, ρ∞ = 0
    α_m = 3/2, α_f = 1, γ = 1."""
    assert coefficients(1.0) == (0.5, 0.5, 0.5)
    assert coefficients(0.0) == (1.5, 1.0, 1.0)


def test_simulate_steps_the_double_pendulum_at_second_order_over_segments():
    """simulate(method="GeneralizedAlpha", step=h): one solver stepped over the 20 segments (the same result
    as one segment, bit for bit), the exact ∂ẋ/∂x counted in njev, and second order against DOP853 at
    rtol 1e-12: halving h from 4e-3 divides the largest error in q over 1 s by 3.5 to 4.5 (measured 4.0)."""
    system = pq.scenes.double_pendulum()
    reference = pq.simulate(system, 1.0, method="DOP853", rtol=1e-12, atol=1e-14, n_points=11)
    runs = {h: pq.simulate(system, 1.0, method="GeneralizedAlpha", step=h, n_points=11) for h in (4e-3, 2e-3)}
    one = pq.simulate(system, 1.0, method="GeneralizedAlpha", step=4e-3, n_points=11, n_segments=1)
    assert np.array_equal(one.q, runs[4e-3].q) and one.method == "GeneralizedAlpha" and one.njev > 0
    errors = [np.abs(r.q - reference.q).max() for r in runs.values()]
    assert 3.5 <= errors[0] / errors[1] <= 4.5, errors


@pytest.mark.parametrize("scene", ["double_pendulum", "chain"])
def test_the_compiled_loop_takes_the_solvers_steps(scene, monkeypatch):
    """simulate(method="GeneralizedAlpha") steps in the compiled loop (projeq.simulation.loop.alpha_segment)
    as the OdeSolver steps through solve_ivp (``method=GeneralizedAlpha``, the class; both with J by forward
    differences): the same evaluations and q to 1e-14 relative over 1 s at h = 1e-3 (measured 1.8e-16 and
    1.2e-15). On the flexible arm round-off parts where their Newton iterations fail and form J again
    (2,717 against 2,707 evaluations at h = 4e-3): q 1.7e-5 to 1.3e-4 apart, the order of the method's own
    error there."""
    from projeq.simulation import loop

    calls, run = [], loop.CompiledLoop.run
    monkeypatch.setattr(loop.CompiledLoop, "run", lambda self, *args, **kwargs: (calls.append(1),
                                                                                 run(self, *args, **kwargs))[1])
    system = getattr(pq.scenes, scene)()
    compiled = pq.simulate(system, 1.0, method="GeneralizedAlpha", step=1e-3, n_points=11)
    assert calls
    solver = pq.simulate(system, 1.0, method=GeneralizedAlpha, step=1e-3, n_points=11, n_segments=1)
    assert compiled.nfev == solver.nfev
    assert np.abs(compiled.q - solver.q).max() <= 1e-14 * np.abs(solver.q).max()


@pytest.mark.parametrize("options, message", [
    ({}, "step: GeneralizedAlpha takes fixed steps"),
    ({"step": -1e-3}, "step: GeneralizedAlpha takes fixed steps"),
    ({"step": 1e-3, "rho_inf": 1.5}, "rho_inf: the spectral radius at infinity must lie in"),
    ({"step": 1e-3, "max_step": 1.0}, r"unknown option \['max_step'\] for method 'GeneralizedAlpha'"),
])
def test_bad_options_are_named(options, message):
    with pytest.raises(ValueError, match=message):
        pq.simulate(pq.scenes.double_pendulum(), 0.1, method="GeneralizedAlpha", **options)

"""integrators.fastest_mode: the spectral radius and whether the fastest mode decays without
oscillating (a real eigenvalue −ρ), on linear systems ẋ = J x whose eigenvalues are known
(Golub & Van Loan, "Matrix Computations", 4th ed. (2013), §7.3.1, the power method) and on
models with closed-form frequencies: a spring–mass chain fixed at one end (the eigenvalues
4 sin²((2j − 1)π / (2(2N + 1))) of its stiffness matrix k·tridiag(−1, 2, −1) with a last
diagonal entry 1: W.-C. Yueh, "Eigenvalues of several tridiagonal matrices", Applied
Mathematics E-Notes 5 (2005)), a pendulum's linearisation ±i√(g/L) and an overdamped
oscillator (−d ± √(d² − 4mk))/2m. Each of fastest_mode's ways (the one-call exact Jacobian, the
complex step column by column, power iteration on complex-step products, power iteration on
forward differences for a right-hand side that takes no complex state) against them."""

import re
import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.analysis.differentiation import is_complex_safe
from projeq.analysis.differentiation import jacobian as richardson_jacobian
from projeq.analysis.jacobians import state_derivative, state_jacobian
from projeq.simulation import driver
from projeq.simulation.driver import default_method
from projeq.simulation.integrators import fastest_mode, spectral_radius
from tests.simulation.test_extremes import axially_stiff_beam


@pytest.mark.parametrize("J, rho, decays", [
    (np.array([[0.0, 1.0], [-1e6, 0.0]]), 1e3, False),  # an undamped oscillator, ±1000i
    (np.array([[0.0, 1.0], [-1e6, -200.0]]), 1e3, False),  # lightly damped −100 ± 995i
    (np.array([[0.0, 1.0], [-1e6, -1e4]]), 9898.979485566356, True),  # overdamped: −9899, −101
    (np.diag([-5.0, -1.0, 0.5]), 5.0, True),
    (np.diag([5.0, -1.0]), 5.0, False),  # growing, not decaying
    (np.diag([-5.0, 5.0, 1.0]), 5.0, False),  # a tie: one of the fastest grows
])
def test_fastest_mode_tells_a_decaying_mode_from_an_oscillation(J, rho, decays):
    """Small n_x: the eigenvalues of the complex-step Jacobian, exact (to 1e-14); the same
    given the Jacobian; spectral_radius is its ρ."""
    found, real = fastest_mode(lambda t, x: J @ x, 0.0, np.zeros(len(J)))
    assert real is decays and found == pytest.approx(rho, rel=1e-14)
    assert fastest_mode(lambda t, x: J @ x, 0.0, np.zeros(len(J)), jacobian=lambda t, x: J) == (found, real)
    assert spectral_radius(lambda t, x: J @ x, 0.0, np.zeros(len(J))) == found


def _stiff_mode_in_a_slow_system(n_slow: int, fastest: np.ndarray) -> np.ndarray:
    """Block-diagonal J: a 2 × 2 fastest block and n_slow slow decaying modes (|λ| ≤ 2)."""
    J = np.zeros((n_slow + 2, n_slow + 2))
    J[:2, :2] = fastest
    J[2:, 2:] = np.diag(-np.linspace(0.5, 2.0, n_slow))
    return J


@pytest.mark.parametrize("fastest, rho, decays", [
    (np.array([[0.0, 1.0], [-1e6, 0.0]]), 1e3, False),
    (np.array([[0.0, 1.0], [-1e6, -1e4]]), 9898.979485566356, True),
])
def test_power_iteration_beyond_the_iterations_by_complex_step_and_by_differences(fastest, rho, decays):
    """n_x > iterations: power iteration, on complex-step products for a complex-safe f and on
    forward differences for one that refuses complex states; both find ρ and whether the fastest
    mode decays. ρ to 100 ε: the iteration converges to round-off here (the slow modes are ≤ 2/1000
    of the fastest; measured ≤ 4.4e-16 relative; the bound was 1e-3, the accuracy the step-size
    choice needs)."""
    J = _stiff_mode_in_a_slow_system(40, fastest)

    def real_only(t, x):
        if np.iscomplexobj(x):
            raise TypeError("real states only")
        return J @ x

    for f in (lambda t, x: J @ x, real_only):
        found, real = fastest_mode(f, 0.0, np.zeros(len(J)))
        assert found == pytest.approx(rho, rel=100 * np.finfo(float).eps, abs=0) and real is decays


def test_a_right_hand_side_that_drops_the_imaginary_part_is_differenced():
    """A right-hand side that returns real values for a complex state (as a compiled one for real
    states does, silently) has no complex step: forward differences find ρ, not 0 (to 100 ε: a linear f
    differenced at x = 0 is exact but for round-off; measured 4.4e-16 relative; was 1e-3)."""
    J = np.array([[0.0, 1.0], [-1e6, -1e4]])
    found, decays = fastest_mode(lambda t, x: J @ np.real(x), 0.0, np.zeros(2))
    assert found == pytest.approx(9898.979485566356, rel=100 * np.finfo(float).eps, abs=0) and decays


def test_a_right_hand_side_that_casts_a_complex_state_now_and_then_is_differenced():
    """A right-hand side that casts its state to float on some calls only (simulate's monitor of
    coordinate singularities, every 200 calls): the complex step gives way to differences, ρ to
    100 ε (measured 4.4e-16 relative; was 1e-3), without an error or a warning."""
    J, calls = np.array([[0.0, 1.0], [-1e6, -1e4]]), [0]

    def sometimes_real(t, x):
        calls[0] += 1
        if calls[0] % 3 == 0:
            np.asarray(x, dtype=float)  # a check on real states
        return J @ x

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        found, decays = fastest_mode(sometimes_real, 0.0, np.zeros(2))
    assert found == pytest.approx(9898.979485566356, rel=100 * np.finfo(float).eps, abs=0) and decays


def _spring_mass_chain(N: int, m: float, k: float, d: float = 0.0) -> pq.System:
    """N point masses m in a row on prismatic joints, each held to the previous one (the first
    to the ground) by a joint spring k (and damper d) on its relative coordinate."""
    names = [f"m{i}" for i in range(N)]
    joints = {n: pq.Prismatic(parent=None if i == 0 else names[i - 1], axis="x") for i, n in enumerate(names)}
    return pq.System(dict.fromkeys(names, pq.PointMass(m)), joints, gravity=(0.0, 0.0, 0.0),
                     forces=[pq.JointSpring(n, k, d) for n in names])


def _rhs(system, evaluator):
    n_q = system.n_q
    return lambda t, x: np.concatenate((system.q_dot(x[:n_q], x[n_q:], t),
                                        evaluator.accelerations(x[:n_q], x[n_q:], t)))


def test_the_spring_mass_chain_has_its_closed_form_fastest_frequency():
    """ρ = ω_N = 2 √(k/m) sin((2N − 1)π / (2(2N + 1))) (module docstring), an oscillation: to
    100 ε by the exact Jacobian's eigenvalues (N = 3, n_x = 6: the complex step column by
    column; measured 1.6e-16, was 1e-12); N = 20 (n_x = 40 > 32 iterations) by power iteration on
    complex-step products to 5 % (measured 3.1 %: ω_19 is 0.6 % below ω_20, and the power method converges as
    (ω_19/ω_20)^k)."""
    m, k = 2.0, 300.0
    for N, tolerance in ((3, 100 * np.finfo(float).eps), (20, 5e-2)):
        system = _spring_mass_chain(N, m, k)
        omega = 2 * np.sqrt(k / m) * np.sin((2 * N - 1) * np.pi / (2 * (2 * N + 1)))
        rho, decays = fastest_mode(_rhs(system, system.evaluator()), 0.0, np.zeros(2 * N))
        assert rho == pytest.approx(omega, rel=tolerance, abs=0) and not decays


def test_the_pendulum_linearisation_and_the_overdamped_oscillator():
    """A point mass at L below a revolute joint, at rest hanging: ρ = √(g/L), an oscillation;
    a mass on a prismatic joint with a stiff overdamped spring-damper: ρ = (d + √(d² − 4mk))/2m,
    decaying. Both by the compiled evaluator's Jacobian where it has one and by the complex step
    column by column (the same, and equal to the closed forms, to 100 ε: measured 0; was 1e-12)."""
    g, L = 9.81, 0.7
    pendulum = pq.System({"bob": pq.PointMass(1.3, r_c=(0.0, 0.0, -L))}, {"bob": pq.Revolute(axis="y")},
                         gravity=(0.0, 0.0, -g))
    m, k, d = 1.0, 1e6, 1e4
    damper = _spring_mass_chain(1, m, k, d)
    for system, rho, decaying in ((pendulum, np.sqrt(g / L), False),
                                  (damper, (d + np.sqrt(d * d - 4 * m * k)) / (2 * m), True)):
        evaluator, x = system.evaluator(), np.zeros(system.n_q + system.n_s)
        for jacobian in (getattr(evaluator, "state_jacobian", None), None):
            found, decays = fastest_mode(_rhs(system, evaluator), 0.0, x, jacobian=jacobian)
            assert found == pytest.approx(rho, rel=100 * np.finfo(float).eps, abs=0) and decays is decaying


def test_the_one_call_jacobian_gives_what_the_complex_step_columns_give():
    """chain(4) away from rest: default_method's way (the compiled one-call Jacobian's
    eigenvalues) = the eigenvalues of the complex step column by column, to 100 ε (measured 0; was 1e-13)."""
    system = pq.scenes.chain(4)
    evaluator = system.evaluator()
    x = np.r_[0.3, -0.5, 0.2, 0.9, 1.0, -0.4, 0.2, 0.1]
    assert evaluator.state_jacobian(0.0, x) is not None
    one_call = fastest_mode(_rhs(system, evaluator), 0.0, x, jacobian=evaluator.state_jacobian)
    columns = fastest_mode(_rhs(system, evaluator), 0.0, x)
    assert one_call[0] == pytest.approx(columns[0], rel=100 * np.finfo(float).eps, abs=0)
    assert one_call[1] == columns[1]


def test_default_method_picks_radau_for_the_overdamped_spring_and_dop853_for_the_chain():
    """The damper above (ρ = 9899 1/s, decaying) over 1 s forces 9899/3.31 ≈ 2990 > 500 RK45 steps:
    Radau; the undamped spring–mass chain (ρ = 23.5 1/s) over 1 s at rtol 1e-8: DOP853."""
    damper, chain = _spring_mass_chain(1, 1.0, 1e6, 1e4), _spring_mass_chain(5, 2.0, 300.0)
    for system, method in ((damper, "Radau"), (chain, "DOP853")):
        q0, s_dot0 = np.zeros(system.n_q), np.zeros(system.n_s)
        assert default_method(system.evaluator(), system, q0, s_dot0, 0.0, 1.0) == method


def test_simulates_stiffness_check_takes_real_states_and_agrees_with_the_exact_rho(monkeypatch):
    """simulate's stiffness check (stiff_steps) on the four-bar, a closed loop, and on README's
    double pendulum: its ρ comes from differences of the model's ẋ at real states (so an
    explicit run never compiles the complex128 specialization of its kernels, about half of the
    first compilation) and agrees with the largest |λ| of the exact (complex-step) Jacobian at
    the segment's end (measured at t = 0.5 s: 3.3e-10 relative on the four-bar, 3.5e-13 on the
    pendulum; bound 3e-9)."""
    seen, original = [], driver.stiff_steps

    def spy(fun, n_steps, t0, t, x, method, rtol):
        seen.append((system, fun, t, np.array(x)))
        return original(fun, n_steps, t0, t, x, method, rtol)

    monkeypatch.setattr(driver, "stiff_steps", spy)
    models = (pq.scenes.four_bar(), pq.scenes.chain(2))
    for system in models:
        pq.simulate(system, 1.0, method="RK45", rtol=1e-6, n_segments=2)
    assert {id(found[0]) for found in seen} == {id(system) for system in models}
    for system, fun, t, x in seen:
        evaluated = []
        rho = spectral_radius(lambda t, z: evaluated.append(z.dtype) or fun(t, z), t, x, derivatives="differences")
        assert evaluated and all(dtype.kind == "f" for dtype in evaluated)
        exact = np.abs(np.linalg.eigvals(state_jacobian(system, x, t)[0])).max()
        assert rho == pytest.approx(exact, rel=3e-9), abs(rho / exact - 1)


def spinning_beam_bent(tip: float) -> pq.System:
    """The spinning beam scene (at rest: q = 0 is its solution) bent by its first v function to
    ``tip`` m at the tip."""
    beam = pq.scenes.spinning_beam()
    q0 = np.zeros(beam.n_q)
    q0[0] = tip
    return pq.System(dict(zip(beam.names, beam.subsystems)), dict(zip(beam.names, beam.joints)), q0=q0)


def test_a_run_at_rest_takes_the_steps_nothing_limits():
    """The spinning beam scene (EI = ρA = L = 1, Ω = 2 rad/s, four clamped–free functions per
    plane): ρ at rest is its fourth bending frequency β₄² √(EI/(ρA L⁴)) raised by the spin Ω
    in the co-rotating frame (the eigenvalues ±i(ω_k ± Ω) of a round beam spinning about its
    axis; β₄L = 10.99554 of cos βL cosh βL = −1), so DOP853 needs ρT/6.39 = 192 < 100,000 steps
    for stability over the 10 s and default_method keeps DOP853 (bent by 1 cm it is 4× faster
    than Radau: benchmarks/default_integrator.py). At exact rest ẋ = 0 in every stage: there is
    nothing for a step beyond the stability limit to amplify, and DOP853's steps grow from
    segment to segment (each segment goes on with the step size the last one reached) — no
    StiffnessWarning, the state exactly 0, 396 evaluations (33 steps). A restart's own guess
    from ẋ = 0 made the steps look as if they crawled at the limit ("ρh = 8.8 by t = 4 s"), and
    the default run switched to Radau for nothing. Bent by 1 cm (over 2 s), DOP853 to the end."""
    rest, bent = pq.scenes.spinning_beam(), spinning_beam_bent(0.01)
    x0 = np.zeros(rest.n_q + rest.n_s)
    rho, decays = fastest_mode(None, 0.0, x0, jacobian=rest.evaluator().state_jacobian)
    # measured 3.5e-13 relative (was 1e-9)
    assert rho == pytest.approx(10.995540734875467**2 + 2.0, rel=4e-12, abs=0) and not decays
    assert default_method(rest.evaluator(), rest, rest.q0, rest.s_dot0, 0.0, 10.0) == "DOP853"
    with warnings.catch_warnings():
        warnings.simplefilter("error", pq.StiffnessWarning)
        forced = pq.simulate(rest, 10.0, method="DOP853", n_points=2)
        chosen = pq.simulate(rest, 10.0, n_points=2)
        assert pq.simulate(bent, 2.0, n_points=2).method == "DOP853"
    for run in (forced, chosen):
        assert run.method == "DOP853" and run.nfev <= 500
        np.testing.assert_array_equal(run.q[-1], 0.0)


def test_the_default_run_goes_on_from_where_its_explicit_steps_crawled():
    """The axially stiff beam of test_extremes (ρ = 1.7e3 1/s) over 0.5 s (within the beam's
    moderate deflections): the default run's DOP853 steps crawl and Radau takes over where the
    segment that shows it ends (the end of DOP853's step past t = 0.1 s), without a StiffnessWarning; its
    final state is a run of Radau throughout's within 50 (rtol |x| + atol), the bound
    test_extremes holds two methods' runs to (both keep their local errors at rtol)."""
    system = axially_stiff_beam()
    with warnings.catch_warnings():
        warnings.simplefilter("error", pq.StiffnessWarning)
        chosen = pq.simulate(system, 0.5, n_points=2)
        implicit = pq.simulate(system, 0.5, method="Radau", n_points=2)
    assert re.fullmatch(r"DOP853, Radau from t = 0\.100\d* s", chosen.method), chosen.method
    for mine, theirs in ((chosen.q[-1], implicit.q[-1]), (chosen.s_dot[-1], implicit.s_dot[-1])):
        assert np.all(np.abs(mine - theirs) < 50 * (1e-8 * np.abs(theirs) + 1e-10))


def test_simulates_own_explicit_choice_starts_at_a_stable_step_where_fast_modes_chose_it():
    """Where simulate chose DOP853 for fast modes (more than FAST_MODE_STEPS RK45 steps for stability
    alone), its first step is half DOP853's stability limit over ρ; scipy's guess reads ẋ, not the modes
    (a UR5 with a flexible last link, ρ ≈ 2e3 1/s: the guess was accepted beyond the stable step and the
    beam's modes grew until D_n was indefinite at 5.6 ms, benchmarks/urdf_pinocchio.py). Rigid models
    and implicit methods keep scipy's guess."""
    from projeq.simulation.integrators import stability_limit

    step = driver.stable_first_step("DOP853", (2e3, False), 0.0, 1.0)
    assert step == pytest.approx(0.5 * stability_limit("DOP853") / 2e3, rel=1e-15, abs=0)  # measured 0
    assert driver.stable_first_step("DOP853", (10.0, False), 0.0, 1.0) is None  # 3 RK45 steps: accuracy rules
    assert driver.stable_first_step("Radau", (2e3, False), 0.0, 1.0) is None


def test_the_stiff_two_mass_oscillator_answers_with_the_default_method():
    """Stiffness ratio 1e10, the fast mode (ω ≈ 1.4e5 rad/s) unexcited (benchmarks/default_integrator.py's two_masses), rtol 1e-8 over 10 s (issue 34:
    no answer after 51 s of CPU): simulate's default is Radau (the ρ of its fastest mode would
    take DOP853 ~1e6 steps for stability alone) and answers in 1548 evaluations (bound 2000; 0.13 s
    warm); q follows the modal solution q(t) = Σ φᵢ φᵢᵀ M q₀ cos ωᵢt of M q̈ + K q = 0 (M = [[2, 1],
    [1, 1]] in these relative coordinates, K = diag(1, 1e10), φᵢ M-normalised by scipy.linalg.eigh)
    within 1e-9 (measured 2.5e-10, at rtol 1e-8 · 0.1 m = 1e-9 per step)."""
    import scipy.linalg

    from tests.studies.test_benchmarks_quick import load

    system = load("default_integrator.py").two_masses(1e10)
    run = pq.simulate(system, 10.0, rtol=1e-8)
    M, K = np.array([[2.0, 1.0], [1.0, 1.0]]), np.diag([1.0, 1e10])
    omega2, phi = scipy.linalg.eigh(K, M)
    exact = np.cos(np.outer(run.t, np.sqrt(omega2))) * (phi.T @ M @ system.q0) @ phi.T
    assert run.method == "Radau" and run.nfev <= 2000
    assert np.abs(run.q - exact).max() < 1e-9


def test_a_5000_body_chain_runs_with_the_default_method():
    """chain(5000) (n_x = 10,000) over 10 ms with simulate's defaults (issue 37: a test of the default
    method at a large n_x): the stiffness check estimates ρ from products of the model's ẋ, never a
    dense ∂ẋ/∂x (no Jacobian formed: njev = 0), finds the chain not stiff over the run and steps it with
    DOP853; energy is conserved to round-off (a conservation law: measured 2.8e-16, bound 100 ε)."""
    system = pq.scenes.chain(5000)
    run = pq.simulate(system, 0.01)
    assert (run.status, run.method, run.njev) == (0, "DOP853", 0)
    assert run.energy_drift < 100 * np.finfo(float).eps, run.energy_drift

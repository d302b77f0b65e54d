"""Stability at the extremes (issue 7, item 4): fast proxies of benchmarks/extremes.py.

Each test's docstring states what "passes" means and the independent reference it is
checked against. The long runs (1e5 pendulum periods, 1e4 disk revolutions, the
1000-body chain for 1 s, the spin-up at four speeds) are in benchmarks/extremes.py.
"The fast evaluator" below is method="auto": the compiled kernel when numba is installed,
else the recursive evaluator.
"""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq import inertia
from projeq.simulation.integrators import StiffnessWarning, spectral_radius

EPS = np.finfo(float).eps
BETA_1 = 1.8750410  # first root of cos β cosh β = −1 (clamped-free Euler–Bernoulli beam)


def first_bending_frequency(EI, rho_A, length):
    """ω₁ = β₁² √(EI/(ρA L⁴)), the clamped-free Euler–Bernoulli beam (Blevins, Formulas for
    Natural Frequency and Mode Shape, ch. 8: clamped-free, λ₁ = β₁ = 1.87510)."""
    return BETA_1**2 * np.sqrt(EI / (rho_A * length**4))


# --- 1. spin-up: stiffened bounded, unstiffened divergence detected ---------------------------

def tip_deflection(result):
    beam = result.system.subsystem("beam")
    return beam.deflection(result, beam.length)[:, 1]  # v: in the plane of rotation


def test_unstiffened_spin_up_diverges_at_the_predicted_rate():
    """Passes if the unstiffened beam spun above its first bending frequency is reported as
    diverging (a RuntimeWarning of the beam, the run itself finishing without a crash) and
    the in-plane tip deflection grows like exp(σt) with σ = √(Ωs² − ω₁²): in the hub frame
    turning at the constant rate Ωs the unstiffened in-plane equation is
    ρA v̈ + EI v'''' − ρA Ωs² v = 0 (centrifugal softening, no stiffening term), whose first
    mode grows at that rate. Ωs = 10 rad/s, ω₁ = 3.80 rad/s (Blevins), spun up in 1 s."""
    omega_s = 10.0
    system = pq.scenes.spin_up_beam(omega_s=omega_s, t_s=1.0, n_shapes=2, stiffening=False)
    with pytest.warns(RuntimeWarning, match="unstiffened model is unstable"):
        result = pq.simulate(system, 4.0, method="DOP853", rtol=1e-8, atol=1e-10, n_points=201)
    late = result.t >= 2.0  # 10 e-foldings after the spin-up: the first mode dominates
    sigma = np.polyfit(result.t[late], np.log(np.abs(tip_deflection(result)[late])), 1)[0]
    omega_1 = first_bending_frequency(1.4e4, 1.2, 10.0)
    sigma_ref = np.sqrt(omega_s**2 - omega_1**2)
    # Two polynomial Ritz functions overestimate ω₁ by < 0.5 % (Rayleigh–Ritz upper bound);
    # through σ = √(Ωs² − ω₁²) that is (ω₁/σ)² · 0.5 % < 1e-3 relative in σ.
    assert sigma == pytest.approx(sigma_ref, rel=1e-3)


def test_stiffened_spin_up_stays_bounded():
    """Passes if the stiffened beam spun up to Ωs = 10 rad/s (2.6 × ω₁) in 5 s stays
    bounded: after the spin-up, in steady rotation, the in-plane tip vibration is smaller
    than the peak deflection of the spin-up and does not grow (its last second is below its
    first second after the spin-up). Reference: with the centrifugal stiffening the
    in-plane first mode has ω² = ω₁² + (k − 1) Ωs² > 0 with Southwell's coefficient
    k ≈ 1.19 of the uniform cantilever's first mode (Hodges & Rutkowski, AIAA J. 19, 1981),
    so it oscillates rather than grows; without stiffening (previous test) it grows."""
    system = pq.scenes.spin_up_beam(omega_s=10.0, t_s=5.0, n_shapes=2)
    result = pq.simulate(system, 8.0, method="RK45", rtol=1e-6, atol=1e-8, n_points=81)
    v = np.abs(tip_deflection(result))
    after = result.t > 5.0
    first, last = v[after & (result.t <= 6.0)].max(), v[result.t > 7.0].max()
    assert np.all(np.isfinite(v))
    assert v[after].max() < v[~after].max()
    assert last < first


# --- 2. a stiffness ratio of 1e6 between beam modes ---------------------------------------------

# (ω_axial/ω₁)² = 1e6 for the continuum: ω_axial = (π/2)√(EA/ρA)/L and ω₁ of Blevins give
# EA = 1e6 (β₁⁴/(π/2)²) EI/L² = 5.01e6 N for EI = 1 N m², L = 1 m
EA_STIFF = 1e6 * BETA_1**4 / (np.pi / 2) ** 2


def axially_stiff_beam():
    """A 1 m cantilever (EI = 1 N m², ρA = 1 kg/m, EA = EA_STIFF) with one bending and one
    axial Ritz function, spun up gently to 1 rad/s."""
    return pq.scenes.spin_up_beam(omega_s=1.0, t_s=1.0, length=1.0, EI=1.0, rho_A=1.0, EA=EA_STIFF,
                                  n_shapes=1, n_axial=1)


def test_stiff_beam_warns_explicit_methods_and_implicit_ones_agree():
    """Passes if, on a beam whose axial mode is 10³ times faster than its bending mode (a
    stiffness ratio of 1e6), RK45 gets a StiffnessWarning suggesting Radau or BDF, and Radau
    and BDF finish without one and agree with RK45's (accurate but slow) solution.
    Reference: the spectral radius of the linearised model must be ω_axial (the fastest
    mode) within the power iteration's accuracy, and the explicit method's steps sit at
    its stability limit ρh ≈ 3 (Hairer & Wanner, Solving ODEs II, §IV.2)."""
    system = axially_stiff_beam()
    rtol, atol = 1e-8, 1e-10
    with pytest.warns(StiffnessWarning, match="try method='Radau' or 'BDF'"):
        explicit = pq.simulate(system, 0.1, method="RK45", rtol=rtol, atol=atol, n_segments=1, n_points=3)
    x0 = np.concatenate((system.q0, system.s_dot0))
    rho = spectral_radius(lambda t, x: np.concatenate((system.q_dot(x[:3], x[3:], t),
                                                       system.accelerations(x[:3], x[3:], t))), 0.0, x0)
    # The one axial Ritz function u = x/L gives ω_axial² = 3 EA/(ρA L²) (its Rayleigh
    # quotient; √3 instead of the continuum's π/2). Power iteration on the exact Jacobian converges
    # like (ω₁/ω_axial)^k = 1e-3^k: round-off is left (measured 7e-16 relative; was 1e-6, from when
    # the Jacobian came by finite differences)
    assert rho == pytest.approx(np.sqrt(3 * EA_STIFF), rel=100 * EPS, abs=0)  # ρA = 1 kg/m, L = 1 m
    for method in ("Radau", "BDF"):
        with warnings.catch_warnings():
            warnings.simplefilter("error", StiffnessWarning)
            implicit = pq.simulate(system, 0.1, method=method, rtol=rtol, atol=atol, n_segments=1, n_points=3)
        # both runs keep local errors at rtol of the state; the global errors of a
        # 0.1 s run of a stable system stay within a small multiple: 50 (rtol |x| + atol)
        scale = rtol * np.abs(explicit.q[-1]) + atol
        assert np.all(np.abs(implicit.q[-1] - explicit.q[-1]) < 50 * scale), method


# --- 3. long runs: drift of RK45 vs the projected method ---------------------------------------

def pendulum():
    return pq.System({"bob": pq.PointMass(1.0, (0.0, 0.0, -1.0))}, {"bob": pq.Revolute(axis="y")},
                     gravity=(0.0, 0.0, -9.81))


def test_projected_method_keeps_the_pendulum_energy_at_round_off():
    """Passes if, over 10 periods of a conservative pendulum (amplitude 1 rad), RK45's
    energy error is measured to grow (its last quarter larger than its first) while
    RK45-projected's stays at round-off, 1e3 times smaller than RK45's at the end.
    Reference: energy conservation (the system is conservative and scleronomic), and
    RK45's step error accumulating with the number of steps."""
    rtol, atol = 1e-6, 1e-8
    period = 2 * np.pi * np.sqrt(1.0 / 9.81) * 1.07  # at 1 rad amplitude (K(sin² 0.5) / (π/2))
    errors = {}
    with warnings.catch_warnings():
        warnings.simplefilter("error", StiffnessWarning)  # a non-stiff system: no warning
        for method in ("RK45", "RK45-projected"):
            result = pq.simulate(pendulum(), 10 * period, q0=[1.0], s_dot0=[0.0], method=method,
                                 rtol=rtol, atol=atol, n_points=201, evaluator="auto")
            errors[method] = np.abs(result.energy - result.energy[0]) / (9.81 * 1.0)  # / (m g l)
    quarter = 50
    assert errors["RK45"][-quarter:].max() > 2 * errors["RK45"][:quarter].max()
    # round-off: the projection stops at 4 ε (|T| + |V|) ≤ 8 ε m g l; evaluating E adds a
    # few ε m g l
    assert errors["RK45-projected"].max() < 20 * EPS
    assert errors["RK45-projected"][-1] * 1e3 < errors["RK45"][-1]


def _sliding_pendulum():
    """A unit mass on x and z sliders kept on the unit circle: a pendulum, Φ = √(x² + z²) − 1."""
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")}, gravity=(0, 0, -9.81))
    return pq.ConstrainedSystem(tree, phi=lambda q, t: [np.sqrt(q[0] ** 2 + q[1] ** 2) - 1.0], q0=[0.6, -0.8],
                                independent=[0])


@pytest.mark.parametrize("model", ["tree", "constrained"])
def test_the_energy_projection_takes_the_exact_gradient(model):
    """Passes if the projected integrators' ∇E (``energy_gradient``: the complex step through
    the energy with q normalised) matches its closed form: the pendulum of length 1 about y,
    E = ½ θ̇² − g cos θ, ∇E = (g sin θ, θ̇), to 1e-14 relative (measured 2e-16; the forward
    differences it replaces: 5e-7); the pendulum on sliders at a point off its circle, which
    q's normalisation (a Gauss–Newton step onto Φ = 0) moves radially to q̂ = q/|q|, where ẋ
    gives ż = −x ẋ/z and E = ½ ẋ² |q|²/z² + g z/|q| (its gradient by sympy), to 1e-12
    (measured 2.9e-13, the floor of Φ_q's inner stencil under the complex step; forward
    differences: 1.7e-6)."""
    import sympy as sp

    from projeq.simulation.integrators import energy_gradient

    if model == "tree":
        theta, rate = 1.1, -0.4
        gradient, expected = energy_gradient(pendulum(), np.array([theta, rate]), 0.2), [9.81 * np.sin(theta), rate]
    else:
        x, z, u = sp.symbols("x z u")
        r = sp.sqrt(x**2 + z**2)
        energy = u**2 * r**2 / (2 * z**2) + sp.Float(9.81) * z / r
        point = {x: 0.62, z: -0.81, u: 0.7}  # |q| = 1.02: off the circle
        expected = [float(energy.diff(v).subs(point)) for v in (x, z, u)]
        gradient = energy_gradient(_sliding_pendulum(), np.array([0.62, -0.81, 0.7]), 0.2)
    assert np.abs(gradient - expected).max() < {"tree": 1e-14, "constrained": 1e-12}[model] * np.abs(expected).max()


def test_projected_method_on_the_rolling_disk():
    """Passes if, over two revolutions of Barhorst's rolling disk (Barhorst §3.2), the
    rolling constraints hold to round-off for both methods (minimal velocities: q̇ = K ṡ
    satisfies them identically), and the projected method keeps the energy (conserved:
    ideal rolling constraints, gravity only) at round-off where RK45's drifts."""
    system = pq.scenes.rolling_disk()
    t_end = 2 * 2 * np.pi / system.s_dot0[1]  # two revolutions at the initial spin u2
    drift = {}
    for method in ("RK45", "RK45-projected"):
        result = pq.simulate(system, t_end, method=method, rtol=1e-5, atol=1e-8, n_points=21)
        speed = system.s_dot0[1] * 0.015  # R u2
        assert np.abs(result.constraint_residual).max() < 10 * EPS * speed, method
        drift[method] = result.energy_drift
    assert drift["RK45-projected"] < 100 * EPS  # energy_drift is relative to max(T, V)
    assert drift["RK45"] > 1e3 * drift["RK45-projected"]


def test_projection_refuses_a_driven_system():
    """The spin-up beam's hub is driven (a prescribed motion does work): its energy is no
    invariant, so the projected methods refuse it by name."""
    system = pq.scenes.spin_up_beam(n_shapes=1, t_s=1.0)
    with pytest.raises(ValueError, match="^method: the projected integrators"):
        pq.simulate(system, 0.6, t_start=0.5, method="DOP853-projected")


@pytest.mark.parametrize("build", [
    lambda: pq.scenes.spin_up_beam(n_shapes=1),  # from rest at t = 0: no drive power yet
    lambda: pq.System({"bob": pq.PointMass(1.0, (0, 0, -1))}, {"bob": pq.Revolute(axis="y")},
                      forces=[pq.JointSpring("bob", stiffness=1.0, damping=0.5)], q0=[0.3]),  # at rest: no damping yet
], ids=["prescribed hub from rest", "damper at rest"])
def test_projection_refuses_systems_that_only_start_conservative(build):
    """dE/dt = 0 at the initial state alone does not make the energy an invariant: the
    spin-up hub does no work at t = 0 (θ̇ = θ̈ = 0) and a damper none at rest; projecting
    onto E = E₀ would be a silent wrong answer (tip 1.50 m instead of 0.34 m at 4 s)."""
    with pytest.raises(ValueError, match="^method: the projected integrators"):
        pq.simulate(build(), 0.1, method="RK45-projected")


# --- 4. near-singular poses -----------------------------------------------------------------------

def test_knife_edge_disc_near_flat_is_accurate_then_refused_at_flat():
    """Passes if the knife-edge disc 1e-3 rad short of flat (slides 29–31: F loses rank at
    ϕ = π/2) still has dense = recursive accelerations to κ(M) ε, with the tilt
    acceleration of the lecture's equation (slide 37 at ψ̇ = θ̇ = ϕ̇ = 0:
    (I + m r²) ϕ̈ = m g r sin ϕ), and the flat pose itself is refused with a message naming
    the rank loss (tests/nonholonomic/test_bad_input.py checks the message's text)."""
    tilt = np.pi / 2 - 1e-3
    system = pq.scenes.knife_edge_disc(q0=(0.0, 0.0, 0.0, tilt, 0.0), s_dot0=(0.0, 0.0, 0.0))
    kappa = np.linalg.cond(system.mass_matrix(system.q0))
    dense = system.accelerations(system.q0, system.s_dot0, method="dense")
    recursive = system.accelerations(system.q0, system.s_dot0, method="recursive")
    phi_ddot = np.sin(tilt) / (0.25 + 1.0)  # m = g = r = 1, I = 1/4
    assert np.abs(dense - recursive).max() <= 10 * kappa * EPS * phi_ddot
    assert recursive[1] == pytest.approx(phi_ddot, rel=10 * kappa * EPS)
    with pytest.raises(ValueError, match="loses rank"):
        pq.scenes.knife_edge_disc(q0=(0.0, 0.0, 0.0, np.pi / 2, 0.0))


def test_chain_stretched_straight_is_not_singular():
    """Passes if a 20-link chain stretched straight (hanging, and horizontal) has a
    regular mass matrix (minimal coordinates of a tree have no singular pose: κ(M) ε
    ≤ 1e-6; κ grows like n⁴ as for any chain and is largest straight, 6.7e5 here) and
    dense = recursive = fast to 10 κ(M) ε relative (the perturbation bound of a linear
    solve). Reference for the hanging pose: s̈ = 0 at any joint rates, since gravity and
    every centripetal acceleration of a collinear chain point along it (an equilibrium
    whose velocity terms produce tension only)."""
    n = 20
    s_dot = np.linspace(-1.0, 1.0, n)
    for first in (0.0, np.pi / 2):
        system = pq.scenes.chain(n, q0=np.r_[first, np.zeros(n - 1)])
        kappa = np.linalg.cond(system.mass_matrix(system.q0))
        assert kappa * EPS < 1e-6
        results = [system.accelerations(system.q0, s_dot, method=m) for m in ("dense", "recursive", "auto")]
        # hanging: s̈ = 0 up to round-off of the centripetal terms, n² |ṡ|² ~ 400 m/s²
        scale = np.abs(results[0]).max() if first else 400.0
        for other in results[1:]:
            assert np.abs(other - results[0]).max() <= 10 * kappa * EPS * scale
        if first == 0.0:
            assert np.abs(results[1]).max() <= 10 * EPS * scale


# --- 5. mass ratios 1e6 and 1e-6 in one chain -------------------------------------------------

def mass_ratio_chain(masses):
    """A chain as scenes.chain, with link masses (and inertias) scaled per link."""
    names = [f"link{i + 1}" for i in range(len(masses))]
    bodies = {name: pq.RigidBody(m, (0.0, 0.0, -0.5), inertia.cylinder(m=m, radius=0.01, length=1.0, axis="z"))
              for name, m in zip(names, masses)}
    joints = {name: pq.Revolute(parent=None if i == 0 else names[i - 1], axis="y",
                                r_pn=(0.0, 0.0, 0.0 if i == 0 else -1.0)) for i, name in enumerate(names)}
    return pq.System(bodies, joints, gravity=(0.0, 0.0, -9.81), q0=[0.5, -0.3, 0.2])


@pytest.mark.parametrize("masses", [(1e6, 1.0, 1e-6), (1e-6, 1.0, 1e6)], ids=["heavy-top", "heavy-tip"])
def test_mass_ratios_evaluators_agree(masses):
    """Passes if dense = recursive = fast for link masses in ratios 1e6 and 1e-6 to
    10 κ(M) ε relative (the perturbation bound of the linear solve M s̈ = −b, the
    dense evaluator's and the reference: the recursive and fast ones are order-n
    eliminations of the same equations, docs/theory.md §6), at three states."""
    system = mass_ratio_chain(masses)
    for seed in range(3):
        rng = np.random.default_rng(seed)
        q, s_dot = rng.uniform(-1.5, 1.5, 3), rng.uniform(-2.0, 2.0, 3)
        kappa = np.linalg.cond(system.mass_matrix(q))
        dense = system.accelerations(q, s_dot, method="dense")
        for method in ("recursive", "auto"):
            other = system.accelerations(q, s_dot, method=method)
            assert np.abs(other - dense).max() <= 10 * kappa * EPS * np.abs(dense).max(), method


def test_mass_ratios_energy_conserved():
    """Passes if the chain with link masses 1e6, 1, 1e-6 kg (heavy on top: no fast mode)
    conserves its energy over 2 s: the drift stays below n_steps · rtol (each accepted
    step commits a local error ≤ rtol of the state; a conservative system keeps their
    sum as the bound of its energy error, 8.6e-8 here). Measured 4.9e-12 (1.3e-12 and 2.4e-12 over 1 and
    3 s, 5.0e-12 with masses 1e5, 1, 1e-5): the bound is 10 times the largest."""
    system = mass_ratio_chain((1e6, 1.0, 1e-6))
    rtol = 1e-9
    result = pq.simulate(system, 2.0, method="DOP853", rtol=rtol, atol=1e-12, n_points=51)
    n_steps = result.nfev / 12  # DOP853: 12 evaluations per step
    assert result.energy_drift < min(n_steps * rtol, 5e-11), result.energy_drift


# --- 6. a 1000-body chain ---------------------------------------------------------------------------

def test_thousand_body_chain_short_run():
    """Passes if the 1000-link chain runs (fast evaluator) for 5 ms (the benchmark runs 1 s)
    with its energy conserved to round-off (100 ε: measured 2.2e-16; n_steps · rtol = 9.3e-8 before) and
    the fast evaluator equal to the recursive one at the initial state to 2.3e-14 relative (measured 2.3e-15;
    was 1e-9)."""
    system = pq.scenes.chain(1000)
    fast = system.accelerations(system.q0, system.s_dot0, method="auto")
    recursive = system.accelerations(system.q0, system.s_dot0, method="recursive")
    assert np.abs(fast - recursive).max() <= 2.3e-14 * np.abs(recursive).max()
    rtol = 1e-8
    result = pq.simulate(system, 5e-3, method="RK45", rtol=rtol, atol=1e-10, evaluator="auto", n_points=3,
                         n_segments=1)
    assert result.energy_drift < 100 * EPS, result.energy_drift


def test_stability_limits_are_the_roots_of_the_stability_polynomials():
    """Passes if the stability intervals computed from scipy's Butcher tableaus equal the
    closed forms: every 3-stage order-3 method (RK23, Bogacki–Shampine) has
    R(x) = 1 + x + x²/2 + x³/6, which reaches −1 at x = −2.5127; Dormand–Prince 5(4) (RK45)
    has R(x) = Σ_{k≤5} x^k/k! + x⁶/600, which reaches +1 at x = −3.3066 (Hairer, Nørsett &
    Wanner, Solving ODEs I, §II.5; Hairer & Wanner II, §IV.2). DOP853's is only bracketed:
    its interval is larger than RK45's (order 8, 12 stages)."""
    from math import factorial

    from projeq.simulation.integrators import stability_limit

    def real_root(coefficients, value):
        shifted = np.array(coefficients, dtype=float)
        shifted[0] -= value
        roots = np.roots(shifted[::-1])
        return -max(-r.real for r in roots if abs(r.imag) < 1e-9 and r.real < -1e-9)

    taylor = [1 / factorial(k) for k in range(6)]
    # both to round-off: measured 1.1e-15 and 1.3e-16 relative (were 1e-9)
    assert stability_limit("RK23") == pytest.approx(-real_root(taylor[:4], -1.0), rel=100 * EPS, abs=0)
    assert stability_limit("RK45") == pytest.approx(-real_root(taylor + [1 / 600], 1.0), rel=100 * EPS, abs=0)
    assert stability_limit("RK45-projected") == stability_limit("RK45")
    assert 2 * stability_limit("RK45") > stability_limit("DOP853") > stability_limit("RK45")

"""Closed loops given as constraint equations (issue 4, items 1–2; docs/theory.md §7)."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import projeq as pq
from projeq.constraints.partitioned import POSITION_TOLERANCE, ConstrainedSystem
from projeq.constraints.reactions import reactions
from projeq.scenes.mechanisms import four_bar, four_bar_angles, quick_return, slider_pendulum

RTOL, ATOL = 1e-9, 1e-11


def test_quick_return_conserves_energy_and_closes_its_loop():
    """Barhorst's quick-return mechanism (Barhorst §3.3: A = 1, H = A/3, B = A + 1.5 H,
    m_a = 1/2, m_b = 1, g = 9.81, T_m = T_d = 0, q1(0) = 9π/20, 10 s as in his Fig. 10):
    with zero drive the energy T + V of (110)–(111) is conserved, and the loop residuals
    c1, c2 of (107), reported in ``Result.constraint_residual``, stay at round-off level
    under the Gauss–Newton projection (the drift between projections is in
    benchmarks/loop_drift.py). 2 s (about one crank turn) keeps the test short."""
    system = quick_return()
    r = pq.simulate(system, 2.0, rtol=RTOL, atol=ATOL, n_points=101)
    assert r.success and r.constraint_residual.shape == (101, 2)
    # energy: local errors of size rtol accumulate over ~100 steps
    assert r.energy_drift < 100 * RTOL
    # residuals: the projection stops at POSITION_TOLERANCE · max(1, |q|) (q1 grows as the crank turns)
    bound = POSITION_TOLERANCE * np.maximum(1.0, np.abs(r.q).max(axis=1))
    assert np.all(np.abs(r.constraint_residual).max(axis=1) <= bound)
    assert np.ptp(r.q[:, 0]) > 1.0  # the crank really moves


def _four_bar_reference(a, b, c, d, m, g):
    """The four-bar in one minimal coordinate θ1 with the loop solved in closed form:
    Lagrange's equation m(θ) θ̈ + ½ m'(θ) θ̇² + V'(θ) = 0 for T = ½ m(θ) θ̇²,
    m(θ) = Σ m_i |G_i'(θ)|² + I_i θ_i'(θ)² of uniform rods (centroidal I_i = m_i L_i²/12)."""
    h = 1e-3

    def d1(f, x):  # five-point stencil, error ~h⁴ ≈ 1e-12
        return (-f(x + 2 * h) + 8 * f(x + h) - 8 * f(x - h) + f(x - 2 * h)) / (12 * h)

    def pose(t1):
        t2, t3 = four_bar_angles(t1, a, b, c, d)
        e = lambda t: np.array([np.cos(t), np.sin(t)])
        G = [a / 2 * e(t1), a * e(t1) + b / 2 * e(t2), np.array([d, 0.0]) + c / 2 * e(t3)]
        return np.concatenate(G + [[t1, t2, t3]])

    lengths = np.array([a, b, c])

    def mass(t1):
        dp = d1(pose, t1)
        return sum(m[i] * dp[2 * i: 2 * i + 2] @ dp[2 * i: 2 * i + 2] for i in range(3)) + \
            np.sum(np.array(m) * lengths**2 / 12 * dp[6:] ** 2)

    def V(t1):
        p = pose(t1)
        return g * sum(m[i] * p[2 * i + 1] for i in range(3))

    def rhs(t, x):
        return [x[1], -(0.5 * d1(mass, x[0]) * x[1] ** 2 + d1(V, x[0])) / mass(x[0])]

    return rhs


def test_four_bar_agrees_with_the_explicitly_solved_loop():
    """Four-bar with the loop as Φ = 0 versus the same mechanism in the minimal coordinate θ1
    with its loop solved in closed form (``four_bar_angles``) and Lagrange's equation
    (an independent formulation: no partitioning, no Projection Equation)."""
    params = dict(a=0.3, b=1.0, c=0.8, d=1.0, m=(1.0, 2.0, 1.5), g=9.81)
    system = four_bar(**params, theta1=0.5, omega1=3.0)
    t = np.linspace(0, 1.0, 21)
    r = pq.simulate(system, 1.0, t_eval=t, rtol=RTOL, atol=ATOL)
    ref = solve_ivp(_four_bar_reference(**params), (0, 1.0), [0.5, 3.0], t_eval=t, rtol=RTOL, atol=ATOL)
    err = np.abs(r.q[:, 0] - ref.y[0])
    # both integrated to rtol 1e-9: 10 rtol·|θ1| (achieved 7e-10 rad)
    assert err.max() < 10 * RTOL * np.abs(ref.y[0]).max(), err.max()
    theta2 = np.array([four_bar_angles(x, 0.3, 1.0, 0.8, 1.0)[0] for x in r.q[:, 0]])
    # the dependent coordinates on the closed loop (measured 2.7e-12: the projection's tolerance)
    assert np.abs(r.q[:, 0] + r.q[:, 2] - theta2).max() < 3e-11


def test_pendulum_rod_tension_from_the_multiplier():
    """The rod tension of a pendulum whose rod is the constraint √(x² + z²) = l equals the
    closed form m (g cos θ + l θ̇²) (radial Newton's law; e.g. the Lagrange seminars, Seminar 5, Lagrange
    multipliers); the multiplier is minus the tension."""
    l, m, g = 1.2, 0.7, 9.81
    system = slider_pendulum(l=l, m=m, g=g, theta0=1.0)
    r = pq.simulate(system, 1.5, rtol=RTOL, atol=ATOL, n_points=31)
    lam = reactions(system, r)[:, 0]
    x, z = r.q[:, 0], r.q[:, 1]
    v2 = np.array([np.sum(system.tree_velocities(q, s) ** 2) for q, s in zip(r.q, r.s_dot)])
    tension = m * (g * (-z / l) + v2 / l)
    # λ is an algebraic function of the state: measured 6.2e-12 (9.0e-13 m g), at most 6.3e-12 over
    # rtol 1e-8 … 1e-10, 3 s and θ0 = 0.5 — independent of rtol; bound 10× (was 1e-8 m g)
    error = np.abs(lam + tension).max()
    assert error < 1e-11 * m * g, error


def test_pendulum_rod_tension_from_the_joint_reaction():
    """The same tension from the tree's joint reaction (a point mass on a revolute joint,
    rod along −z of the rod frame): the force the pivot exerts along the rod, W_z in the
    rod's axes, equals m (g cos θ + l θ̇²); the moment about the joint axis, F_nᵀ W_n, is
    zero (a free joint carries no torque about its axis)."""
    from projeq.constraints.reactions import joint_reactions

    l, m, g = 1.2, 0.7, 9.81
    tree = pq.System({"bob": pq.PointMass(m, r_c=(0, 0, -l))}, {"bob": pq.Revolute(axis="y")},
                     gravity=(0, 0, -g))
    for theta, omega in ((0.0, 0.0), (1.0, 2.0), (2.5, -3.0)):
        W = joint_reactions(tree, [theta], [omega])["bob"]
        # algebraic: round-off only, 100 ε of the scale (measured ≤ 4.4e-16 N and 1.8e-15 N m; was 1e-12)
        exact = 100 * np.finfo(float).eps
        assert abs(W[2] - m * (g * np.cos(theta) + l * omega**2)) < exact * m * (g + l * omega**2)
        assert abs(W[4]) < exact * m * g * l


@pytest.mark.parametrize("planar", [False, True])
def test_joint_reactions_have_no_part_along_the_free_directions(planar):
    """The Projection Equation itself: projected on the joints' free directions the
    transmitted wrenches vanish, F_nᵀ W_n = 0 for every joint (no joint forces), for a
    3-link chain (spatial and planar bodies) in a moving state."""
    from projeq.assembly.kinematics import forward
    from projeq.constraints.reactions import joint_reactions

    system = pq.scenes.chain(3, planar=planar)
    q, s_dot = np.array([0.4, -0.7, 1.1]), np.array([1.5, -0.5, 2.0])
    W = joint_reactions(system, q, s_dot)
    kin = forward(system, q, s_dot, 0.0)
    for n, name in enumerate(system.names):
        scale = 1 + np.abs(W[name]).max()
        # round-off of one Gauss solve: measured ≤ 6.2e-16 (was 1e-12)
        assert np.abs(kin.F[n].T @ W[name]).max() < 100 * np.finfo(float).eps * scale
    assert np.abs(W[system.names[0]]).max() > 1.0  # the root joint does carry the chain


def test_rheonomic_constraint_with_baumgarte():
    """A bead on a ring whose radius is prescribed, ρ(t) = 1 + 0.1 sin 2t (Φ(q, t) depends
    on t, so ∂Φ/∂t and ∂²Φ/∂t² enter b_s and γ): the bead stays on the moving ring, and
    its angle from the downward vertical follows the polar-coordinate equation
    ρ θ̈ + 2 ρ̇ θ̇ + g sin θ = 0 (transverse Newton's law, an independent formulation)."""
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")},
                     gravity=(0, 0, -9.81))
    rho = lambda t: 1.0 + 0.1 * np.sin(2 * t)
    system = ConstrainedSystem(tree, phi=lambda q, t: [np.hypot(q[0], q[1]) - rho(t)], q0=[0.6, -0.8],
                               correction="baumgarte", beta=10.0)
    r = pq.simulate(system, 1.0, rtol=RTOL, atol=ATOL, n_points=21)
    # Baumgarte's Φ̇ = −βΦ keeps Φ at the size of the local errors: 100 atol
    assert np.abs(r.constraint_residual).max() < 100 * ATOL
    rho_dot = lambda t: 0.2 * np.cos(2 * t)
    theta0 = np.arctan2(0.6, 0.8)  # x = ρ sin θ, z = −ρ cos θ; ṡ = 0 still moves the bead with the ring
    x_dot, z_dot = system.tree_velocities(system.q0, system.s_dot0)
    omega0 = x_dot * np.cos(theta0) + z_dot * np.sin(theta0)  # ρ(0) = 1
    ref = solve_ivp(lambda t, x: [x[1], -(2 * rho_dot(t) * x[1] + 9.81 * np.sin(x[0])) / rho(t)],
                    (0, 1.0), [theta0, omega0], t_eval=r.t, rtol=RTOL, atol=ATOL)
    theta = np.arctan2(r.q[:, 0], -r.q[:, 1])
    # both to rtol 1e-9, θ ~ 1 rad: measured 3.4e-10 (was 10 rtol)
    assert np.abs(theta - ref.y[0]).max() < 3.4e-9, np.abs(theta - ref.y[0]).max()


def test_the_minimum_norm_solution_passes_the_complex_step():
    """minimum_norm_solution through the complex step gives d/dε (A(ε)⁺ c(ε)) for A of constant
    rank 2 (4 × 3, a product of 4 × 2 and 2 × 3 factors: redundant rows and a null space),
    against the sixth-order stencil (step 1e-3) of numpy's own pinv, an independent
    implementation: measured 1.02e-12 relative, bound 1.1e-11 (the stencil's error; 7e-10 at step 3e-3). The
    complex step through numpy's lstsq, which conjugates, is off by 0.43."""
    from projeq.analysis.differentiation import complex_step, sixth_order
    from projeq.constraints.partitioned import minimum_norm_solution

    rng = np.random.default_rng(4)
    B0, B1, C0, C1, c0, c1 = (rng.standard_normal(shape) for shape in ((4, 2), (4, 2), (2, 3), (2, 3), 4, 4))

    def A(e):
        return (B0 + e * B1) @ (C0 + e * C1)

    exact = complex_step(lambda e: minimum_norm_solution(A(e), c0 + e * c1))
    reference = sixth_order(lambda e: np.linalg.pinv(A(e), rcond=1e-7) @ (c0 + e * c1), 1e-3)
    error = np.abs(exact - reference).max() / np.abs(reference).max()
    assert error < 1.1e-11, error
    conjugated = complex_step(lambda e: np.linalg.lstsq(A(e), c0 + e * c1, rcond=1e-7)[0])
    assert np.abs(conjugated - reference).max() > 0.1 * np.abs(reference).max()

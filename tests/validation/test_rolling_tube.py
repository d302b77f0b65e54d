"""Particle inside a rolling tube, Problem 12 of the Lagrange seminars.

A thin tube (mass M on its periphery, radius a, I_c = M a², eq. (49)) rolls without
slipping on a horizontal plane; a particle m slides freely on its inside surface. The
seminars' coordinates: x of the tube's centre and the angle θ of the particle measured
downwards from the horizontal through the centre, x_m = x + a cos θ, height
y_m = a − a sin θ (52). Rolling on a plane is a holonomic constraint, ψ = x/a (50), so
projeq can model it in two ways:

- "coupled": the tube's translation and its spin are two joints, a prismatic joint along
  x carrying a point mass M/2 (the "carriage") and a revolute joint about y, *coupled* to
  it by ψ = x/a, carrying a ring of mass M/2 with the whole tube's inertia tensor
  (M a² about its axis). Both parts are centred on the axis, so the kinetic energy is
  exactly that of the tube, T_c = ½ M ẋ² + ½ M a² ψ̇² = M ẋ² (51). The particle hangs
  from the non-spinning carriage by a revolute joint, so its coordinate is the seminars' θ.
  (Splitting the mass is needed because projeq has no massless frames: every joint
  carries a body of positive mass.)
- "rolling joint": the tube is one rigid body on a one-dof ``UserJoint`` whose pose is a
  translation x along the plane and a rotation x/a about y; the particle's revolute joint
  is attached to the spinning tube, so its coordinate is φ = θ − x/a.
"""

import numpy as np
import pytest

import projeq as pq

G = 9.81
M_TUBE, A, M_P = 2.0, 0.3, 0.7  # kg, m, kg


def ring_inertia(M, a):
    """A thin ring about its centre, axis y: M a² about the axis, M a²/2 across (49)."""
    return M * a**2 * np.diag([0.5, 1.0, 0.5])


def coupled_model(M=M_TUBE, a=A, m=M_P):
    return pq.System(
        subsystems={
            "carriage": pq.PointMass(M / 2),
            "tube": pq.RigidBody(M / 2, I_c=ring_inertia(M, a)),
            "particle": pq.PointMass(m, (a, 0.0, 0.0)),
        },
        joints={
            "carriage": pq.Prismatic(axis="x", r_pn=(0.0, 0.0, a)),
            "tube": pq.Revolute(parent="carriage", axis="y", coupling={"carriage": 1.0 / a}),  # ψ = x/a (50)
            "particle": pq.Revolute(parent="carriage", axis="y"),
        },
        gravity=(0.0, 0.0, -G),
    )


def rolling_joint(a):
    """Rolling on the plane z = 0: centre at (x, 0, a), turned by x/a about y (no slip:
    the contact point's velocity ẋ − a ψ̇ vanishes). ṡ = ẋ; the twist in tube
    coordinates is (Aᵀ e_x ẋ, e_y ẋ/a)."""

    def pose(q, t):
        c, s = np.cos(q[0] / a), np.sin(q[0] / a)
        zero, one = 0 * c, 1 + 0 * c
        rotation = np.array([[c, zero, s], [zero, one, zero], [-s, zero, c]])
        return rotation, np.array([q[0], zero, zero])

    def F(q, t):
        rotation, _ = pose(q, t)
        twist = np.concatenate((rotation.T @ np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0 / a, 0.0])))
        return twist[:, None]

    return pq.UserJoint.from_functions(1, 1, pose, F, lambda q, t: np.eye(1), r_pn=(0.0, 0.0, a))


def rolling_model(M=M_TUBE, a=A, m=M_P):
    return pq.System(
        subsystems={"tube": pq.RigidBody(M, I_c=ring_inertia(M, a)),
                    "particle": pq.PointMass(m, (a, 0.0, 0.0))},
        joints={"tube": rolling_joint(a), "particle": pq.Revolute(parent="tube", axis="y")},
        gravity=(0.0, 0.0, -G),
    )


MODELS = {"coupled": coupled_model, "rolling-joint": rolling_model}


def to_seed(model):
    """Matrix P with (ẋ, θ̇) = P ṡ for the model's minimal velocities (and (x, θ) = P q)."""
    return np.eye(2) if model == "coupled" else np.array([[1.0, 0.0], [1.0 / A, 1.0]])


def seed_accelerations(theta, x_dot, theta_dot, M=M_TUBE, a=A, m=M_P, g=G):
    """(ẍ, θ̈) of Problem 12: θ̈ from eq. (67),
    (2M/m + cos²θ) θ̈ − ½ sin 2θ θ̇² − (2M/m + 1)(g/a) cos θ = 0,
    and ẍ from eq. (66), ẍ = m a/(m + 2M) (cos θ θ̇² + sin θ θ̈) (the time derivative of
    the momentum (57), so valid at every state). ẋ does not enter (x is cyclic)."""
    mu = 2 * M / m
    theta_ddot = (0.5 * np.sin(2 * theta) * theta_dot**2 + (mu + 1) * g / a * np.cos(theta)) / (
        mu + np.cos(theta) ** 2)
    x_ddot = m * a / (m + 2 * M) * (np.cos(theta) * theta_dot**2 + np.sin(theta) * theta_ddot)
    return np.array([x_ddot, theta_ddot])


@pytest.mark.parametrize("model", list(MODELS))
def test_rolling_tube_equations_of_motion(model):
    """Problem 12, eqs. (56), (66), (67) of the Lagrange seminars, at
    random states: the mass matrix of the Lagrangian (56),
    [[2M + m, −m a sin θ], [−m a sin θ, m a²]] (transformed by P for the rolling joint),
    and the accelerations (66)–(67)."""
    system = MODELS[model]()
    P = to_seed(model)
    rng = np.random.default_rng(12)
    for q, s_dot in zip(rng.uniform(-3.0, 3.0, size=(6, 2)), rng.normal(scale=2.0, size=(6, 2))):
        _, theta = P @ q
        x_dot, theta_dot = P @ s_dot
        coupling = -M_P * A * np.sin(theta)
        M_seed = np.array([[2 * M_TUBE + M_P, coupling], [coupling, M_P * A**2]])
        # algebraic identities: 100 ε of the largest entry (measured 3.8e-16 of it for M, 2.7e-16 of the
        # terms' size for s̈; were 1e-12)
        np.testing.assert_allclose(system.mass_matrix(q), P.T @ M_seed @ P, rtol=0,
                                   atol=100 * np.finfo(float).eps * M_seed.max())
        expected = np.linalg.solve(P, seed_accelerations(theta, x_dot, theta_dot))
        scale = G / A + theta_dot**2  # size of the terms that are summed (rad/s²)
        np.testing.assert_allclose(system.accelerations(q, s_dot), expected, rtol=0,
                                   atol=100 * np.finfo(float).eps * scale)


def bottom_event(P):
    """Event: the particle passes through the bottom θ = π/2 (θ increasing)."""

    def bottom(t, q, s_dot):
        return (P @ q)[1] - np.pi / 2

    bottom.direction = 1
    return bottom


@pytest.mark.parametrize("model", list(MODELS))
def test_rolling_tube_released_particle(model):
    """Problem 12, eqs. (57)–(62) and (68) of the Lagrange seminars:
    released from rest at θ = 0, x = 0 (58), the momentum (57) (2M + m) ẋ − m a sin θ θ̇
    stays 0 and the tube follows x = m a (1 − cos θ)/(2M + m) (62) over several swings;
    at the bottom θ = π/2 the particle's velocity is v_f = ẋ − a θ̇ (68), where (57) gives
    ẋ = c θ̇, c = m a/(2M + m), and conservation of the energy T + V of (56),
    M ẋ² + ½ m (ẋ² + a² θ̇² − 2 a ẋ θ̇) = m g a (V = m g a (1 − sin θ), (55)), gives
    θ̇² = m g a / (M c² + ½ m c² + ½ m a² − m a c).
    """
    system = MODELS[model]()
    P = to_seed(model)
    rtol, atol = 1e-10, 1e-12
    res = pq.simulate(system, 3.0, q0=[0.0, 0.0], s_dot0=[0.0, 0.0], method="DOP853", rtol=rtol, atol=atol,
                      events=[bottom_event(P)], dense_output=True)
    x, theta = (res.q @ P.T).T
    x_dot, theta_dot = (res.s_dot @ P.T).T
    c = M_P * A / (2 * M_TUBE + M_P)
    assert theta.max() > 3.0  # the particle swings across the bottom to the other side
    # Each model coordinate and velocity may be off by 5 units of the request (5 as in
    # scipy's solve_ivp tests); the seminars' (x, θ) = P q then by |P| of that.
    dx, dtheta = np.abs(P) @ (5 * (atol + rtol * np.abs(res.q))).T
    dx_dot, dtheta_dot = np.abs(P) @ (5 * (atol + rtol * np.abs(res.s_dot))).T
    # (62): r = x − c (1 − cos θ), so |r| ≤ δx + c |sin θ| δθ
    residual = x - c * (1 - np.cos(theta))
    assert np.all(np.abs(residual) <= dx + c * np.abs(np.sin(theta)) * dtheta)
    # (57): the same argument on the velocities
    momentum = (2 * M_TUBE + M_P) * x_dot - M_P * A * np.sin(theta) * theta_dot
    bound = (2 * M_TUBE + M_P) * dx_dot + M_P * A * (np.abs(np.sin(theta)) * dtheta_dot
                                                     + np.abs(theta_dot) * dtheta)
    assert np.all(np.abs(momentum) <= bound)
    # (68) at the first passage through the bottom
    q_b, s_b = res.sol(res.t_events[0][0])
    xd_b, thd_b = P @ s_b
    dxd_b, dthd_b = np.abs(P) @ (5 * (atol + rtol * np.abs(s_b)))
    theta_dot_ref = np.sqrt(M_P * G * A / (M_TUBE * c**2 + 0.5 * M_P * c**2 + 0.5 * M_P * A**2 - M_P * A * c))
    v_ref = (c - A) * theta_dot_ref
    assert abs((xd_b - A * thd_b) - v_ref) <= dxd_b + A * dthd_b
    # energy is quadratic in the state: state errors of 5 request units change it by ≤ 10 rtol
    assert res.energy_drift < 10 * rtol

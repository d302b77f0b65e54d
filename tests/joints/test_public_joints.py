"""The public joints stated once — Cylindrical, Universal, Spherical, RollingDisk, RollingSphere —
each compiled by default and checked against an independent reference:

- Cylindrical and Universal: the same freedoms built from Revolute and Prismatic joints on massless
  Frames (same q and ṡ, so the same mass matrix and s̈);
- Spherical: three Revolutes (x, y, z) on Frames, whose Euler rates map to ω = J(θ) θ̇;
- RollingDisk: sympy's KanesMethod of Barhorst's disk (tests/nonholonomic/test_rolling_disk.py);
- RollingSphere: a uniform ball on a turntable turning at Ω circles at 2Ω/7 (Weckesser (1997)).

Each system is built once per module (the first compile of a new joint's callback costs seconds).
"""

import warnings
from functools import cache
from types import SimpleNamespace

import numpy as np
import pytest

import projeq as pq
from projeq.analysis.differentiation import derivative_along
from projeq.assembly import InterpretedWarning, PythonPieceWarning, kernels
from projeq.joints import pose_twist_mismatch
from projeq.spatial import rotation_x, rotation_y, rotation_z

HAS_NUMBA = kernels.has_numba()
GRAVITY = (0.0, 0.0, -9.81)
AXIS = np.array([1.0, 2.0, -0.5]) / np.linalg.norm([1.0, 2.0, -0.5])
AXES = (np.array([1.0, 0.0, 0.0]), np.array([0.2, 1.0, 0.3]) / np.linalg.norm([0.2, 1.0, 0.3]))


def _body(seed):
    """A rigid body with its mass centre off the joint and a full inertia tensor."""
    rng = np.random.default_rng(seed)
    J = rng.uniform(0.02, 0.2, 3)
    A = pq.Revolute(axis=rng.standard_normal(3)).relative(np.array([rng.uniform(0, 3)]), np.zeros(1), 0.0).A
    return pq.RigidBody(float(rng.uniform(0.5, 2.0)), r_c=rng.uniform(-0.3, 0.3, 3),
                        I_c=A @ np.diag([J[1] + J[2], J[0] + J[2], J[0] + J[1]]) @ A.T)


def compiled(system):
    """The default evaluator, asserted to be the compiled one with no piece in Python and no warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        warnings.simplefilter("error", PythonPieceWarning)
        default = system.evaluator()
    assert default.name == "fast" and default.evaluator.interpreted == []
    return default


@cache
def arm(stated):
    """base (Revolute about z) → link (Cylindrical about AXIS) → hand (Universal about AXES) → tip
    (Spherical), or, with ``stated=False``, the same freedoms from Revolute/Prismatic on Frames
    (the spherical part left out: it has other velocities, see test_spherical…)."""
    bodies = {"base": _body(1), "link": _body(2), "hand": _body(3)}
    joints = {"base": pq.Revolute(axis="z")}
    if stated:
        joints["link"] = pq.Cylindrical("base", AXIS, r_pn=(0.3, 0.0, 0.1))
        joints["hand"] = pq.Universal("link", AXES, r_pn=(0.0, 0.2, -0.4))
    else:
        bodies = {"base": bodies["base"], "link_turn": pq.Frame(), "link": bodies["link"],
                  "hand_first": pq.Frame(), "hand": bodies["hand"]}
        joints["link_turn"] = pq.Revolute("base", AXIS, r_pn=(0.3, 0.0, 0.1))
        joints["link"] = pq.Prismatic("link_turn", AXIS)
        joints["hand_first"] = pq.Revolute("link", AXES[0], r_pn=(0.0, 0.2, -0.4))
        joints["hand"] = pq.Revolute("hand_first", AXES[1])
    return pq.System(bodies, joints, gravity=GRAVITY)


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
def test_cylindrical_and_universal_equal_revolutes_and_prismatics_on_frames():
    """Same q = (φ, θ, z, θ₁, θ₂) and ṡ: the mass matrices agree (measured 1.9e-16 relative, bound
    2e-14 = 100 ε) and the compiled s̈ of the stated joints equals the reference's order-n s̈
    (measured 3.6e-16, bound 2e-14) at random states."""
    system, reference = arm(True), arm(False)
    evaluator = compiled(system)
    rng = np.random.default_rng(5)
    for _ in range(4):
        q, s_dot = rng.uniform(-2, 2, 5), rng.uniform(-2, 2, 5)
        M, M_ref = system.mass_matrix(q), reference.mass_matrix(q)
        assert np.abs(M - M_ref).max() <= 2e-14 * np.abs(M_ref).max()
        expected = reference.accelerations(q, s_dot, method="recursive")
        assert np.abs(evaluator.accelerations(q, s_dot, 0.0) - expected).max() <= 2e-14 * (1 + np.abs(expected).max())


def _euler_rates(theta):
    """J(θ) of ω = J θ̇ for A = R_x(θ₁) R_y(θ₂) R_z(θ₃), ω in the last (child) frame."""
    c2, s2, c3, s3 = np.cos(theta[1]), np.sin(theta[1]), np.cos(theta[2]), np.sin(theta[2])
    return np.array([[c2 * c3, s3, 0.0], [-c2 * s3, c3, 0.0], [s2, 0.0, 1.0]])


def _euler_quaternion(theta):
    """The unit quaternion (w, x, y, z) of R_x(θ₁) R_y(θ₂) R_z(θ₃) (w > 0 here: angles ≤ 1 rad)."""
    A = rotation_x(theta[0]) @ rotation_y(theta[1]) @ rotation_z(theta[2])
    w = 0.5 * np.sqrt(1.0 + np.trace(A))
    return np.array([w, (A[2, 1] - A[1, 2]) / (4 * w), (A[0, 2] - A[2, 0]) / (4 * w), (A[1, 0] - A[0, 1]) / (4 * w)])


@cache
def pendulum(stated):
    """A body on a Revolute (a moving parent), a ball-jointed body on it and a Revolute below that;
    the ball joint a Spherical or three Revolutes x, y, z on two Frames."""
    bodies = {"base": _body(4), "ball": _body(5), "tail": _body(6)}
    joints = {"base": pq.Revolute(axis="y"), "tail": pq.Revolute("ball", axis="x", r_pn=(0.1, 0.0, -0.5))}
    if stated:
        joints["ball"] = pq.Spherical("base", r_pn=(0.0, 0.3, -0.2))
    else:
        bodies = {"base": bodies["base"], "x": pq.Frame(), "y": pq.Frame(), "ball": bodies["ball"], "tail": bodies["tail"]}
        joints.update(x=pq.Revolute("base", "x", r_pn=(0.0, 0.3, -0.2)), y=pq.Revolute("x", "y"), ball=pq.Revolute("y", "z"))
    return pq.System(bodies, {name: joints[name] for name in bodies}, gravity=GRAVITY)


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
def test_spherical_equals_three_revolutes():
    """With the Euler angles θ of three Revolutes (x, y, z) on Frames, the Spherical's quaternion is
    that of R_x R_y R_z, ω = J(θ) θ̇, so with S = diag(1, J, 1): M_euler = Sᵀ M S (measured 1.8e-16
    relative, bound 2e-14 = 100 ε) and s̈ = S s̈_euler + Ṡ ṡ_euler (Ṡ ṡ by the complex step; measured
    7.3e-16, bound 2e-14), the Spherical's s̈ from the compiled kernel; its q̇ = K(q) ω is the time
    derivative of the Euler angles' quaternion (complex step; measured 5.8e-16 relative, bound 2e-14)."""
    system, euler = pendulum(True), pendulum(False)
    evaluator = compiled(system)
    rng = np.random.default_rng(8)
    for _ in range(4):
        phi, theta, tail = rng.uniform(-1, 1), rng.uniform(-1, 1, 3), rng.uniform(-1, 1)
        phi_dot, theta_dot, tail_dot = rng.uniform(-2, 2), rng.uniform(-2, 2, 3), rng.uniform(-2, 2)
        q = np.array([phi, *_euler_quaternion(theta), tail])
        q_euler, s_euler = np.array([phi, *theta, tail]), np.array([phi_dot, *theta_dot, tail_dot])
        S = np.eye(5)
        S[1:4, 1:4] = _euler_rates(theta)
        s_dot = S @ s_euler
        M_euler = euler.mass_matrix(q_euler)
        assert np.abs(S.T @ system.mass_matrix(q) @ S - M_euler).max() <= 2e-14 * np.abs(M_euler).max()
        S_dot_s = np.zeros(5)
        S_dot_s[1:4] = derivative_along(lambda th: _euler_rates(th) @ theta_dot, theta, theta_dot)
        expected = S @ euler.accelerations(q_euler, s_euler, method="recursive") + S_dot_s
        got = evaluator.accelerations(q, s_dot, 0.0)
        assert np.abs(got - expected).max() <= 2e-14 * (1 + np.abs(expected).max())
        quat_rate = derivative_along(_euler_quaternion, theta, theta_dot)  # q̇ = K(q) ω of the quaternion
        assert np.abs(system.q_dot(q, s_dot)[1:5] - quat_rate).max() <= 2e-14 * np.abs(quat_rate).max()


@cache
def disk():
    """Barhorst's disk and eccentric mass (tests/nonholonomic/test_rolling_disk.py) on a RollingDisk."""
    from tests.nonholonomic.test_rolling_disk import G, M_R, M_S, R
    bodies = {"disk": pq.RigidBody(M_R, I_c=np.diag([M_R * R * R / 4, M_R * R * R / 2, M_R * R * R / 4])),
              "mass": pq.PointMass(M_S)}
    joints = {"disk": pq.RollingDisk(radius=R), "mass": pq.Fixed("disk", r_pn=ECC)}
    return pq.System(bodies, joints, gravity=(0.0, 0.0, -G))


ECC = (0.004, -0.007, 0.011)  # the eccentric mass in the disk's frame (m)


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
def test_rolling_disk_equals_kanes_method():
    """Barhorst's disk with an eccentric mass: projeq's mass matrix in ṡ = ω (body-fixed) equals
    KanesMethod's (measured 1.7e-16 relative, bound 2e-14 = 100 ε) and the compiled s̈ equals its
    M⁻¹ f (measured 8.3e-16 relative, bound 2e-14) at random states; the contact constraints hold
    (measured 1.1e-16 m/s on speeds of 50, bound 1e-13)."""
    from tests.nonholonomic.test_rolling_disk import G, M_R, M_S, R, kane_model

    system, f = disk(), kane_model()
    evaluator = compiled(system)
    rng = np.random.default_rng(11)
    for _ in range(5):
        q = np.array([*rng.uniform(-np.pi, np.pi, 1), rng.uniform(-1.2, 1.2), *rng.uniform(-np.pi, np.pi, 1),
                      *rng.uniform(-1, 1, 2)])
        u = rng.uniform(-30, 30, 3)
        MM, rhs = f(q[:3], u, (M_R, M_S, R, G, *ECC, M_R * R * R / 4, M_R * R * R / 2))
        MM = np.asarray(MM, float)
        expected = np.linalg.solve(MM, np.asarray(rhs, float).ravel())
        assert np.abs(system.mass_matrix(q) - MM).max() <= 2e-14 * np.abs(MM).max()
        assert np.abs(evaluator.accelerations(q, u, 0.0) - expected).max() <= 2e-14 * np.abs(expected).max()
        assert np.abs(system.constraint_residual(q, system.q_dot(q, u))).max() < 1e-13


OMEGA, RADIUS = 2.0, 0.1  # the turntable's rate (rad/s) and the ball's radius (m)


@cache
def turntable():
    """A uniform ball (I = 2 m R²/5) rolling on a table turning at Ω about the vertical."""
    mass = 0.3
    bodies = {"table": pq.Frame(), "ball": pq.RigidBody(mass, I_c=0.4 * mass * RADIUS**2 * np.eye(3))}
    joints = {"table": pq.Prescribed(pq.Revolute(axis="z"), f"{OMEGA}*t"), "ball": pq.RollingSphere("table", RADIUS)}
    return pq.System(bodies, joints, gravity=GRAVITY, q0=[0.4, 0.1, 1.0, 0.0, 0.0, 0.0], s_dot0=[1.5, -2.0, 3.0])


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
def test_ball_on_a_turntable_circles_at_two_sevenths_of_its_rate():
    """Weckesser (1997): on a table turning at Ω the centre of a uniform ball moves, seen from the
    ground, on a circle at the rate 2Ω/7 (k Ω/(1 + k) with k = I/(m R²) = 2/5: the contact force
    f = m r̈ turns ω by I ω̇ = R f × n, and rolling on the table ṙ = Ω ẑ × r + R ω × ẑ gives
    r̈ = (2/7) Ω ẑ × ṙ). The simulated path z(t) = x + i y (ground) fits c + a e^{i 2Ω t/7} to
    measured 1.9e-7 m (bound 2e-6 m; radius 1.1 m) over a full circle at rtol 1e-9; the rate 0.3 Ω
    (instead of 2/7) misses it by 0.22 m. The contact constraints hold to 9e-16 m/s (bound 1e-13).
    The run takes the compiled evaluator's accelerations alone (simulate's fused ẋ kernel for a new
    set of joints would cost a first compile of about 40 s)."""
    system = turntable()
    rhs = SimpleNamespace(accelerations=compiled(system).accelerations)
    result = pq.simulate(system, 7 * np.pi / OMEGA, method="DOP853", rtol=1e-9, atol=1e-10, n_points=101,
                         evaluator=rhs)
    x, y = result.q[:, 0], result.q[:, 1]
    path = (x + 1j * y) * np.exp(1j * OMEGA * result.t)  # the table's coordinates → the ground's

    def misfit(rate):
        basis = np.column_stack((np.ones_like(result.t), np.exp(1j * rate * result.t)))
        coefficients = np.linalg.lstsq(basis, path, rcond=None)[0]
        return np.abs(basis @ coefficients - path).max()

    assert misfit(2 * OMEGA / 7) < 2e-6
    assert misfit(0.3 * OMEGA) > 0.1
    assert np.abs(result.constraint_residual).max() < 1e-13


@pytest.mark.parametrize("joint", [pq.Cylindrical(axis=AXIS), pq.Universal(axes=AXES), pq.Spherical(),
                                   pq.RollingDisk(radius=0.3), pq.RollingSphere(radius=0.2)], ids=type)
def test_the_statement_is_the_derivative_of_its_pose(joint):
    """F⁶ ṡ + f⁶ = the pose's time derivative along q̇ = K ṡ (central differences, step 1e-7:
    measured 1.0e-10 to 2.9e-9, the Spherical's the largest; bound 2.9e-8, was 1e-7), on unit quaternions."""
    rng = np.random.default_rng(2)
    for _ in range(3):
        q = joint.normalized(rng.uniform(-1, 1, joint.n_q) + joint.default_q())
        mismatch = pose_twist_mismatch(joint, q, rng.uniform(-2, 2, joint.n_s), 0.3)
        assert mismatch < 2.9e-8, mismatch


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="axes: e₁ .* parallel"):
        pq.Universal(axes=("x", "-x"))
    with pytest.raises(ValueError, match="axes: expected two axes"):
        pq.Universal(axes="xy")
    with pytest.raises(ValueError, match="axes\\[1\\]: zero axis"):
        pq.Universal(axes=("x", (0.0, 0.0, 0.0)))
    with pytest.raises(ValueError, match="radius"):
        pq.RollingDisk(radius=0.0)
    with pytest.raises(ValueError, match="radius"):
        pq.RollingSphere(radius=-1.0)
    with pytest.raises(ValueError, match="axis"):
        pq.Cylindrical(axis="w")

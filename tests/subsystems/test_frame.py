"""A massless Frame chains joints: a universal joint equals a UserJoint with both angles."""

import numpy as np
import pytest

import projeq as pq
from projeq.spatial import rotation


def _universal_by_frame(body):
    return pq.System(
        {"cross": pq.Frame(), "body": body},
        {"cross": pq.Revolute(axis="x"), "body": pq.Revolute(parent="cross", axis="y")},
        gravity=(0, 0, -9.81),
    )


def _universal_by_user_joint(body):
    """The same two rotations as one joint: A = R_x(α) R_y(β); the relative twist in child
    coordinates is ω = R_y(β)ᵀ e_x α̇ + e_y β̇ (derived by hand, checked by projeq's pose test)."""

    def pose(q, t):
        return rotation(np.array([1.0, 0, 0]), q[0]) @ rotation(np.array([0, 1.0, 0]), q[1]), np.zeros(3)

    def F(q, t):
        F6 = np.zeros((6, 2), dtype=np.result_type(q, float))
        F6[3:, 0] = [np.cos(q[1]), 0 * q[1], np.sin(q[1])]
        F6[4, 1] = 1.0
        return F6

    joint = pq.UserJoint.from_functions(2, 2, pose, F, lambda q, t: np.eye(2))
    return pq.System({"body": body}, {"body": joint}, gravity=(0, 0, -9.81))


@pytest.mark.parametrize("method", ["recursive", "dense"])
def test_universal_joint_through_a_massless_frame(method):
    """Both models have the same q, ṡ and motion: equal s̈ to 1e-12."""
    body = pq.RigidBody(2.0, (0.1, 0.2, -0.8), np.diag([0.3, 0.4, 0.1]))
    by_frame, by_joint = _universal_by_frame(body), _universal_by_user_joint(body)
    rng = np.random.default_rng(4)
    for _ in range(3):
        q, s_dot = rng.uniform(-1, 1, 2), rng.uniform(-2, 2, 2)
        a = by_frame.accelerations(q, s_dot, method=method)
        b = by_joint.accelerations(q, s_dot, method=method)
        # measured 1.2e-16 of the scale (was 1e-12)
        assert np.abs(a - b).max() <= 100 * np.finfo(float).eps * max(1.0, np.abs(b).max())


def test_a_frame_that_moves_no_mass_is_singular():
    """A Frame at the end of a chain makes its joint's D_n = 0: a clear error, not NaN."""
    system = pq.System({"frame": pq.Frame()}, {"frame": pq.Revolute(axis="z")})
    with pytest.raises(pq.SingularMassError, match="frame"):
        system.accelerations([0.0], [0.0])

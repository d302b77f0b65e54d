"""Slender rods with zero axial inertia (I_c = diag(m l²/12, m l²/12, 0), as sympy/PyDy
models write them): accepted where no joint can turn the rod about its axis (every joint
block F_nᵀ M_n F_n positive definite when the System is built), refused naming the body and
the axis where one can."""

import numpy as np
import pytest

import projeq as pq

M1, M2, L1, L2, G = 1.3, 0.8, 1.1, 0.7, 9.81


def _rod(m: float, l: float) -> pq.RigidBody:
    """A uniform rod of mass m and length l hanging along −z from its joint, no axial inertia."""
    return pq.RigidBody(m, (0.0, 0.0, -l / 2), np.diag([m * l * l / 12, m * l * l / 12, 0.0]))


def _double_rod_pendulum() -> pq.System:
    return pq.System({"upper": _rod(M1, L1), "lower": _rod(M2, L2)},
                     {"upper": pq.Revolute(axis="y"), "lower": pq.Revolute(parent="upper", axis="y", r_pn=(0, 0, -L1))},
                     gravity=(0.0, 0.0, -G))


def _closed_form(q, s_dot):
    """The double compound pendulum of uniform rods in absolute angles φ₁ = q₁, φ₂ = q₁ + q₂
    from the vertical (Lagrange's equations, e.g. Meirovitch, Methods of Analytical Dynamics,
    1970, §2.8 with the rods' moments m l²/3 about their hinges):
    (m₁/3 + m₂) l₁² φ̈₁ + ½ m₂ l₁ l₂ [cos(φ₁ − φ₂) φ̈₂ + sin(φ₁ − φ₂) φ̇₂²] + (m₁/2 + m₂) g l₁ sin φ₁ = 0,
    ⅓ m₂ l₂² φ̈₂ + ½ m₂ l₁ l₂ [cos(φ₁ − φ₂) φ̈₁ − sin(φ₁ − φ₂) φ̇₁²] + ½ m₂ g l₂ sin φ₂ = 0;
    returns (q̈₁, q̈₂) = (φ̈₁, φ̈₂ − φ̈₁)."""
    phi1, phi2 = q[0], q[0] + q[1]
    w1, w2 = s_dot[0], s_dot[0] + s_dot[1]
    c, s = np.cos(phi1 - phi2), np.sin(phi1 - phi2)
    k = 0.5 * M2 * L1 * L2
    mass = np.array([[(M1 / 3 + M2) * L1**2, k * c], [k * c, M2 * L2**2 / 3]])
    rhs = np.array([-k * s * w2**2 - (M1 / 2 + M2) * G * L1 * np.sin(phi1), k * s * w1**2 - 0.5 * M2 * G * L2 * np.sin(phi2)])
    a1, a2 = np.linalg.solve(mass, rhs)
    return np.array([a1, a2 - a1])


@pytest.mark.parametrize("method", ["recursive", "dense", None])
def test_double_pendulum_of_rods_without_axial_inertia(method):
    """s̈ of the order-n (recursive), the dense and the default evaluator equal the closed form
    at three random states: 1e-14 relative to |s̈| (measured ≤ 5e-16). Before, the rods were refused
    as "not positive definite"."""
    system = _double_rod_pendulum()
    rng = np.random.default_rng(36)
    for _ in range(3):
        q, s_dot = rng.uniform(-2, 2, 2), rng.uniform(-2, 2, 2)
        expected = _closed_form(q, s_dot)
        s_ddot = system.accelerations(q, s_dot, method=method)
        assert np.abs(s_ddot - expected).max() <= 1e-14 * np.abs(expected).max()


@pytest.mark.parametrize("joint", [pq.Revolute(axis="z"), pq.Free()], ids=["revolute-about-the-axis", "free"])
def test_a_joint_that_can_spin_the_rod_about_its_axis_is_refused(joint):
    """A revolute about the rod's own axis, or a free joint, would leave the rod's spin
    without inertia (a singular mass matrix): refused when the System is built, naming the
    body, the axis and the joint."""
    with pytest.raises(ValueError, match=r"^joints\['rod'\]: the body 'rod' has no inertia about its axis "
                                         r"\[0\.0, 0\.0, -?1\.0\].*joint (Revolute|Free) can turn it"):
        pq.System({"rod": _rod(1.0, 1.0)}, {"rod": joint})


def test_only_one_zero_moment_is_a_rod():
    """The rod's axis is found (body coordinates); a body with every moment zero is still
    refused (a particle is a PointMass), so is a negative moment."""
    rod = pq.RigidBody(1.0, I_c=np.diag([0.0, 0.5, 0.5]))
    # measured 0 (was allclose's defaults)
    assert np.allclose(np.abs(rod.slender_axis), [1.0, 0.0, 0.0], rtol=0, atol=100 * np.finfo(float).eps)
    assert pq.RigidBody(1.0, I_c=np.eye(3)).slender_axis is None
    with pytest.raises(ValueError, match=r"^I_c: inertia tensor is not positive definite \(all zero\)"):
        pq.RigidBody(1.0, I_c=np.zeros((3, 3)))

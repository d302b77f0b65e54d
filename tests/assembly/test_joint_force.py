"""JointForce on a one-dof joint takes a scalar τ (a constant or a callable's value), as it
takes [τ]; checked against the closed form of a driven point-mass pendulum."""

import numpy as np
import pytest

import projeq as pq

M, L, G = 2.0, 0.7, 9.81


def _pendulum(tau) -> pq.System:
    return pq.System({"bob": pq.PointMass(M, (0.0, 0.0, -L))}, {"bob": pq.Revolute(axis="y")},
                     gravity=(0.0, 0.0, -G), forces=[pq.JointForce("bob", tau)])


@pytest.mark.parametrize("method", ["recursive", "dense", None])
@pytest.mark.parametrize("tau", [5.0, np.float64(5.0), lambda t, q, s_dot: 5.0 * np.cos(t)],
                         ids=["float", "numpy-scalar", "callable"])
def test_a_scalar_tau_drives_a_one_dof_joint(tau, method):
    """θ̈ = −(g/l) sin θ + τ/(m l²) for a point mass m on a rod l hinged about y, gravity −z
    (the moment of the weight about y is −m g l sin θ). Before, a scalar was refused when the
    System was built ("expected shape (1,), got ()"). 100 ε relative (measured 7e-16)."""
    system = _pendulum(tau)
    theta, t = 0.4, 0.3
    expected = -G / L * np.sin(theta) + 5.0 * (np.cos(t) if callable(tau) else 1.0) / (M * L * L)
    s_ddot = system.accelerations([theta], [0.2], t, method=method)
    assert s_ddot.shape == (1,)
    assert s_ddot[0] == pytest.approx(expected, rel=2.2e-14)


def test_a_scalar_is_one_number_only_for_one_dof():
    """A joint of three dofs still needs τ of shape (3,): a scalar is refused naming the joint."""
    body = pq.RigidBody(1.0, (0.1, 0.0, 0.0), np.diag([0.1, 0.1, 0.05]))
    with pytest.raises(ValueError, match=r"tau of joint 'b': expected shape \(3,\), got \(\)"):
        pq.System({"b": body}, {"b": pq.Planar(plane="xy")}, forces=[pq.JointForce("b", 1.0)])

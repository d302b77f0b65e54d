"""The subsystem contract (projeq/subsystems/base.py): required members are checked when a
System is built, optional ones have defaults, and capabilities are declared by the class
(``has_ports``, ``deforms``), so evaluators, the exporter and the command line read them
instead of probing."""

import numpy as np
import pytest

import projeq as pq


class Ball:
    """A duck-typed subsystem (no base class): a point mass m at its frame origin."""

    n_y = 6

    def __init__(self, m):
        self.m = m

    def gauss_terms(self, y_dot, R, gravity, q_e):
        v, omega = y_dot[:3], y_dot[3:]
        return np.diag([self.m] * 3 + [0.0] * 3), np.concatenate((self.m * (R.T @ gravity - np.cross(omega, v)), np.zeros(3)))

    def kinetic_energy(self, y_dot, q_e):
        return 0.5 * self.m * y_dot[:3] @ y_dot[:3]

    def potential_energy(self, R, r, gravity, q_e):
        return -self.m * gravity @ r


def test_capabilities_are_declared_by_the_class():
    beam = pq.RitzBeam(1.0, 2.0, 10.0, n_v=1, n_w=1)
    assert beam.has_ports and beam.deforms
    for sub in (pq.RigidBody(1.0, I_c=np.eye(3)), pq.PointMass(1.0), pq.Frame(), pq.PlanarBody(1.0, I_c=0.1)):
        assert not (sub.has_ports or sub.deforms) and sub.n_e == 0
    with pytest.raises(NotImplementedError, match="RigidBody does not deform"):
        pq.RigidBody(1.0, I_c=np.eye(3)).centre_line(np.zeros(0), np.zeros(6))


def test_a_duck_typed_subsystem_gets_the_defaults_when_the_system_is_built():
    """Ball lacks S, n_e, rigid_inertia and the capabilities; the System gives it the
    defaults, and it falls freely: s̈ = −g along the vertical slider."""
    ball = Ball(0.5)
    system = pq.System({"ball": ball}, {"ball": pq.Prismatic(axis="z")}, gravity=(0.0, 0.0, -9.81))
    assert (ball.S, ball.n_e, ball.rigid_inertia, ball.has_ports, ball.deforms) == (None, 0, None, False, False)
    assert system.accelerations(system.q0, system.s_dot0) == pytest.approx([-9.81], rel=1e-14)


def test_a_subclass_that_leaves_a_required_member_to_the_base_class_is_refused_by_name():
    class Half(pq.Subsystem):
        n_y = 6

        def gauss_terms(self, y_dot, R, gravity, q_e):
            return np.eye(6), np.zeros(6)

    with pytest.raises(ValueError, match=r"subsystems\['half'\]: .* lacks kinetic_energy, potential_energy"):
        pq.System({"half": Half()}, {"half": pq.Revolute()})

"""A user-defined subsystem with an internal coordinate plugs into both assemblers.

The subsystem is a rigid body carrying a point mass (an absorber) that slides along the
body axis e through r_0 on a spring k: ẏ = (v_O, ω, ẋ_a), one internal coordinate x_a with
ṡ_e = ẋ_a. Its Gauss terms are derived here independently of projeq's rigid formulas,
from the Projection Equation B(13) for the two parts: the absorber's velocity is
v_a = J ẏ with J = [E, −r̃_a, e], r_a = r_0 + e x_a, so its contribution is
Jᵀ (m_a (J ÿ + J̇ ẏ + ω̃ v_a) − m_a g) with J̇ ẏ = ẋ_a ω̃ e, plus the spring's −k x_a on ẋ_a.
"""

import numpy as np
import pytest

import projeq as pq
from projeq.spatial import skew


class BodyWithAbsorber:
    """Rigid body (m, r_c, I_c) plus an absorber mass m_a on a spring k along e at r_0."""

    n_y = 7
    n_e = 1
    S = np.vstack((np.eye(6), np.zeros((1, 6))))

    def __init__(self, m, r_c, I_c, m_a, r_0, e, k):
        self.body = pq.RigidBody(m, r_c, I_c)
        self.m_a, self.r_0, self.e, self.k = m_a, np.asarray(r_0, float), np.asarray(e, float), k

    def _absorber(self, y_dot, q_e):
        r_a = self.r_0 + self.e * q_e[0]
        J = np.hstack((np.eye(3), -skew(r_a), self.e[:, None]))
        return r_a, J

    def gauss_terms(self, y_dot, R, gravity, q_e):
        M = np.zeros((7, 7))
        M_body, h_body = self.body.gauss_terms(y_dot[:6], R, gravity)
        M[:6, :6] = M_body
        r_a, J = self._absorber(y_dot, q_e)
        omega = y_dot[3:6]
        v_a = J @ y_dot
        M += self.m_a * J.T @ J
        h = np.concatenate((h_body, [-self.k * q_e[0]]))
        h -= J.T @ (self.m_a * (y_dot[6] * np.cross(omega, self.e) + np.cross(omega, v_a)) - self.m_a * R.T @ gravity)
        return M, h

    def kinetic_energy(self, y_dot, q_e):
        M, _ = self.gauss_terms(y_dot, np.eye(3), np.zeros(3), q_e)
        return 0.5 * y_dot @ M @ y_dot

    def potential_energy(self, R, r, gravity, q_e):
        r_a = self.r_0 + self.e * q_e[0]
        return (
            self.body.potential_energy(R, r, gravity)
            - self.m_a * gravity @ (r + R @ r_a)
            + 0.5 * self.k * q_e[0] ** 2
        )


def _pendulum_with_absorber():
    absorber = BodyWithAbsorber(
        m=2.0, r_c=(0, 0, -0.5), I_c=np.diag([0.2, 0.2, 0.01]), m_a=0.3, r_0=(0, 0, -1.0), e=(1.0, 0, 0), k=40.0
    )
    link = pq.RigidBody(1.0, (0, 0, -0.4), np.diag([0.05, 0.05, 0.01]))
    return pq.System(
        {"arm": absorber, "tip": link},
        {"arm": pq.Revolute(axis="y"), "tip": pq.Revolute(parent="arm", axis="x", r_pn=(0, 0, -1.0))},
        gravity=(0, 0, -9.81),
        q0=[0.4, 0.05, 0.3],
    )


def test_internal_coordinates_are_laid_out_after_the_joints():
    """q_n = (joint coordinates, internal coordinates): arm θ, arm x_a, tip φ."""
    system = _pendulum_with_absorber()
    assert system.n_q == 3 and system.n_s == 3
    assert np.array_equal(system.q_dot(system.q0, np.array([1.0, 2.0, 3.0])), [1.0, 2.0, 3.0])  # measured 0


@pytest.mark.parametrize("seed", range(5))
def test_recursive_equals_dense(seed):
    """docs/theory.md §5 = §6 for a subsystem with its own minimal velocity (round-off: 100 ε of the
    scale, measured 1.2e-16 over the five seeds; was 1e-12)."""
    system = _pendulum_with_absorber()
    rng = np.random.default_rng(seed)
    q, s_dot = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)
    a = system.accelerations(q, s_dot, method="recursive")
    b = system.accelerations(q, s_dot, method="dense")
    assert np.abs(a - b).max() <= 100 * np.finfo(float).eps * max(1.0, np.abs(b).max())


def test_energy_is_conserved():
    """No damping, no drive: kinetic + potential (gravity, spring) is constant; DOP853 at
    rtol 1e-11 keeps it to 4.1e-13 of the energy scale over 5 s (4.0e-13 over 3 s, 5.0e-13 over 8 s); the
    bound is 10 times the largest (was 1e-8)."""
    system = _pendulum_with_absorber()
    result = pq.simulate(system, 5.0, method="DOP853", rtol=1e-11, atol=1e-12)
    assert result.energy_drift < 5e-12, result.energy_drift
    assert np.ptp(result.q[:, 1]) > 0.01  # the absorber does move


@pytest.mark.parametrize("method", ["recursive", "dense", "hub_beam"])
def test_on_a_fixed_root_the_absorber_is_a_spring_mass_oscillator(method):
    """The body fixed to the ground, the absorber slides horizontally: m_a ẍ_a = −k x_a.
    ``"hub_beam"`` (which ``"auto"`` picks) is the hub path (projeq/assembly/beam_fast.py)
    through the default ``elastic_terms``, the rows of this subsystem's own gauss_terms."""
    absorber = BodyWithAbsorber(m=2.0, r_c=(0, 0, -0.5), I_c=np.diag([0.2, 0.2, 0.01]), m_a=0.3, r_0=(0, 0, -1.0),
                                e=(1.0, 0, 0), k=40.0)
    system = pq.System({"arm": absorber}, {"arm": pq.Fixed()}, gravity=(0.0, 0.0, -9.81), q0=[0.02], s_dot0=[0.5])
    if method == "hub_beam":
        assert system.evaluator("auto").name == "hub_beam"
    s_ddot = system.accelerations(system.q0, system.s_dot0, method=method)
    assert s_ddot == pytest.approx([-40.0 * 0.02 / 0.3], rel=1e-13)


class _Blob(pq.Subsystem):
    """A user subsystem whose terms have the wrong size: n_y = 6, but a 3×3 M and a 3-vector h."""

    n_y = 6

    def gauss_terms(self, y_dot, R, gravity, q_e=None):
        return np.eye(3), np.zeros(3)

    def kinetic_energy(self, y_dot, q_e=None):
        return 0.0

    def potential_energy(self, R, r, gravity, q_e=None):
        return 0.0


@pytest.mark.parametrize("sub, message", [
    (_Blob(), r"gauss_terms returned M of shape \(3, 3\) and h of shape \(3,\); with n_y = 6 they must be "
              r"\(6, 6\) and \(6,\)"),
    (type("Selected", (_Blob,), {"S": np.eye(6)[:3]})(), r"S has shape \(3, 6\), expected \(n_y, 6\) = \(6, 6\)"),
], ids=["terms", "selection"])
def test_a_user_subsystem_of_inconsistent_size_is_named(sub, message):
    """Passes if a subsystem whose n_y, S and terms disagree is refused where the System is built,
    by its name; before, it was accepted and every evaluation failed inside numpy ("could not
    broadcast input array from shape (1,3,3) into shape (1,6,6)", or matmul's "mismatch in its
    core dimension 0")."""
    with pytest.raises(ValueError, match=rf"^subsystems\['blob'\]: {message}"):
        pq.System({"blob": sub}, {"blob": pq.Revolute(axis="y")})

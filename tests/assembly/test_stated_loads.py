"""A force law stated once (projeq.BodyLoad): its wrench runs on numpy (the reference evaluators),
traced with sympy (gauss_form) and compiled (the fast evaluator's loop of laws), and they agree.

The law is quadratic air drag −c |v| v plus a moment −c_ω ω, on every body of random trees; the
references are the closed form of a ball falling under quadratic drag, the order-n elimination
and the dense Gauss form (numpy), and Richardson-extrapolated differences for the exact Jacobian."""

import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import projeq as pq
from projeq.assembly import InterpretedWarning, PythonPieceWarning
from projeq.assembly.fast import FastEvaluator

numba = pytest.importorskip("numba")


class Drag(pq.BodyLoad):
    """Air drag −c |v| v on the body's origin and a rotational drag −c_ω ω."""

    def __init__(self, body, c, c_omega=0.0):
        super().__init__(body)
        self.c, self.c_omega = float(c), float(c_omega)

    def statement(self, R, r, v, omega, t, m):
        speed = m.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
        return m.vector([*(-self.c * speed * v), *(-self.c_omega * omega)])


class Gust(Drag):
    """Drag in a wind that grows with time, w = a t along z: −c (v_z − a t); the wrench depends on t."""

    def __init__(self, body, c, a):
        super().__init__(body, c)
        self.a = float(a)

    def statement(self, R, r, v, omega, t, m):
        return m.vector([0.0, 0.0, -self.c * (v[2] - self.a * t), 0.0, 0.0, 0.0])


def _ball(law):
    return pq.System({"ball": pq.PointMass(0.5)}, {"ball": pq.Prismatic(axis="z")}, gravity=(0.0, 0.0, -9.81),
                     forces=[law])


def test_a_falling_ball_reaches_the_closed_form_compiled():
    """v(t) = −√(m g / c) tanh(t √(g c / m)) (m v̇ = −m g + c v²) by the default evaluator, compiled
    with no warning: measured 1.0e-9 m/s at rtol 1e-10, bound 1e-8."""
    m, c, g = 0.5, 0.2, 9.81
    system = _ball(Drag("ball", c))
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        warnings.simplefilter("error", PythonPieceWarning)
        assert system.evaluator().evaluator.interpreted == []
    result = pq.simulate(system, 3.0, rtol=1e-10, atol=1e-12)
    v = -np.sqrt(m * g / c) * np.tanh(result.t * np.sqrt(g * c / m))
    assert np.abs(result.s_dot[:, 0] - v).max() <= 1e-8


def _tree(n, seed):
    rng = np.random.default_rng(seed)
    bodies, joints, laws = {}, {}, []
    for i in range(n):
        name, parent = f"b{i}", None if i == 0 else f"b{int(rng.integers(max(0, i - 2), i))}"
        axis = rng.standard_normal(3)
        joint = pq.Revolute if rng.random() < 0.6 else pq.Prismatic
        joints[name] = joint(parent, axis / np.linalg.norm(axis), rng.uniform(-0.5, 0.5, 3))
        J = rng.uniform(0.02, 0.2, 3)
        bodies[name] = pq.RigidBody(float(rng.uniform(0.5, 2)), r_c=rng.uniform(-0.3, 0.3, 3),
                                    I_c=np.diag([J[1] + J[2], J[0] + J[2], J[0] + J[1]]))
        laws.append(Drag(name, float(rng.uniform(0.1, 1.0)), float(rng.uniform(0.0, 0.3))))
    return pq.System(bodies, joints, gravity=(0.0, 0.0, -9.81), forces=laws)


@settings(max_examples=20)
@given(n=st.integers(1, 6), seed=st.integers(0, 2**32 - 1))
def test_compiled_interpreted_and_reference_agree_on_random_trees(n, seed):
    """s̈ by the compiled loop of laws = the same kernels interpreted = the order-n elimination and
    the dense Gauss form with the law's add_to: relative to 1 + |s̈|, bound 2.9e-14 (measured ≤ 2.9e-15,
    the largest over 1200 random trees drawn as here; was 1e-11)."""
    system = _tree(n, seed)
    rng = np.random.default_rng(seed)
    q, s_dot = rng.uniform(-1, 1, system.n_q), rng.uniform(-1, 1, system.n_s)
    reference = system.accelerations(q, s_dot, 0.3, method="recursive")
    scale = 1.0 + np.abs(reference).max()
    for s_ddot in (FastEvaluator(system).accelerations(q, s_dot, 0.3),
                   FastEvaluator(system, compiled=False).accelerations(q, s_dot, 0.3),
                   system.accelerations(q, s_dot, 0.3, method="dense")):
        assert np.abs(s_ddot - reference).max() <= 2.9e-14 * scale, (s_ddot - reference) / scale


def test_the_gauss_form_and_the_exact_jacobian_come_from_the_statement():
    """gauss_form (the wrench traced with sympy) = the order-n elimination (measured 2.3e-15 of
    1 + |s̈|, bound 2.3e-14; was 1e-12); the one-call exact ∂ẋ/∂x against Richardson differences
    of q̇ and the recursive evaluator (measured 2.8e-12 of 1 + |J|, bound 2.8e-11; was 1e-7)."""
    from projeq.analysis.differentiation import jacobian
    from projeq.analysis.jacobians import state_jacobian

    system = _tree(3, 11)
    rng = np.random.default_rng(12)
    q, s_dot = rng.uniform(-1, 1, system.n_q), rng.uniform(-1, 1, system.n_s)
    reference = system.accelerations(q, s_dot, 0.0, method="recursive")
    symbolic = pq.symbolic.gauss_form(system).evaluator().accelerations(q, s_dot)
    error = np.abs(symbolic - reference).max() / (1 + np.abs(reference).max())
    assert error <= 2.3e-14, error
    x = np.concatenate((q, s_dot))
    J, how = state_jacobian(system, x, 0.0)

    def x_dot(z):
        return np.concatenate((z[system.n_q:], system.accelerations(z[:system.n_q], z[system.n_q:], 0.0,
                                                                     method="recursive")))

    reference_J = jacobian(x_dot, x)
    error = np.abs(J - reference_J).max() / (1 + np.abs(reference_J).max())
    assert how == "exact" and error <= 2.8e-11, (how, error)


def test_a_wrench_of_t_runs_compiled_and_reaches_the_closed_form():
    """The compiled loop takes t: a wrench that depends on t runs compiled by default with no warning,
    and the ball in the growing wind, v̇ = −g − k (v − a t) with k = c/m, reaches
    v(t) = α (1 − e^(−kt)) + a t, α = −(g + a)/k, from rest: measured 6.5e-10 m/s over 3 s at rtol 1e-10
    (2.3e-11 of |v| ≤ 28 m/s; 8.0e-15 while each of the 20 segments cut its last step short), bound
    6.5e-9."""
    m, c, a, g = 0.5, 0.2, 1.5, 9.81
    system = _ball(Gust("ball", c, a))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        evaluator = system.evaluator()
    assert evaluator.name == "fast" and evaluator.evaluator.interpreted == []
    result = pq.simulate(system, 3.0, rtol=1e-10, atol=1e-12)
    k = c / m
    v = -(g + a) / k * (1 - np.exp(-k * result.t)) + a * result.t
    error = np.abs(result.s_dot[:, 0] - v).max()
    assert error <= 6.5e-9, error

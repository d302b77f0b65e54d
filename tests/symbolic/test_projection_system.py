"""``projeq.symbolic.gauss_form(system)``: symbolic == numeric on random trees (STYLE §0.5),
symbolic parameters, refusal of what the symbolic chain does not cover."""

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings

import projeq as pq
from projeq.symbolic import gauss_form
from tests.strategies import trees

# the symbolic and the numeric evaluators are two double-precision evaluations of the same
# equations for ≤ 2 bodies with masses in [1e-2, 1e2]: round-off ~1e-13 relative to the
# largest entry; 1e-9 covers the conditioning of M (mass ratios up to 1e4) with margin
RTOL = 1e-9


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(trees(max_n=2, kinds=("revolute", "prismatic", "fixed"), forces=False, scleronomic=True))
def test_symbolic_equals_dense_and_recursive_on_random_trees(tree):
    """Random trees (≤ 2 bodies: general float axes make the unsimplified expressions grow
    fast; a 4-body tree takes minutes) of revolute/prismatic/fixed joints with random axes, offsets, masses,
    inertias and gravity: M and s̈ of the compiled symbolic Gauss form equal the numeric
    dense Gauss form and both numeric evaluators at a random state."""
    system = tree.system
    assume(system.n_s > 0)  # a system of Fixed joints only has no equations of motion
    evaluator = gauss_form(system).evaluator()
    M, _ = evaluator.gauss_form(tree.q, tree.s_dot, tree.t)
    M_ref, _ = system.gauss_form(tree.q, tree.s_dot, tree.t)
    assert np.allclose(M, M_ref, rtol=0, atol=RTOL * np.abs(M_ref).max())
    s_ddot = evaluator.accelerations(tree.q, tree.s_dot, tree.t)
    for method in ("recursive", "dense"):
        reference = system.accelerations(tree.q, tree.s_dot, tree.t, method=method)
        assert np.allclose(s_ddot, reference, rtol=RTOL, atol=RTOL * np.abs(reference).max())


def test_double_pendulum_with_symbolic_parameters_is_the_closed_form():
    """Problem 8 of the Lagrange problem book (``scenes.double_pendulum``): for point masses
    m₁, m₂ on rods l₁, l₂, θ₂ relative, M = [[(m₁+m₂)l₁² + m₂l₂² + 2m₂l₁l₂ cos θ₂,
    m₂l₂² + m₂l₁l₂ cos θ₂], [·, m₂l₂²]]; the parameters are given as sympy symbols."""
    m1, m2, l1, l2, g = sp.symbols("m_1 m_2 l_1 l_2 g", positive=True)
    gauss = gauss_form(pq.scenes.double_pendulum(), {
        "bob1.m": m1, "bob2.m": m2, "bob1.r_c": (0, 0, -l1), "bob2.r_c": (0, 0, -l2),
        "bob2.r_pn": (0, 0, -l1), "gravity": (0, 0, -g),
    })
    theta2 = gauss.q[1]
    c = sp.cos(theta2)
    expected = sp.Matrix([[(m1 + m2) * l1**2 + m2 * l2**2 + 2 * m2 * l1 * l2 * c, m2 * l2**2 + m2 * l1 * l2 * c],
                          [m2 * l2**2 + m2 * l1 * l2 * c, m2 * l2**2]])
    assert sp.simplify(gauss.M - expected) == sp.zeros(2, 2)
    assert set(gauss.parameters) == {m1, m2, l1, l2, g}
    # at rest the right-hand side is the gravity torque: −(m₁+m₂) g l₁ sin θ₁ − m₂ g l₂ sin(θ₁+θ₂), −m₂ g l₂ sin(θ₁+θ₂)
    theta1 = gauss.q[0]
    rest = gauss.rhs.subs({s_k: 0 for s_k in gauss.s})
    gravity = sp.Matrix([-(m1 + m2) * g * l1 * sp.sin(theta1) - m2 * g * l2 * sp.sin(theta1 + theta2),
                         -m2 * g * l2 * sp.sin(theta1 + theta2)])
    assert sp.simplify(rest - gravity) == sp.zeros(2, 1)


def test_unsupported_joints_and_forces_are_named():
    system = pq.System({"b": pq.RigidBody(1.0, I_c=np.eye(3))}, {"b": pq.Planar()})
    with pytest.raises(ValueError, match="^system: joint 'b' \\(Planar\\) is not supported"):
        gauss_form(system)


def test_bad_parameters_are_named():
    system = pq.scenes.double_pendulum()
    with pytest.raises(ValueError, match="^parameters: unknown key 'bob3.m'"):
        gauss_form(system, {"bob3.m": sp.Symbol("m")})
    with pytest.raises(ValueError, match=r"^parameters: 'bob1.r_c' must have shape \(3, 1\)"):
        gauss_form(system, {"bob1.r_c": (0, sp.Symbol("l"))})

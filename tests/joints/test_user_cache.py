"""A joint from sympy is derived once per statement in a process
(``projeq.joints.user_compiler.derive``): a repeated ``UserJoint.from_sympy`` with the same
symbols, expressions and constraints reuses the derivation, with the same parameters' values or
others (passed at run time), and gives the accelerations of a fresh derivation; a statement that
differs in an expression or a constraint is derived anew; joints from one derivation keep their
own parameters' values, parent, q0, placement and expressions.

The reference is always a fresh derivation of the same statement (the cache cleared), and the
particle's s̈ the one of Barhorst's particle with ẏ + a zᵖ ẋ = 0 (Barhorst, "Systematic closed form
modeling of multibody systems with non-holonomic constraints", §3.1, footnote 6, for a = p = 1).
"""

import numpy as np
import pytest
import sympy as sp

import projeq as pq
from projeq.joints.user_compiler import derive

x, y, z, a = sp.symbols("x y z a")
U = sp.symbols("u_x u_z")
XD, YD, ZD = sp.symbols("xd yd zd")
STATE = (np.array([0.3, -0.2, 0.7]), np.array([1.1, -0.4]))


def particle_joint(a_value=1.0, power=1, scale=None, **placement):
    """The particle in space with ẏ + a zᵖ ẋ = 0: q = (x, y, z), ṡ = (ẋ, ż); with a ``scale``,
    the constraint (times ``scale``) stated for its residual."""
    lateral = -a * z**power
    F = sp.Matrix([[1, 0], [lateral, 0], [0, 1], [0, 0], [0, 0], [0, 0]])
    K = sp.Matrix([[1, 0], [lateral, 0], [0, 1]])
    constraints = None if scale is None else [scale * (YD - lateral * XD)]
    return pq.UserJoint.from_sympy([x, y, z], U, sp.eye(3), [x, y, z], F, K, parameters={a: a_value},
                                   constraints=constraints, q_dot=[XD, YD, ZD], **placement)


def particle_s_ddot(joint) -> np.ndarray:
    system = pq.System({"p": pq.PointMass(1.0)}, {"p": joint}, gravity=(0.0, 0.0, -9.81))
    return system.accelerations(*STATE, method="recursive")


def fresh(build):
    """``build()`` from a fresh derivation: the cache cleared first."""
    derive.cache_clear()
    return build()


def close(u, v) -> bool:
    u, v = np.asarray(u), np.asarray(v)
    return u.shape == v.shape and np.abs(u - v).max(initial=0.0) <= 1e-13 * (1.0 + np.abs(v).max(initial=0.0))


def test_a_repeated_scene_build_reuses_the_derivation_and_gives_the_fresh_accelerations():
    """Barhorst's rolling disk of radius 1.5 cm and 2 cm, each built twice (interleaved): one
    derivation, three reuses (the cache's statistics), one compiled function per radius, and the
    reused joints' s̈ at a moving state are the fresh derivations' to round-off."""
    q, s_dot = np.array([0.1, 0.2, 0.3, 0.01, -0.02]), np.array([1.0, 15.0, -0.5])
    derive.cache_clear()
    first = [pq.scenes.rolling_disk(R=R) for R in (0.015, 0.02)]
    again = [pq.scenes.rolling_disk(R=R) for R in (0.015, 0.02)]
    info = derive.cache_info()
    assert (info.misses, info.hits) == (1, 3)
    assert again[1].joints[0].compiled_values() is first[1].joints[0].compiled_values()
    assert again[0].joints[0].compiled_values() is not again[1].joints[0].compiled_values()
    references = fresh(lambda: [pq.scenes.rolling_disk(R=R) for R in (0.015, 0.02)])
    for system, reference in zip(again, references):
        expected = reference.accelerations(q, s_dot, method="recursive")
        assert close(system.accelerations(q, s_dot, method="recursive"), expected)
    assert not close(*(system.accelerations(q, s_dot, method="recursive") for system in again))


@pytest.mark.parametrize("first, variant, derivations", [
    pytest.param({}, {"a_value": 2.0}, 1, id="parameter"),
    pytest.param({}, {"power": 2}, 2, id="expression"),
    pytest.param({"scale": 1}, {"scale": 2}, 2, id="constraint"),
])
def test_a_different_statement_is_derived_anew_other_parameter_values_are_its_own(first, variant, derivations):
    """After the particle with a = p = 1, one that differs from it only in the power p (the
    expressions F and K) or only in the stated constraint is derived anew, one that differs only in
    the parameter's value a reuses the derivation; either way its s̈ and constraint residual are
    those of its own fresh derivation (which differ from the first particle's)."""
    q_dot = np.array([0.5, 0.9, -0.3])  # violates the constraint: the residual shows its statement
    derive.cache_clear()
    base = particle_joint(**first)
    other = particle_joint(**variant)
    assert derive.cache_info().misses == derivations
    reference = fresh(lambda: particle_joint(**variant))
    s_ddot, residual = particle_s_ddot(other), other.constraint_residual(STATE[0], q_dot, 0.0)
    assert close(s_ddot, particle_s_ddot(reference))
    assert close(residual, reference.constraint_residual(STATE[0], q_dot, 0.0))
    changed = not close(s_ddot, particle_s_ddot(base)) or not close(residual, base.constraint_residual(
        STATE[0], q_dot, 0.0))
    assert changed


def test_joints_from_one_derivation_keep_their_own_placement_and_expressions():
    """Three particles from one derivation: the first (a = 1), the second on the first, placed and
    turned, another q0, and a third with a = 2 on the first: each keeps its parent, q0, r_pn,
    orientation and parameter, changing one's expressions leaves the other and the next build
    alone, and the system's s̈ is the one of the same joints each derived afresh."""
    turn = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    placements = {"one": {"q0": (0.1, 0.2, 0.3)},
                  "two": {"parent": "one", "q0": (-0.4, 0.0, 0.5), "r_pn": (0.3, 0.0, 0.2), "orientation": turn},
                  "three": {"a_value": 2.0, "parent": "one", "r_pn": (0.0, 0.1, 0.0)}}

    def s_ddot(joints):
        system = pq.System({n: pq.RigidBody(1.0, (0.1, 0.0, 0.0), np.diag([0.1, 0.2, 0.3])) for n in joints},
                           joints, gravity=(0.0, 0.0, -9.81))
        q = np.concatenate([STATE[0], STATE[0] + 0.1, STATE[0] - 0.2])
        return system.accelerations(q, np.concatenate([STATE[1], -STATE[1], 2 * STATE[1]]), method="recursive")

    derive.cache_clear()
    shared = {name: particle_joint(**placement) for name, placement in placements.items()}
    assert (derive.cache_info().misses, derive.cache_info().hits) == (1, 2)
    one, two = shared["one"], shared["two"]
    assert one.compiled_values() is two.compiled_values()
    assert (one.parent, two.parent) == (None, "one")
    assert np.array_equal(one.default_q(), [0.1, 0.2, 0.3]) and np.array_equal(two.default_q(), [-0.4, 0.0, 0.5])
    assert np.array_equal(one.r_pn, [0.0, 0.0, 0.0]) and np.array_equal(two.r_pn, [0.3, 0.0, 0.2])
    assert np.array_equal(one.orientation, np.eye(3)) and np.array_equal(two.orientation, turn)
    F = one.symbols["F"].copy()
    two.symbols["F"][1, 0] = 7
    assert one.symbols["F"] == F and particle_joint().symbols["F"] == F
    assert shared["three"].symbols["F"] == F.xreplace({z: 2 * z})
    separately = {name: fresh(lambda: particle_joint(**placement)) for name, placement in placements.items()}
    assert close(s_ddot(shared), s_ddot(separately))

"""The Whipple bicycle's s̈ in one compiled call (projeq.constraints.compiled): Pfaffian rows A(q) q̇ = 0
next to Φ, and a UserJoint from sympy stating its relative motion by compiled code, give the s̈_tree
of the numpy path (the complex step of A and Φ″'s stencil in numpy, the joint's own
``relative_values``) and of the dense reference form (Σ J_nᵀ M_n J_n, docs/theory.md §5, an
independent formulation of M and b) to round-off, at random states on Φ = 0; the expressions
printed for numba (:mod:`projeq.symbolic.codegen`) give the numbers of the expressions themselves."""

import warnings

import numpy as np
import pytest
import sympy as sp

import projeq as pq
from projeq.assembly.given import generated_module
from projeq.constraints import compiled
from projeq.constraints.compiled import CompiledClosure
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.joints import UserJoint
from projeq.scenes.bicycle import _contact_expressions
from projeq.symbolic import codegen

# the same stencils and the same M, b summed in another order: measured ≤ 2.6e-15 of
# max(1, |s̈_tree|∞) on the bicycle (partitioned, tangent and dense); 10× that (was 1e-13)
RTOL = 2.6e-14


def _close(a, b) -> bool:
    return bool(np.abs(a - b).max(initial=0.0) <= RTOL * max(1.0, np.abs(b).max(initial=0.0)))


@pytest.fixture(scope="module")
def bike():
    return pq.scenes.whipple_bicycle(speed=4.0, roll=0.05, steer=0.02, roll_rate=0.3)


def _states(bike, count=4):
    """Random states on Φ = 0 (q projected), away from upright straight running."""
    rng = np.random.default_rng(17)
    for _ in range(count):
        q = bike.project(bike.q0 + 0.2 * rng.standard_normal(bike.n_q))
        yield q, bike.s_dot0 + 2.0 * rng.standard_normal(bike.n_s), float(rng.uniform(0, 1))


def test_the_bicycles_compiled_call_gives_the_numpy_paths_and_the_dense_accelerations(bike):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert compiled.unsupported(bike) is None and bike.compiled_kernel() is not None
        assert "one compiled call" in bike.evaluator().reason
    for q, s_dot, t in _states(bike):
        found, A_s, M, b = bike.compiled_kernel().accelerations(bike, q, s_dot, t)
        reference, A_ref, M_ref, b_ref = bike._projected_accelerations(q, s_dot, t, None)
        assert _close(found, reference)
        assert _close(A_s, A_ref) and _close(M, M_ref) and _close(b, b_ref)
        assert _close(found, bike.accelerations_tree(q, s_dot, t, method="dense")[0])
        x_dot = bike.evaluator().state_derivative(t, np.concatenate((q, s_dot)))  # simulate's right-hand side
        assert _close(x_dot, np.concatenate((bike.q_dot(q, s_dot, t), reference[bike.independent])))


def test_the_kernel_interpreted_gives_the_compiled_numbers(bike):
    """The kernel's source as plain Python (Φ, A and the joint's generated function themselves) is the
    compiled algorithm step by step."""
    interpreted = CompiledClosure(bike.tree, bike.n_c, bike._phi, "partitioned", (1e8,), compiled=False,
                                  m_h=bike.m_h, pfaffian=bike._A)
    for q, s_dot, t in _states(bike, 2):
        expected = bike.compiled_kernel().accelerations(bike, q, s_dot, t)
        assert all(_close(a, b) for a, b in zip(interpreted.accelerations(bike, q, s_dot, t), expected))


def test_a_simulation_by_the_compiled_right_hand_side_equals_the_numpy_paths():
    """0.5 s of the weaving bicycle ends where the numpy path's right-hand side takes it: the two differ
    by round-off per call, the runs by 2.7e-15 in q and 3.6e-15 in ṡ (at most 8.9e-15 and 7.1e-15 at
    5 m/s, over 1 s and at rtol 1e-9; the bounds are 10 times those, were 1e-8 and 1e-7)."""
    runs = []
    for compiled_call in (True, False):
        model = pq.scenes.whipple_bicycle(speed=4.0, roll_rate=0.5)
        if not compiled_call:
            model._compiled = None  # the numpy path
        assert hasattr(model.evaluator(), "state_derivative") == compiled_call
        runs.append(pq.simulate(model, 0.5, rtol=1e-10, atol=1e-12))
    assert np.abs(runs[0].q[-1] - runs[1].q[-1]).max() < 9e-14
    assert np.abs(runs[0].s_dot[-1] - runs[1].s_dot[-1]).max() < 7.1e-14


def test_the_printed_contact_expressions_are_the_expressions():
    """Φ and A printed by numeric_function (numpy, and compiled by numba at complex points, the
    complex step's) equal sympy's own evaluation of the same expressions to round-off."""
    import numba

    q, constants, phi, A = _contact_expressions()
    values = dict(zip(constants, (0.3, 0.35, 0.31, 0.95, 1.1, 0.3, -0.08, -0.35)))
    arguments = [("q", list(q)), ("t", sp.Symbol("t"))]
    rng = np.random.default_rng(4)
    for expressions in (phi, A):
        function = codegen.numeric_function("f", arguments, expressions, constants)(*values.values())
        jitted = numba.njit(function)
        for point in rng.standard_normal((2, 8)):
            exact = np.array(expressions.xreplace(values).xreplace(dict(zip(q, point))).evalf(30), dtype=float)
            exact = exact.reshape(np.shape(function(point, 0.0)))
            assert np.abs(function(point, 0.0) - exact).max() <= 1e-14 * max(1.0, np.abs(exact).max())
            z = point + 1e-30j * rng.standard_normal(8)
            assert np.array_equal(jitted(z, 0.0).real, function(z, 0.0).real)
            assert np.allclose(jitted(z, 0.0).imag, function(z, 0.0).imag, rtol=1e-14, atol=1e-44)


def test_a_user_joints_compiled_values_are_its_relative_values():
    """UserJoint.compiled_values: the same A, r, w, ζ, F⁶ as the joint's relative_values (scalar
    code of the same expressions), for the bicycle's rear frame and the rolling disk's joint."""
    import numba

    joints = [pq.scenes.whipple_bicycle().tree.joints[0], pq.scenes.rolling_disk().joints[0]]
    rng = np.random.default_rng(8)
    for joint in joints:
        values = numba.njit(joint.compiled_values())
        for _ in range(3):
            q_n, s_n, t = joint.default_q() + 0.3 * rng.standard_normal(joint.n_q), rng.standard_normal(joint.n_s), 0.4
            expected = np.concatenate((joint.relative_values(q_n, s_n, t), joint.q_dot(q_n, s_n, t)))
            assert np.abs(values(q_n, s_n, t) - expected).max() <= 1e-14 * max(1.0, np.abs(expected).max())
    assert joints[0].rates_are_speeds and not joints[1].rates_are_speeds  # the disk's K ≠ E


@pytest.mark.parametrize("constraints, why", [
    ({"A": lambda q, t: np.array([[0.0, 1.0, 0.0]]), "b": lambda q, t: [0.5]}, "b ≠ 0"),
    ({"A": lambda q, t: np.array([[t, 1.0, 0.0]])}, "A depending on t"),
    ({"A": lambda q, t: np.array([[t * q[1], 1.0, 0.0]])}, "A depending on t"),  # not at q0 = 0: around it
])
def test_rheonomic_pfaffian_rows_keep_the_numpy_path_saying_why(constraints, why):
    model = pq.System({"x": pq.PointMass(1.0), "y": pq.PointMass(1.0), "z": pq.PointMass(1.0)},
                      {"x": pq.Prismatic(axis="x"), "y": pq.Prismatic(parent="x", axis="y"),
                       "z": pq.Prismatic(parent="y", axis="z")})
    model = ConstrainedSystem(model, phi=lambda q, t: [q[0] - q[2]], q0=[0.0, 0.0, 0.0], **constraints)
    assert why in compiled.unsupported(model)
    assert model.compiled_kernel() is None


class _Turn:
    """A Python object numba cannot read: its method gives the hub's motion."""

    def motion(self, t):
        return 0.3 * t, 0.3, 0.0


def test_a_joint_stating_its_motion_in_python_keeps_the_numpy_path_saying_why():
    """A Prescribed joint (kind GIVEN) whose motion calls a Python object's method, which numba cannot
    compile, has no compiled form."""
    turn = _Turn()
    hub = pq.Prescribed(pq.Revolute(axis="z"), lambda t: turn.motion(t))
    tree = pq.System({"hub": pq.RigidBody(1.0, (0, 0, 0), np.eye(3)), "x": pq.PointMass(1.0), "y": pq.PointMass(1.0)},
                     {"hub": hub, "x": pq.Prismatic(parent="hub", axis="x"), "y": pq.Prismatic(parent="x", axis="y")})
    model = ConstrainedSystem(tree, phi=lambda q, t: [q[0] - q[1] ** 2 - 0.5], q0=[0.5, 0.0])
    assert "in Python" in compiled.unsupported(model)
    assert model.compiled_kernel() is None


def test_the_tangent_kernel_takes_the_pfaffian_rows_too(bike):
    """TangentSystem (F = N N_ind⁻¹ from the null space of A_s) of the same bicycle: the compiled
    call gives its numpy path's s̈_tree (the tangent kept along the branch reset before each, so that
    both start from the same null space)."""
    from projeq.constraints.partitioned import TangentSystem

    model = TangentSystem(bike.tree, phi=bike._phi, A=bike._A, independent=bike.independent, q0=bike.q0,
                          s_dot0=bike.s_dot0)
    assert model.compiled_kernel() is not None
    for q, s_dot, t in _states(bike, 3):
        model._tangent = None
        found = model.accelerations_tree(q, s_dot, t)[0]
        model._tangent = None
        assert _close(found, model._projected_accelerations(q, s_dot, t, None)[0])


def test_a_printed_function_is_compiled_from_a_module_file_numba_caches(bike):
    """Φ printed by codegen compiles from a generated module file (numba's disk cache needs one), whose
    compiled function gives Φ's own numbers, and whose C callback is the one the kernel calls."""
    from pathlib import Path

    module = generated_module(bike._phi, compiled._ROWS_INTO.format(n=bike.n_q, size=1))
    assert Path(module.__file__).is_file() and Path(module.__file__).parent.name == "generated"
    x = bike.q0 + 0.1 + 1e-30j
    assert np.array_equal(module.function(x, 0.0).real, bike._phi(x, 0.0).real)
    assert compiled.closure_callback(bike._phi, bike.n_q, 1, bike.q0) is module.into

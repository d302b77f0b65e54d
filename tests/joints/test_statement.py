"""A joint's one statement runs three ways, and they agree (projeq/joints/statement.py).

Four joints each stated once as ``statement(q, t, m)``: a screw (pose and a constant F⁶),
projeq's Cylindrical (two freedoms), and, not shipped, a slider on a turntable turning at a
given rate (rheonomic: f⁶ depends on q, so ζ has ∂f/∂q q̇ + ∂f/∂t), and a knife edge (Bremer's
non-holonomic minimal velocities, q̇ = K(q) ṡ with K not integrable). The references are
independent of the statement's derivations: the pose's own time derivative
(``pose_twist_mismatch``, central differences), sympy's ``lambdify`` of the traced form (not
projeq's printer), and the Gauss form against the order-n elimination.
"""

import ctypes
import math
import warnings

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import projeq as pq
from projeq.assembly import InterpretedWarning, PythonPieceWarning, given as given_joints, kernels
from projeq.joints import Stated, pose_twist_mismatch
from projeq.joints.user_compiler import joint_symbols, row_expressions

HAS_NUMBA = kernels.has_numba()
OMEGA = 1.7  # rad/s, the turntable's rate


class Screw(pq.Joint):
    """Rotation θ about the unit axis e with the advance λ θ along it."""

    n_q = n_s = 1

    def __init__(self, parent=None, axis=(0.0, 0.0, 1.0), lead=0.05, r_pn=(0.0, 0.0, 0.0)):
        super().__init__(parent, r_pn)
        self.e, self.lead = np.asarray(axis, float) / np.linalg.norm(axis), float(lead)

    def statement(self, q, t, m):
        return Stated(A=m.rotation(self.e, q[0]), r=self.lead * q[0] * m.vector(self.e),
                      F=m.columns(m.vector([*(self.lead * self.e), *self.e])))


class Turntable(pq.Joint):
    """A slider along the x axis of a table turning at the rate Ω about z: A = R_z(Ω t),
    r = A (x, 0, 0); in child coordinates v = (ẋ, Ω x, 0), ω = (0, 0, Ω): f⁶ = (0, Ω x, 0, 0, 0, Ω)."""

    n_q = n_s = 1

    def statement(self, q, t, m):
        c, s = m.cos(OMEGA * t), m.sin(OMEGA * t)
        A = m.matrix([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        return Stated(A=A, r=A @ m.vector([q[0], 0.0, 0.0]), F=m.columns(m.vector([1.0, 0, 0, 0, 0, 0])),
                      f=m.vector([0.0, OMEGA * q[0], 0.0, 0.0, 0.0, OMEGA]))


class KnifeEdge(pq.Joint):
    """A knife edge on the x–y plane: q = (x, y, θ), ṡ = (v, ω), the edge's speed along its own
    x axis and its spin; no sideways speed (q̇ = K(q) ṡ, K not integrable, as Bremer's car B(11))."""

    n_q, n_s = 3, 2

    def statement(self, q, t, m):
        c, s = m.cos(q[2]), m.sin(q[2])
        return Stated(A=m.matrix([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), r=m.vector([q[0], q[1], 0.0]),
                      F=m.columns(m.vector([1.0, 0, 0, 0, 0, 0]), m.vector([0.0, 0, 0, 0, 0, 1])),
                      K=m.matrix([[c, 0.0], [s, 0.0], [0.0, 1.0]]))


JOINTS = {
    "screw": lambda: Screw(axis=(0.3, -0.5, 0.8), lead=0.04),
    "cylindrical": lambda: pq.Cylindrical(axis=(1.0, 2.0, -0.5)),
    "turntable": Turntable,
    "knife_edge": KnifeEdge,
}


def _interpreted_row(joint, q, s_dot, t):
    return np.concatenate((joint.relative_values(q, s_dot, t), joint.q_dot(q, s_dot, t)))


def _compiled_row(joint, q, s_dot, t):
    """The row of the joint's C callback (given.joint_callback: its address and parameters), called through
    ctypes."""
    callback = given_joints.joint_callback(joint)
    row = np.zeros(given_joints.row_width(joint))
    pointer = ctypes.POINTER(ctypes.c_double)
    into = ctypes.CFUNCTYPE(None, pointer, pointer, ctypes.c_double, pointer, pointer)(callback.address)
    q, s_dot = np.ascontiguousarray(q, dtype=float), np.ascontiguousarray(s_dot, dtype=float)
    into(q.ctypes.data_as(pointer), s_dot.ctypes.data_as(pointer), t, callback.parameters.ctypes.data_as(pointer),
         row.ctypes.data_as(pointer))
    return row


def _lambdified_row(joint):
    """The traced form's row (A, r, w, ζ, F⁶, q̇) by sympy's own lambdify, ζ = d/dt (F ṡ + f)."""
    q, s, t = sp.symbols(f"q0:{joint.n_q}"), sp.symbols(f"s0:{joint.n_s}"), sp.Symbol("t")
    form = joint.symbolic_relative(list(q), list(s), t)
    row = row_expressions(joint_symbols(q, s, t, *(form.A, form.r, form.F, form.f, form.K, form.k)))
    return sp.lambdify([q, s, t], row, modules="numpy")


@pytest.mark.parametrize("name", JOINTS)
def test_the_statement_is_the_derivative_of_its_pose(name):
    """F⁶ ṡ + f⁶ equals the pose's time derivative along q̇ = K ṡ + k (central differences of
    step 1e-7: measured 8.2e-11 to 5.7e-9, the turntable's the largest; bound 5.7e-8, was 1e-7)."""
    joint, rng = JOINTS[name](), np.random.default_rng(7)
    for _ in range(3):
        q, s_dot, t = rng.uniform(-2, 2, joint.n_q), rng.uniform(-2, 2, joint.n_s), rng.uniform(0, 2)
        assert pose_twist_mismatch(joint, q, s_dot, t) < 5.7e-8


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
@pytest.mark.parametrize("name", JOINTS)
@settings(max_examples=25)
@given(seed=st.integers(0, 2**32 - 1))
def test_interpreted_compiled_and_traced_agree(name, seed):
    """The statement on numpy (ζ by the complex step), the compiled C callback and sympy's
    lambdify of the traced form give the same row at random (q, ṡ, t): measured ≤ 4.5e-16
    relative to the row's largest entry, bound 1e-13."""
    joint, rng = JOINTS[name](), np.random.default_rng(seed)
    q, s_dot, t = rng.uniform(-3, 3, joint.n_q), rng.uniform(-3, 3, joint.n_s), float(rng.uniform(-3, 3))
    interpreted = _interpreted_row(joint, q, s_dot, t)
    compiled = _compiled_row(joint, q, s_dot, t)
    traced = np.array(_lambdified_row(joint)(q, s_dot, t), dtype=float)
    scale = 1.0 + np.abs(interpreted).max()
    assert np.abs(compiled - interpreted).max() <= 1e-13 * scale
    assert np.abs(traced - interpreted).max() <= 1e-13 * scale


def _tree(kinds, seed):
    """A random tree of rigid bodies on the given joint kinds (each body's parent the previous one
    or an earlier one), under gravity."""
    rng = np.random.default_rng(seed)
    bodies, joints = {}, {}
    for i, kind in enumerate(kinds):
        name, parent = f"b{i}", None if i == 0 else f"b{int(rng.integers(max(0, i - 2), i))}"
        axis, offset = rng.standard_normal(3), rng.uniform(-0.5, 0.5, 3)
        joints[name] = {
            "screw": lambda: Screw(parent, axis, float(rng.uniform(0.01, 0.1)), offset),
            "cylindrical": lambda: pq.Cylindrical(parent, axis, offset),
            "turntable": lambda: Turntable(parent, offset),
            "knife_edge": lambda: KnifeEdge(parent, offset),
            "revolute": lambda: pq.Revolute(parent, axis / np.linalg.norm(axis), offset),
            "prismatic": lambda: pq.Prismatic(parent, axis / np.linalg.norm(axis), offset),
        }[kind]()
        J = rng.uniform(0.02, 0.2, 3)
        bodies[name] = pq.RigidBody(float(rng.uniform(0.5, 2)), r_c=rng.uniform(-0.3, 0.3, 3),
                                    I_c=np.diag([J[1] + J[2], J[0] + J[2], J[0] + J[1]]))
    return pq.System(bodies, joints, gravity=(0.0, 0.0, -9.81))


KINDS = ("screw", "cylindrical", "turntable", "knife_edge", "revolute", "prismatic")


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
@settings(max_examples=30)
@given(kinds=st.lists(st.sampled_from(KINDS), min_size=1, max_size=6), seed=st.integers(0, 2**32 - 1))
def test_random_trees_of_stated_joints_run_compiled_and_agree(kinds, seed):
    """Whole trees of stated and built-in joints: the default evaluator is the compiled kernel
    with no piece in Python and no warning, and its s̈ equals the recursive (order-n, the
    statement on numpy) and dense Gauss forms, relative to 1 + |s̈|: compiled 100 ε (measured ≤ 2.1e-15),
    dense 7.3e-14 (measured ≤ 7.3e-15, κ(M) = 143; the largest over 1150 random trees drawn as here; both
    were 1e-10)."""
    system = _tree(kinds, seed)
    rng = np.random.default_rng(seed)
    q, s_dot, t = rng.uniform(-1, 1, system.n_q), rng.uniform(-1, 1, system.n_s), float(rng.uniform(0, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        warnings.simplefilter("error", PythonPieceWarning)
        default = system.evaluator()
    assert default.name == "fast" and default.evaluator.interpreted == []
    compiled = default.accelerations(q, s_dot, t)
    recursive = system.accelerations(q, s_dot, t, method="recursive")
    dense = system.accelerations(q, s_dot, t, method="dense")
    scale = 1.0 + np.abs(recursive).max()
    eps = np.finfo(float).eps
    assert np.abs(compiled - recursive).max() <= 100 * eps * scale, (compiled - recursive) / scale
    assert np.abs(dense - recursive).max() <= 7.3e-14 * scale, (dense - recursive) / scale


def test_the_gauss_form_is_traced_from_the_statements():
    """gauss_form (the statements traced with sympy, lambdified) = the order-n elimination on a
    cylindrical joint carrying a knife edge and a turntable slider: measured 1.4e-15, bound 100 ε = 2.2e-14
    (of 1 + |s̈|; was 1e-12)."""
    system = _tree(("cylindrical", "knife_edge", "turntable"), 3)
    symbolic = pq.symbolic.gauss_form(system).evaluator()
    rng = np.random.default_rng(4)
    q, s_dot = rng.uniform(-1, 1, system.n_q), rng.uniform(-1, 1, system.n_s)
    reference = system.accelerations(q, s_dot, 0.4, method="recursive")
    error = np.abs(symbolic.accelerations(q, s_dot, 0.4) - reference).max() / (1 + np.abs(reference).max())
    assert error <= 100 * np.finfo(float).eps, error


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
def test_the_exact_jacobian_of_a_stated_tree():
    """∂ẋ/∂x by the complex step through the compiled model (one call) against Richardson-extrapolated
    central differences of q̇ and the recursive evaluator (truncation O(h⁴)), relative to 1 + |J|:
    measured 4.2e-12, bound 4.2e-11 (was 1e-7)."""
    from projeq.analysis.differentiation import jacobian
    from projeq.analysis.jacobians import state_jacobian

    system = _tree(("knife_edge", "screw", "cylindrical"), 5)
    rng = np.random.default_rng(6)
    x = np.concatenate((rng.uniform(-1, 1, system.n_q), rng.uniform(-1, 1, system.n_s)))
    J, how = state_jacobian(system, x, 0.2)

    def x_dot(z):  # the statements on numpy: q̇ and the order-n elimination
        q, s_dot = z[:system.n_q], z[system.n_q:]
        return np.concatenate((system.q_dot(q, s_dot, 0.2), system.accelerations(q, s_dot, 0.2, method="recursive")))

    reference = jacobian(x_dot, x)
    error = np.abs(J - reference).max() / (1 + np.abs(reference).max())
    assert how == "exact" and error <= 4.2e-11, error


class SteeperScrew(Screw):
    """A subclass that restates the statement: twice the lead."""

    def statement(self, q, t, m):
        found = super().statement(q, t, m)
        return found._replace(r=2.0 * found.r, F=m.columns(m.vector([*(2 * self.lead * self.e), *self.e])))


class ScrewInPython(Screw):
    """A subclass that restates ``relative`` only: it has no statement of its own."""

    def relative(self, q_n, s_dot_n, t):
        return super().relative(q_n, s_dot_n, t)


def _nut(joint):
    nut = pq.RigidBody(2.0, I_c=np.diag([0.02, 0.02, 0.01]))
    return pq.System({"nut": nut}, {"nut": joint}, gravity=(0.0, 0.0, -9.81), q0=[0.3], s_dot0=[2.0])


def test_an_overridden_statement_gives_every_form():
    """θ̈ = −m g λ / (m λ² + J_z) with λ the subclass's own lead (2 λ), in the recursive, dense and
    symbolic forms (measured 0 to 2e-16 relative, bound 100 ε; was 1e-12)."""
    system = _nut(SteeperScrew(lead=0.005))
    theta_ddot = -2.0 * 9.81 * 0.01 / (2.0 * 0.01**2 + 0.01)
    for method in ("recursive", "dense"):
        assert system.accelerations(system.q0, system.s_dot0, method=method)[0] == pytest.approx(
            theta_ddot, rel=100 * np.finfo(float).eps)
    symbolic = pq.symbolic.gauss_form(system).evaluator()
    assert symbolic.accelerations(system.q0, system.s_dot0)[0] == pytest.approx(theta_ddot, rel=100 * np.finfo(float).eps)


def test_an_overridden_relative_is_never_bypassed():
    """A subclass that restates ``relative`` loses the traced forms (its statement may no longer
    be its motion): no compiled values, gauss_form refuses it by name, and the default evaluator
    says once that the joint runs in Python."""
    joint = ScrewInPython()
    assert joint.compiled_values() is None
    with pytest.raises(NotImplementedError):
        joint.symbolic_relative([sp.Symbol("q")], [sp.Symbol("s")], sp.Symbol("t"))
    if HAS_NUMBA:
        with warnings.catch_warnings(record=True) as said:
            warnings.simplefilter("always")
            evaluator = _nut(joint).evaluator()
        assert [type(w.message) for w in said] == [PythonPieceWarning]
        assert "joint 'nut' (ScrewInPython) run in Python" in str(said[0].message)
        assert "statement(q_n, t, m)" in str(said[0].message)
        assert "ScrewInPython" in evaluator.reason and "knows every" not in evaluator.reason


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
def test_a_force_law_in_python_is_named_once():
    """A user's force law (no compiled row) runs between the compiled kernels: one warning naming
    it and saying how to compile the loads."""

    class Push(pq.ForceLaw):
        def bind(self, system):
            self.index = system.index("nut")
            return self

        def add_to(self, h, kin, t, q, s_dot):
            h[self.index][2] += 1.0

        def potential(self, kin, q):
            return 0.0

    system = pq.System({"nut": pq.RigidBody(2.0, I_c=np.eye(3))}, {"nut": Screw(lead=0.01)}, forces=[Push()])
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        system.evaluator()
        system.evaluator()
    assert [type(w.message) for w in said] == [PythonPieceWarning]
    assert "force law Push" in str(said[0].message) and "projeq.forces" in str(said[0].message)
    assert math.isfinite(system.accelerations([0.1], [0.2])[0])

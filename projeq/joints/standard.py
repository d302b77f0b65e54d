"""The standard joints: Revolute, Prismatic, Fixed, Planar, Free, Prescribed, Cylindrical, Universal
and Spherical (docs/theory.md §4).

Revolute, Prismatic, Fixed, Planar, Free and Prescribed state their relative kinematics (A, r, F⁶,
w, ζ) in ``relative``, next to it their sympy form in ``symbolic_relative`` and, where the compiled
kernel has the same kinematics, its ``compiled_kind``; Cylindrical, Universal and Spherical state
them once, in ``statement`` (:mod:`projeq.joints.statement`). See :mod:`projeq.joints.base` for the
contract.
"""

from __future__ import annotations

import functools
import math

from typing import Callable, NamedTuple

import numpy as np

from projeq.checks import callable_name
from projeq.joints import statement
from projeq.joints.base import Joint, Relative, SymbolicRelative
from projeq.joints.statement import Stated
from projeq.spatial import axis_spin, cross, norm, numeric, quaternion_matrix, quaternion_rate_matrix, rodrigues, unit_axis
from projeq.symbolic import lazy_import

sp = lazy_import("sympy")
algebra = lazy_import("projeq.symbolic.algebra")

_ZERO6 = np.zeros(6)
_ZERO6.flags.writeable = False


def _scleronomic(A, r, F, K) -> SymbolicRelative:
    """A SymbolicRelative without rheonomic terms (f = 0, k = 0)."""
    return SymbolicRelative(A, r, F, sp.zeros(6, 1), K, sp.zeros(K.rows, 1))


class _OneAxis(Joint):
    """Shared part of the one-dof joints along or about a unit axis e (joint-frame coordinates)."""

    n_q = 1
    n_s = 1

    def __init__(self, parent=None, axis="z", r_pn=(0.0, 0.0, 0.0), orientation=None, coupling=None):
        super().__init__(parent, r_pn, orientation, coupling)
        self.axis = unit_axis(axis, "axis")


class Revolute(_OneAxis):
    """Rotation θ about the unit axis e through O_n: F⁶ = [0; e] (docs/theory.md §4).

    θ is positive by the right-hand rule about e; q = ṡ-integral = (θ,).
    """

    compiled_kind = "revolute"

    def coordinates(self):
        return (("angle", "rad"),)

    def velocities(self):
        return (("angle_dot", "rad/s"),)

    def __init__(self, parent=None, axis="z", r_pn=(0.0, 0.0, 0.0), orientation=None, coupling=None):
        super().__init__(parent, axis, r_pn, orientation, coupling)
        self._spin = axis_spin(self.axis)
        self._F = np.concatenate((np.zeros(3), self.axis))[:, None]

    def relative(self, q_n, s_dot_n, t):
        A = rodrigues(self._spin, q_n[0])
        return Relative(A, _ZERO6[:3], self._F, self._F[:, 0] * s_dot_n[0], _ZERO6)

    def symbolic_relative(self, q_n, s_n, t):
        e = algebra.exact(self.axis)
        return _scleronomic(algebra.rotation(e, q_n[0]), sp.zeros(3, 1), sp.Matrix.vstack(sp.zeros(3, 1), e), sp.eye(1))


class Prismatic(_OneAxis):
    """Translation x along the unit axis e: F⁶ = [e; 0], r = e x (docs/theory.md §4)."""

    compiled_kind = "prismatic"

    def coordinates(self):
        return (("position", "m"),)

    def velocities(self):
        return (("position_dot", "m/s"),)

    def __init__(self, parent=None, axis="z", r_pn=(0.0, 0.0, 0.0), orientation=None, coupling=None):
        super().__init__(parent, axis, r_pn, orientation, coupling)
        self._F = np.concatenate((self.axis, np.zeros(3)))[:, None]

    def relative(self, q_n, s_dot_n, t):
        return Relative(np.eye(3), self.axis * q_n[0], self._F, self._F[:, 0] * s_dot_n[0], _ZERO6)

    def symbolic_relative(self, q_n, s_n, t):
        e = algebra.exact(self.axis)
        return _scleronomic(sp.eye(3), e * q_n[0], sp.Matrix.vstack(e, sp.zeros(3, 1)), sp.eye(1))


class Fixed(Joint):
    """A rigid connection: no coordinates; the child is the joint frame."""

    _F = np.zeros((6, 0))
    compiled_kind = "fixed"

    def relative(self, q_n, s_dot_n, t):
        return Relative(np.eye(3), _ZERO6[:3], self._F, _ZERO6, _ZERO6)

    def symbolic_relative(self, q_n, s_n, t):
        return _scleronomic(sp.eye(3), sp.zeros(3, 1), sp.zeros(6, 0), sp.zeros(0, 0))


class Planar(Joint):
    """Three dof in a plane of the joint frame: q = (a, b, θ), ṡ = (v_a, v_b, ω).

    (a, b) locate O_n along the plane's first and second axis, θ turns about its normal.
    The minimal velocities are the relative velocity of O_n and the spin in *child*
    coordinates, so F⁶ is constant and K(q) rotates (v_a, v_b) into the joint frame —
    Bremer's car (B(11)) is this joint with the lateral velocity v_b = 0 removed.
    """

    n_q = 3
    n_s = 3
    _AXES = {"xy": (0, 1, 2), "yz": (1, 2, 0), "zx": (2, 0, 1), "xz": (0, 2, 1)}

    def __init__(self, parent=None, plane="xy", r_pn=(0.0, 0.0, 0.0), orientation=None):
        super().__init__(parent, r_pn, orientation)
        if plane not in self._AXES:
            raise ValueError(f"plane: unknown plane {plane!r}; use one of {sorted(self._AXES)}")
        self.plane = plane
        a, b, n = (np.eye(3)[i] for i in self._AXES[plane])
        self._P = np.array([a, b])
        self.normal = n
        self._spin = axis_spin(n)
        self._F = np.zeros((6, 3))
        self._F[:3, 0], self._F[:3, 1], self._F[3:, 2] = a, b, n

    def coordinates(self):
        return (("a", "m"), ("b", "m"), ("angle", "rad"))

    def velocities(self):  # the velocity of O_n along the child's axes a, b and the spin
        return (("v_a", "m/s"), ("v_b", "m/s"), ("omega", "rad/s"))

    def _A(self, theta):
        return rodrigues(self._spin, theta)

    def relative(self, q_n, s_dot_n, t):
        r = self._P.T @ q_n[:2]
        return Relative(self._A(q_n[2]), r, self._F, self._F @ s_dot_n, _ZERO6)

    def K(self, q_n, t):
        A = self._A(q_n[2])
        K = np.zeros((3, 3), dtype=A.dtype)
        K[:2, :2] = self._P @ A @ self._P.T
        K[2, 2] = 1.0
        return K

    def symbolic_relative(self, q_n, s_n, t):
        P = algebra.exact(self._P)
        A = algebra.rotation(algebra.exact(self.normal), q_n[2])
        return _scleronomic(A, algebra.mul(P.T, sp.Matrix(q_n[:2])), algebra.exact(self._F), sp.diag(algebra.mul(P, A, P.T), 1))


class Free(Joint):
    """Six dof: q = (r, quaternion (w, x, y, z)), ṡ = (v, ω) of the child in child coordinates.

    F⁶ = E₆; ṙ = A v and q̇_quat = ½ quat ⊗ (0, ω) (no Euler-angle singularity). The
    quaternion is normalised wherever the pose is evaluated and in simulation output.
    """

    n_q = 7
    n_s = 6
    _F = np.eye(6)

    def relative(self, q_n, s_dot_n, t):
        A = quaternion_matrix(q_n[3:] / norm(q_n[3:]))
        return Relative(A, q_n[:3], self._F, s_dot_n, _ZERO6)

    def K(self, q_n, t):
        quat = q_n[3:] / norm(q_n[3:])
        K = np.zeros((7, 6), dtype=quat.dtype)
        K[:3, :3] = quaternion_matrix(quat)
        K[3:, 3:] = quaternion_rate_matrix(quat)
        return K

    def compiled_values(self):
        """:meth:`projeq.joints.base.Joint.compiled_values` printed from :meth:`symbolic_relative` with the
        quaternion q/√(qᵀq) put in (as :meth:`relative` and :meth:`K` normalise it: the same numbers
        off the unit sphere, and the same derivatives)."""
        return statement.printed(self, unit=range(3, 7))

    def symbolic_relative(self, q_n, s_n, t):
        """With the quaternion taken as unit (the numeric joint normalises it)."""
        A = algebra.quaternion_matrix(q_n[3:])
        return _scleronomic(A, sp.Matrix(q_n[:3]), sp.eye(6), sp.diag(A, algebra.quaternion_rate_matrix(q_n[3:])))

    def coordinates(self):
        return tuple((f"r_{a}", "m") for a in "xyz") + tuple((f"quat_{a}", "") for a in "wxyz")

    def velocities(self):  # (v, ω) of the child in child coordinates
        return tuple((f"v_{a}", "m/s") for a in "xyz") + tuple((f"omega_{a}", "rad/s") for a in "xyz")

    def default_q(self):
        return np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])

    def normalized(self, q_n):
        """The quaternion divided by its length √(qᵀq) (analytic: a complex step passes)."""
        out = numeric(np.array(q_n))
        out[3:] /= norm(out[3:])
        return out


class Cylindrical(Joint):
    """Rotation θ about and translation z along the unit axis e through O_n (joint-frame
    coordinates): q = (θ, z), ṡ = (θ̇, ż), F⁶ = [[0, e], [e, 0]] (A e = e, so the same in child
    and joint-frame coordinates); a Revolute and a Prismatic about one axis in one joint."""

    n_q = n_s = 2

    def __init__(self, parent=None, axis="z", r_pn=(0.0, 0.0, 0.0), orientation=None):
        super().__init__(parent, r_pn, orientation)
        self.axis = unit_axis(axis, "axis")

    def statement(self, q, t, m):
        zero = (0.0, 0.0, 0.0)
        return Stated(A=m.rotation(self.axis, q[0]), r=q[1] * m.vector(self.axis),
                      F=m.columns(m.vector([*zero, *self.axis]), m.vector([*self.axis, *zero])))

    def coordinates(self):
        return (("angle", "rad"), ("position", "m"))

    def velocities(self):
        return (("angle_dot", "rad/s"), ("position_dot", "m/s"))


class Universal(Joint):
    """Two rotations: θ₁ about the unit axis e₁ fixed in the joint frame, then θ₂ about the unit
    axis e₂ fixed in the child (the cross of a Cardan joint; e₁ ⟂ e₂ for a Cardan joint, any two
    axes that are not parallel allowed): A = R(e₁, θ₁) R(e₂, θ₂), q = (θ₁, θ₂), ṡ = (θ̇₁, θ̇₂).

    The child's angular velocity is ω = θ̇₁ R(e₂, θ₂)ᵀ e₁ + θ̇₂ e₂ in child coordinates, so
    F⁶ = [[0, 0], [R(e₂, θ₂)ᵀ e₁, e₂]]: two Revolutes on a massless Frame in one joint.
    """

    n_q = n_s = 2

    def __init__(self, parent=None, axes=("x", "y"), r_pn=(0.0, 0.0, 0.0), orientation=None):
        super().__init__(parent, r_pn, orientation)
        if isinstance(axes, str) or len(axes) != 2:
            raise ValueError(f"axes: expected two axes (e₁ in the joint frame, e₂ in the child), got {axes!r}")
        first, second = unit_axis(axes[0], "axes[0]"), unit_axis(axes[1], "axes[1]")
        if norm(cross(first, second)) < 1e-6:
            raise ValueError(f"axes: e₁ = {first} and e₂ = {second} are parallel; a universal joint turns about "
                             "two different axes (one axis: a Revolute)")
        self.axes = np.array([first, second])

    def statement(self, q, t, m):
        first, second = self.axes
        turn = m.rotation(second, q[1])
        first_in_child = turn.T @ m.vector(first)
        zero = (0.0, 0.0, 0.0)
        return Stated(A=m.rotation(first, q[0]) @ turn, r=m.zeros(3),
                      F=m.columns(m.vector([*zero, *first_in_child]), m.vector([*zero, *second])))

    def coordinates(self):
        return (("angle_1", "rad"), ("angle_2", "rad"))

    def velocities(self):
        return (("angle_1_dot", "rad/s"), ("angle_2_dot", "rad/s"))


class Spherical(Joint):
    """Three rotations about O_n (a ball joint): q = the unit quaternion (w, x, y, z) of the child
    relative to the joint frame, ṡ = ω, the child's angular velocity in child coordinates.

    F⁶ = [[0], [E₃]] and q̇ = ½ q ⊗ (0, ω) = Γ(q) ω, as Free does for its rotation (no Euler-angle
    singularity). The statement divides the quaternion by its length √(qᵀq) wherever it is read,
    so a quaternion that drifts off the unit sphere in integration still gives a rotation.
    """

    n_q, n_s = 4, 3

    def statement(self, q, t, m):
        length = m.sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2 + q[3] ** 2)
        w, x, y, z = (q[i] / length for i in range(4))
        rows = [[0.0] * 3] * 3 + [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        rate = [[-x, -y, -z], [w, -z, y], [z, w, -x], [-y, x, w]]  # 2 Γ(q): quaternion_rate_matrix
        return Stated(A=m.quaternion_matrix([w, x, y, z]), r=m.zeros(3), F=m.matrix(rows),
                      K=m.matrix([[entry / 2 for entry in row] for row in rate]))

    def coordinates(self):
        return tuple((f"quat_{a}", "") for a in "wxyz")

    def velocities(self):  # ω of the child in child coordinates
        return tuple((f"omega_{a}", "rad/s") for a in "xyz")

    def default_q(self):
        return np.array([1.0, 0.0, 0.0, 0.0])

    def normalized(self, q_n):
        """The quaternion divided by its length √(qᵀq) (analytic: a complex step passes)."""
        out = numeric(np.array(q_n))
        return out / norm(out)


class Prescribed(Joint):
    """A one-dof joint whose coordinate is a given function of time (rheonomic).

    ẏ_n = T_np ẏ_p + f⁶(t) with f⁶ = F⁶ θ̇(t), and ζ_n gains F⁶ θ̈(t) (docs/theory.md §4). The
    joint adds no coordinate and no minimal velocity.

    Parameters
    ----------
    joint : Revolute or Prismatic
        The joint whose coordinate θ is prescribed (its parent and placement are used).
    motion : sympy expression in ``t`` or callable
        θ(t) as an expression in the symbol ``t`` (θ̇, θ̈ by differentiation), or a callable
        ``t -> (θ, θ̇, θ̈)``; either runs compiled, a callable where numba compiles it (written with
        numpy and math on numbers and arrays; else it runs in Python, named once).
    """

    symbolic_parameters = {"motion": "its motion θ(t) as a sympy expression"}

    def __init__(self, joint: Joint, motion):
        if not isinstance(joint, _OneAxis) or joint.coupling:
            raise ValueError("joint: Prescribed needs an uncoupled Revolute or Prismatic joint")
        super().__init__(joint.parent, joint.r_pn, joint.orientation)
        self.joint = joint
        self.expression = None if callable(motion) else _expression(motion)  # θ(t) in sympy, or None
        self.motion = motion if callable(motion) else _time_function(self.expression)
        try:  # the callable's signature, shape and finiteness, checked once here
            self.angles(0.0)
        except TypeError as exc:
            raise ValueError(f"motion: {_label(self.motion)} must be callable as motion(t): {exc}") from exc

    def angles(self, t: float) -> tuple[float, float, float]:
        """(θ, θ̇, θ̈) at t, checked: ValueError naming the motion and t when they are not three
        finite numbers (complex at a complex t: the complex step through the motion)."""
        values = self.motion(t)
        number = complex if isinstance(t, complex) else float
        try:
            theta, theta_dot, theta_ddot = (number(v) for v in values)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"motion: {_label(self.motion)} must return three numbers (θ, θ̇, θ̈) at t = {t:.6g}, "
                             f"got {values!r}") from exc
        if not (math.isfinite(abs(theta)) and math.isfinite(abs(theta_dot)) and math.isfinite(abs(theta_ddot))):
            raise ValueError(f"motion: {_label(self.motion)} returned (θ, θ̇, θ̈) = {(theta, theta_dot, theta_ddot)} "
                             f"at t = {t:.6g}; they must be finite")
        return theta, theta_dot, theta_ddot

    def relative(self, q_n, s_dot_n, t):
        theta, theta_dot, theta_ddot = self.angles(t)
        inner = self.joint.relative(np.array([theta]), np.array([theta_dot]), t)
        zeta = inner.zeta + inner.F[:, 0] * theta_ddot
        return Relative(inner.A, inner.r, Fixed._F, inner.w, zeta)

    def symbolic_relative(self, q_n, s_n, t, motion):
        """The inner joint's kinematics at θ = ``motion`` (an expression in t): f = F θ̇."""
        inner = self.joint.symbolic_relative([motion], [], t)
        return SymbolicRelative(inner.A, inner.r, sp.zeros(6, 0), inner.F * motion.diff(t), sp.zeros(0, 0),
                                sp.zeros(0, 1))

    def compiled_values(self):
        """``values(q_n, ṡ_n, t)`` -> :meth:`relative_values` (A, r, w, ζ = ḟ), built once per joint: of
        a motion given in sympy, printed as scalar code that numba compiles, as a UserJoint's
        (:func:`projeq.joints.user_compiler.printed_values`); of a callable motion, its
        :class:`MotionValues` (the row printed at the callable's θ, θ̇, θ̈, which the compiled kernels
        take from the callable compiled, :func:`projeq.assembly.given.motion_callbacks`)."""
        if "_printed" in self.__dict__:
            return self._printed
        if self.expression is None:
            self._printed = MotionValues(moved_row(self), self.motion)
        else:
            t = sp.Symbol("t")
            inner = self.symbolic_relative([], [], t, self.expression)
            self._printed = statement.printed_form((), (), t, *(sp.ImmutableMatrix(e) for e in inner))()
        return self._printed


class MotionValues(NamedTuple):
    """The compiled values of a :class:`Prescribed` joint moved by a callable: ``row(θ, θ̇, θ̈)``, its
    row A, r, w = F⁶ θ̇, ζ = Ḟ⁶ θ̇ + F⁶ θ̈ (docs/theory.md §4) printed as scalar code that numba compiles
    (:func:`moved_row`), and ``motion``, the callable t -> (θ, θ̇, θ̈), which the compiled kernels call
    compiled (:func:`projeq.assembly.given.motion_callbacks`); called as ``values(q_n, ṡ_n, t)``, the
    row at the motion's values at t, in Python (the kernels interpreted)."""

    row: Callable
    motion: Callable

    def __call__(self, q_n, s_dot_n, t):
        return self.row(*self.motion(t))


def moved_row(joint: Prescribed):
    """``row(theta, theta_dot, theta_ddot)``: the row of ``joint``'s compiled values (A, r, w, ζ;
    :func:`projeq.joints.user_compiler.row_expressions`) with θ(t) and its rates as arguments, printed
    as scalar numpy code (:func:`projeq.symbolic.codegen.numeric_function`): the inner joint's
    kinematics at a function θ(t) (:meth:`Prescribed.symbolic_relative`), ζ = ḟ derived, then θ̈, θ̇,
    θ put in for d²θ/dt², dθ/dt and θ(t); printed once per kinematics in a process (a scene built
    again, a sweep of its motion's numbers)."""
    t = sp.Symbol("t")
    form = joint.symbolic_relative([], [], t, sp.Function("theta")(t))
    return _printed_row(*(sp.ImmutableMatrix(e) for e in form))


@functools.lru_cache(maxsize=64)
def _printed_row(A, r, F, f, K, k):
    """:func:`moved_row` of the sympy form (A, r, F, f, K, k) at θ(t)."""
    from projeq.joints.user_compiler import joint_symbols, row_expressions
    from projeq.symbolic import codegen

    t, angles = sp.Symbol("t"), sp.symbols("theta theta_dot theta_ddot")
    theta = sp.Function("theta")(t)
    symbols = joint_symbols((), (), t, A, r, F, f, K, k)
    rates = {theta.diff(t, 2): angles[2], theta.diff(t): angles[1], theta: angles[0]}
    expressions = [e.xreplace(rates) for e in row_expressions(symbols)]
    return codegen.numeric_function("moved_row", [(str(a), a) for a in angles], expressions)()


def _label(motion) -> str:
    return f"the prescribed motion {callable_name(motion)}"


def _expression(motion):
    """The motion θ(t) as a sympy expression in the symbol t, checked."""
    t = sp.Symbol("t")
    try:
        read = sp.sympify(motion)
    except (sp.SympifyError, SyntaxError, TypeError):
        read = None
    if not isinstance(read, sp.Expr):
        raise ValueError(f"motion: cannot read {motion!r} as an expression in t (a sympy expression or "
                         "a string such as '0.5*sin(2*t)'), or give a callable t -> (θ, θ̇, θ̈)")
    # the time under any assumptions (sp.Symbol("t", real=True)) is t
    expr = read.xreplace({symbol: t for symbol in read.free_symbols if symbol.name == "t"})
    extra = expr.free_symbols - {t}
    if extra:
        raise ValueError(f"motion: depends on {sorted(map(str, extra))}; only t is allowed")
    return expr


def _time_function(expr) -> Callable:
    """t ↦ (θ, θ̇, θ̈) of the expression θ(t), lambdified."""
    t = sp.Symbol("t")
    f = sp.lambdify(t, [expr, expr.diff(t), expr.diff(t, 2)], modules="numpy")
    return lambda time: tuple(f(time))  # complex at a complex t: Prescribed.angles keeps the complex step

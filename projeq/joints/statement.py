"""One statement per joint: its pose and minimal velocities as plain scalar code (docs/theory.md §4).

A joint states, once, in ``statement(q_n, t, m) -> Stated(A, r, F, f, K, k)``, the pose (A, r) of
its child relative to the joint frame, F⁶ (the relative twist (v, ω) per unit ṡ_n in child
coordinates) and, where they are not zero or the identity, the rheonomic twist f⁶ and the
kinematics q̇_n = K ṡ_n + k. The statement is written over a namespace ``m`` that the caller
chooses, in the style of Drake's mobilizers (one definition for double, AutoDiff and symbolic
scalars), and runs three ways:

- :data:`NUMERIC` (numpy, real or complex arrays): the interpreted reference, the ``relative``,
  ``K`` and ``q_dot`` the recursive and dense evaluators call, with ζ = Ḟ ṡ + ḟ by the complex
  step along (q̇, 1) through the same statement (:func:`relative`; exact to round-off, Squire &
  Trapp, SIAM Review 40, 1998), nested complex steps included;
- :data:`SYMBOLIC` (sympy): the traced form ``symbolic_relative`` that
  :func:`projeq.symbolic.gauss_form`, the Hamel and Lagrange comparisons and the operation counts
  read (:func:`traced`);
- compiled: the traced form printed as scalar code that numba compiles into the C callback the
  compiled kernels call (:func:`printed`, :mod:`projeq.assembly.given`), so a joint stated this
  way runs compiled by default.

``m`` offers the elementary functions (``sin``, ``cos``, ``tan``, ``sqrt``, ``exp``, ``log``,
``atan2``, ``pi``) and the constructors ``vector(entries)`` (a column), ``matrix(rows)``,
``columns(*vectors)`` (F⁶ from its columns), ``rotation(axis, angle)`` (Rodrigues, about a fixed
unit axis), ``quaternion_matrix(quat)``, ``eye(n)`` and ``zeros(rows, cols)``. Products are
``@`` and ``*`` as for numpy arrays and sympy matrices alike; constants (a joint's axis, its
lead) go in through ``vector``/``matrix``.

>>> import numpy as np
>>> def screw(q, t, m):  # rotation q[0] about z with the advance 0.1 q[0] along it
...     e = m.vector([0.0, 0.0, 1.0])
...     return Stated(A=m.rotation([0.0, 0.0, 1.0], q[0]), r=0.1 * q[0] * e, F=m.columns(m.vector([0, 0, 0.1, 0, 0, 1])))
>>> screw(np.array([0.5]), 0.0, NUMERIC).r.tolist()
[0.0, 0.0, 0.05]
>>> import sympy as sp
>>> screw([sp.Symbol("x")], sp.Symbol("t"), SYMBOLIC).r.T
Matrix([[0, 0, 0.1*x]])
"""

from __future__ import annotations

import functools
from typing import Any, NamedTuple

import numpy as np

from projeq.analysis.differentiation import derivative_along
from projeq.spatial import quaternion_matrix, rotation
from projeq.symbolic import lazy_import

sp = lazy_import("sympy")


class Stated(NamedTuple):
    """What a joint states (:func:`statement <projeq.joints.Joint.statement>`): the pose ``A``
    (child → joint frame) and ``r`` (J → O_n, joint-frame coordinates), ``F`` = F⁶ (6 × n_s), and
    ``f`` = f⁶ (None: 0), ``K`` (n_q × n_s, None: the identity) and ``k`` (None: 0) of
    q̇_n = K ṡ_n + k. Arrays of the namespace's kind: numpy (A 3×3, r and f 1-D, F and K 2-D) or
    sympy matrices."""

    A: Any
    r: Any
    F: Any
    f: Any = None
    K: Any = None
    k: Any = None


class _Numeric:
    """The namespace of the interpreted form: numpy on real or complex arrays (the complex step)."""

    sin, cos, tan, sqrt, exp, log = np.sin, np.cos, np.tan, np.sqrt, np.exp, np.log
    pi = np.pi

    @staticmethod
    def atan2(y, x):
        """atan2 that passes a complex step: the real angle, with the derivative of atan(y/x) in
        the imaginary part (the same analytic continuation as np.arctan of the ratio)."""
        if np.iscomplexobj(y) or np.iscomplexobj(x):
            angle = np.arctan2(np.real(y), np.real(x))
            return angle + 1j * np.imag(np.arctan(y / x))
        return np.arctan2(y, x)

    @staticmethod
    def vector(entries):
        return np.array([entry for entry in entries])

    @staticmethod
    def matrix(rows):
        return np.array([[entry for entry in row] for row in rows])

    @staticmethod
    def columns(*vectors):
        return np.column_stack(vectors) if vectors else np.zeros((6, 0))

    @staticmethod
    def rotation(axis, angle):
        return rotation(np.asarray(axis, dtype=float), angle)

    quaternion_matrix = staticmethod(quaternion_matrix)

    @staticmethod
    def eye(n):
        return np.eye(n)

    @staticmethod
    def zeros(rows, cols=None):
        return np.zeros(rows if cols is None else (rows, cols))


class _Symbolic:
    """The namespace of the traced form: sympy, floats that are integers made exact (0, ±1)."""

    def __getattr__(self, name):  # sin, cos, tan, sqrt, exp, log, atan2, pi
        if name not in ("sin", "cos", "tan", "sqrt", "exp", "log", "atan2", "pi"):
            raise AttributeError(f"the statement namespace has no {name!r}")
        return getattr(sp, name)

    @staticmethod
    def vector(entries):
        return sp.Matrix([_exact(entry) for entry in entries])

    @staticmethod
    def matrix(rows):
        return sp.Matrix([[_exact(entry) for entry in row] for row in rows])

    @staticmethod
    def columns(*vectors):
        return sp.Matrix.hstack(*(sp.Matrix(v) for v in vectors)) if vectors else sp.zeros(6, 0)

    @staticmethod
    def rotation(axis, angle):
        return lazy_import("projeq.symbolic.algebra").rotation(sp.Matrix([_exact(e) for e in axis]), angle)

    @staticmethod
    def quaternion_matrix(quat):
        return lazy_import("projeq.symbolic.algebra").quaternion_matrix(list(quat))

    @staticmethod
    def eye(n):
        return sp.eye(n)

    @staticmethod
    def zeros(rows, cols=None):
        return sp.zeros(rows, 1 if cols is None else cols)


def _exact(entry):
    """A float that is an integer as a sympy Integer (so 0 and 1 stay exact), other numbers as they are."""
    if isinstance(entry, (float, np.floating, int, np.integer)) and float(entry).is_integer():
        return sp.Integer(int(entry))
    return entry


#: the namespaces of the interpreted and the traced form
NUMERIC, SYMBOLIC = _Numeric(), _Symbolic()


def stated(joint, q_n, t) -> Stated:
    """The joint's statement at numeric (q_n, t), as numpy arrays with f, K, k filled in."""
    found = joint.statement(q_n, t, NUMERIC)
    F = np.asarray(found.F).reshape(6, joint.n_s)
    zero = np.zeros(1, dtype=F.dtype)[0]  # 0 of the statement's dtype
    f = np.zeros(6) + zero if found.f is None else np.asarray(found.f).reshape(6)
    K = np.eye(joint.n_q, joint.n_s) + zero if found.K is None else np.asarray(found.K).reshape(joint.n_q, joint.n_s)
    k = np.zeros(joint.n_q) + zero if found.k is None else np.asarray(found.k).reshape(joint.n_q)
    return Stated(np.asarray(found.A).reshape(3, 3), np.asarray(found.r).reshape(3), F, f, K, k)


def relative(joint, q_n, s_dot_n, t) -> tuple:
    """The numbers of the joint's :class:`projeq.joints.Relative` from its statement: A, r, F⁶, w = F⁶ ṡ + f⁶ and
    ζ = Ḟ⁶ ṡ + ḟ⁶ = d/dt (F⁶(q, t) ṡ + f⁶(q, t)) at fixed ṡ along (q̇, 1), q̇ = K ṡ + k, by the
    complex step through the statement (an outer complex step in q, ṡ or t carried through,
    :func:`projeq.analysis.differentiation.derivative_along`)."""
    now = stated(joint, q_n, t)
    w = now.F @ s_dot_n + now.f
    q_dot = now.K @ s_dot_n + now.k

    def twist(x):  # F⁶ ṡ + f⁶ at (q, t) = x
        later = stated(joint, x[:-1], x[-1])
        return later.F @ s_dot_n + later.f

    zeta = derivative_along(twist, np.append(q_n, t), np.append(q_dot, 1.0))
    return now.A, now.r, now.F, w, zeta


def rates(joint, q_n, s_dot_n, t):
    """q̇_n = K ṡ_n + k of the statement at (q_n, ṡ_n, t)."""
    now = stated(joint, q_n, t)
    return now.K @ s_dot_n + now.k


def traced(joint, q_n, t) -> tuple:
    """The entries (A, r, F, f, K, k) of the joint's :class:`projeq.joints.SymbolicRelative` from its
    statement traced with sympy at the symbols or expressions q_n and t."""
    found = joint.statement(list(q_n), t, SYMBOLIC)

    def given(value, shape, default):
        return default if value is None else sp.Matrix(value).reshape(*shape)

    return (
        given(found.A, (3, 3), None), given(found.r, (3, 1), None), given(found.F, (6, joint.n_s), None),
        given(found.f, (6, 1), sp.zeros(6, 1)), given(found.K, (joint.n_q, joint.n_s), sp.eye(joint.n_q, joint.n_s)),
        given(found.k, (joint.n_q, 1), sp.zeros(joint.n_q, 1)),
    )


def printed(joint, unit=None):
    """The joint's compiled values (:meth:`projeq.joints.Joint.compiled_values`): its sympy form at
    fresh symbols — its statement traced with its parameters as symbols (:func:`parameterized`), or
    its own ``symbolic_relative`` —, ζ derived and everything printed as scalar code that numba
    compiles, the parameters' values its constants (so joints of one class that differ in their
    parameters share the printed source, and one compiled callback: :mod:`projeq.assembly.given`);
    ``unit``: the coordinates whose values are normalised, q/√(qᵀq), put in as the numeric joint does
    (a quaternion)."""
    q, s, t = sp.symbols(f"q0:{joint.n_q}"), sp.symbols(f"s0:{joint.n_s}"), sp.Symbol("t")
    form, symbols, values = parameterized(joint, q, t) if joint.states_motion() else \
        (tuple(joint.symbolic_relative(list(q), list(s), t)), (), ())
    if unit is not None:
        u = [q[i] for i in unit]
        length = sp.sqrt(sum(x**2 for x in u))
        form = tuple(sp.Matrix(e).xreplace({x: x / length for x in u}) for e in form)
    return printed_form(q, s, t, *(sp.ImmutableMatrix(e) for e in form), parameters=symbols)(*values)


#: the members of a joint that place it in the tree (not parameters of its statement)
_PLACEMENT = ("parent", "r_pn", "orientation", "coupling")


def parameterized(joint, q, t) -> tuple[tuple, tuple, tuple]:
    """(form, symbols, values): the statement traced with the joint's own numbers — its float and
    float-array members — as symbols p0, p1, … (``symbols``, their ``values``), so that the form,
    and the code printed from it, is the same for every joint of its class; where the statement
    cannot take symbols for them (a comparison, a numpy function of a parameter), traced with the
    numbers themselves (no symbols)."""
    import copy

    symbols, values, members = [], [], {}
    for name, value in vars(joint).items():
        if name in _PLACEMENT or name.startswith("_printed"):
            continue
        array = np.asarray(value) if isinstance(value, (float, np.ndarray)) else None
        if array is None or array.dtype.kind != "f":
            continue
        entries = [sp.Symbol(f"p{len(symbols) + i}") for i in range(array.size)]
        symbols += entries
        values += [float(v) for v in array.ravel()]
        members[name] = entries[0] if array.ndim == 0 else np.array(entries, dtype=object).reshape(array.shape)
    tracer = copy.copy(joint)
    vars(tracer).update(members)
    try:
        return traced(tracer, q, t), tuple(symbols), tuple(values)
    except Exception:  # noqa: BLE001 — a statement that needs its numbers: traced with them
        return traced(joint, q, t), (), ()


@functools.lru_cache(maxsize=64)
def printed_form(q, s, t, A, r, F, f, K, k, parameters=()):
    """``make(*p)`` -> the compiled-form ``values`` of a joint's sympy form (A, r, F, f, K, k at the
    symbols q, ṡ, t and the ``parameters``, whose values p it takes), ζ derived as for a UserJoint
    (:func:`projeq.joints.user_compiler.joint_symbols`), one per form in a process."""
    from projeq.joints.user_compiler import joint_symbols, printed_values

    return printed_values(joint_symbols(q, s, t, A, r, F, f, K, k), parameters)

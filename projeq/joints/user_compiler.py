"""Compiling user-defined joints (:class:`projeq.joints.UserJoint`).

From sympy: F, A, r, K (and the rheonomic f, k) are checked for unknown symbols,
Ḟ ṡ + ḟ is derived by differentiating along q̇ = K ṡ + k, and everything is lambdified
once with common subexpressions and the parameters as an argument — once per statement (symbols,
expressions, constraints) in a process (:func:`derive`, the last :data:`DERIVED_SIZE` kept), so a
scene built again (a sweep, a loop, the tests), with the same parameters' values or others, takes
its joint's functions ready; each joint keeps its own parameters' values, parent, q0, placement
and expressions. From callables: Ḟ ṡ + ḟ by complex-step
differentiation, exact to round-off. Either way the pose is checked against F and K.
"""

from __future__ import annotations

from functools import cached_property, lru_cache, partial
from typing import NamedTuple

import numpy as np
import sympy as sp

from projeq.analysis.differentiation import derivative_along
from projeq.checks import callable_name, check_rotation, count, finite_array
from projeq.joints import Relative, pose_twist_mismatch
from projeq.spatial import numeric
from projeq.symbolic import codegen

_SINGULAR_CONDITION = 1e10  # condition number of K(q0) treated as singular
_POSE_TOLERANCE = 1e-5  # central differences of step 1e-7 in pose_twist_mismatch: error ~1e-9


def _matrix(name: str, value, shape: tuple) -> sp.Matrix:
    M = sp.Matrix(value)
    if shape[1] == 1 and M.shape == (1, shape[0]):
        M = M.T
    if M.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {M.shape}")
    return M


def _check_symbols(name: str, expr: sp.Matrix, allowed: set, q, t, s=()) -> None:
    extra = expr.free_symbols - allowed
    speeds = sorted(map(str, extra & set(s)))
    if speeds:
        raise ValueError(
            f"{name}: depends on the minimal velocities {speeds}; it may depend only on the "
            f"coordinates {[str(x) for x in q]}, time {t} and declared parameters (the twist "
            "F ṡ + f and the rates K ṡ + k are linear in ṡ)"
        )
    if extra:
        raise ValueError(
            f"{name}: depends on {sorted(map(str, extra))}, which are not coordinates "
            f"{[str(x) for x in q]}, time {t} or declared parameters; declare them with "
            "parameters={symbol: value}"
        )


def compile_user_joint(cls, q, s, A, r, F, K, *, f, k, t, parameters, parent, q0, r_pn, orientation,
                       constraints=None, q_dot=None):
    """A :class:`UserJoint` from sympy expressions (see ``UserJoint.from_sympy``): the statement
    checked, its derivation and functions from :func:`derive` (built once per statement in a
    process), the parameters' values, placement and q0 the joint's own, the pose checked."""
    statement, p = _statement(q, s, A, r, F, K, f, k, t, parameters, constraints, q_dot)
    derived = derive(statement)
    q0 = None if q0 is None else finite_array("q0", q0, (len(statement.q),))
    at = ([0.0] * len(statement.q) if q0 is None else q0, [1.0] * len(statement.s), 0.3)
    joint = cls(
        parent, len(statement.q), len(statement.s), partial(derived.relative, p), partial(derived.K, p),
        partial(derived.q_dot, p), q0=q0, r_pn=r_pn, orientation=orientation,
        constraints=None if derived.residual is None else partial(derived.residual, p), n_c=derived.n_c,
        symbols=derived.symbols(p), values=_evaluates(partial(derived.values, p), at),
        rates=_evaluates(partial(derived.rates, p), at), compiled=partial(_compiled_values, derived, p),
    )
    _check_pose(joint)
    return joint


class Statement(NamedTuple):
    """What determines the derivation of a joint from sympy, hashable (the key of :func:`derive`):
    the symbols of q, ṡ and t, the expressions A, r, F, K, f, k, the original velocity constraints
    in the rates ``q_dot`` (or None), and the ``parameters``' symbols, whose values each joint
    passes to the derived functions as their first argument."""

    q: tuple
    s: tuple
    t: sp.Symbol
    A: sp.ImmutableMatrix
    r: sp.ImmutableMatrix
    F: sp.ImmutableMatrix
    K: sp.ImmutableMatrix
    f: sp.ImmutableMatrix
    k: sp.ImmutableMatrix
    constraints: sp.ImmutableMatrix | None
    q_dot: tuple | None
    parameters: tuple


def _statement(q, s, A, r, F, K, f, k, t, parameters, constraints, q_dot) -> tuple[Statement, tuple]:
    """The user's expressions checked (shapes, symbols), and the parameters' values in the order of
    the statement's ``parameters`` (sympy's canonical order of their symbols)."""
    q, s = tuple(q), tuple(s)
    t = t if t is not None else sp.Symbol("t")
    n_q, n_s = len(q), len(s)
    exprs = {
        "A": _matrix("A", A, (3, 3)),
        "r": _matrix("r", r, (3, 1)),
        "F": _matrix("F", F, (6, n_s)),
        "K": _matrix("K", K, (n_q, n_s)),
        "f": _matrix("f", sp.zeros(6, 1) if f is None else f, (6, 1)),
        "k": _matrix("k", sp.zeros(n_q, 1) if k is None else k, (n_q, 1)),
    }
    values = {sym: float(finite_array(f"parameters[{sym}]", val, ())) for sym, val in parameters.items()}
    variables = sorted(map(str, set(values) & (set(q) | set(s) | {t})))
    if variables:
        raise ValueError(f"parameters: {variables} are coordinates, minimal velocities or time, not constants")
    allowed = set(q) | {t} | set(values)
    for name, expr in exprs.items():
        _check_symbols(name, expr, allowed, q, t, s)
    C = None
    if constraints is not None:
        if q_dot is None or len(q_dot) != n_q:
            raise ValueError("q_dot: give one symbol for each coordinate's rate to state constraints")
        q_dot = tuple(q_dot)
        C = sp.ImmutableMatrix(list(constraints))
        _check_symbols("constraints", C, allowed | set(q_dot), q, t)
    symbols = tuple(sorted(values, key=sp.default_sort_key))
    statement = Statement(q, s, t, *map(sp.ImmutableMatrix, exprs.values()), C,
                          q_dot if constraints is not None else None, symbols)
    return statement, tuple(values[symbol] for symbol in symbols)


#: statements whose derivation :func:`derive` keeps (least recently used first out), and
#: parameter values whose compiled function :func:`_compiled_values` keeps
DERIVED_SIZE = 64


@lru_cache(maxsize=DERIVED_SIZE)
def derive(statement: Statement) -> Derived:
    """Ḟ ṡ + ḟ = (∂F/∂q q̇ + ∂F/∂t) ṡ + ∂f/∂q q̇ + ∂f/∂t along q̇ = K ṡ + k, and every function of
    the joint lambdified once with common subexpressions, the parameters p their first argument:
    the same statement (equal symbols, expressions and constraints) is derived once per process
    whatever its parameters' values (``derive.cache_info()``)."""
    p, q, s, t = list(statement.parameters), list(statement.q), list(statement.s), statement.t
    A, r, F, K, f, k = (sp.Matrix(e) for e in statement[3:9])
    s_vec = sp.Matrix(s)
    rates = K * s_vec + k  # q̇
    symbols = joint_symbols(q, s, t, A, r, F, f, K, k)
    zeta = symbols["zeta"]
    rel = sp.lambdify([p, q, s, t], [A, r, F, F * s_vec + f, zeta], modules="numpy", cse=True)
    K_fun = sp.lambdify([p, q, t], K, modules="numpy", cse=True)
    q_dot_fun = sp.lambdify([p, q, s, t], rates, modules="numpy", cse=True)

    def relative(p_n, q_n, s_dot_n, time):
        A_, r_, F_, w_, z_ = rel(p_n, q_n, s_dot_n, time)
        return Relative(
            numeric(A_),
            numeric(r_).ravel(),
            numeric(F_),
            numeric(w_).ravel(),
            numeric(z_).ravel(),
        )

    residual, n_c = _compile_constraints(statement.constraints, p, q, statement.q_dot, t)
    return Derived(
        p, symbols, relative,
        lambda p_n, q_n, time: numeric(K_fun(p_n, q_n, time)),
        lambda p_n, q_n, s_dot_n, time: numeric(q_dot_fun(p_n, q_n, s_dot_n, time)).ravel(),
        # the same numbers as flat lists of scalars (Joint.relative_values, q̇): for real arguments
        sp.lambdify([p, q, s, t], value_expressions(symbols), modules="math", cse=True),
        sp.lambdify([p, q, s, t], list(rates), modules="math", cse=True),
        residual, n_c,
    )


def joint_symbols(q, s, t, A, r, F, f, K, k) -> dict:
    """The expressions {"q", "s", "t", "A", "r", "F", "K", "f", "k", "zeta"} of a joint's sympy form
    (its symbols q, ṡ (``s``), t and A, r, F, f, K, k as :class:`projeq.joints.base.SymbolicRelative`
    holds them), with ζ = Ḟ ṡ + ḟ = (∂F/∂q q̇ + ∂F/∂t) ṡ + ∂f/∂q q̇ + ∂f/∂t along q̇ = K ṡ + k."""
    q, s = list(q), list(s)
    A, r, F, f, K, k = (sp.Matrix(e) for e in (A, r, F, f, K, k))
    s_vec = sp.Matrix(len(s), 1, s)
    rates = K * s_vec + k

    def d_dt(M: sp.Matrix) -> sp.Matrix:
        return sum((M.diff(qi) * rates[i] for i, qi in enumerate(q)), M.diff(t))

    zeta = d_dt(F) * s_vec + d_dt(f)
    return {"q": q, "s": s, "t": t, "A": A, "r": r, "F": F, "K": K, "f": f, "k": k, "zeta": zeta}


class Derived:
    """The derivation of one :class:`Statement` (:func:`derive`): functions of (p, q, ṡ, t), the
    parameters' values p first, shared by every joint from it, none with state of its own —
    ``relative``, ``K``, ``q_dot``, the scalar ``values`` and ``rates`` (``math``), the
    constraints' ``residual`` (or None) and their number ``n_c`` — and the expressions, each
    joint's own with its parameters' values put in (:meth:`symbols`)."""

    def __init__(self, parameters, symbols, relative, K, q_dot, values, rates, residual, n_c):
        self.parameters, self._symbols = parameters, symbols
        self.relative, self.K, self.q_dot, self.values, self.rates = relative, K, q_dot, values, rates
        self.residual, self.n_c = residual, n_c

    def symbols(self, p) -> dict:
        """The expressions {"q", "s", "t", "A", "r", "F", "K", "f", "k", "zeta"} with the
        parameters' values ``p`` put in: a joint's own (sympy matrices are mutable)."""
        numbers = dict(zip(self.parameters, p))
        return {key: (value.xreplace(numbers) if isinstance(value, sp.MatrixBase) else value.copy())
                for key, value in self._symbols.items() if key != "t"} | {"t": self._symbols["t"]}

    @cached_property
    def make_values(self):
        """``make(*p)`` -> the compiled-form ``values`` at the parameters' values p
        (:func:`printed_values`, printed once per statement)."""
        return printed_values(self._symbols, self.parameters)


@lru_cache(maxsize=DERIVED_SIZE)
def _compiled_values(derived: Derived, p: tuple):
    """The compiled-form ``values`` of ``derived`` at the parameters' values ``p``, one function per
    (statement, values) in a process, so that its numba callback is built once."""
    return derived.make_values(*p)


def value_expressions(symbols: dict) -> list:
    """The entries of :meth:`projeq.joints.base.Joint.relative_values` of a joint from sympy:
    A row by row, r, w = F ṡ + f, ζ = Ḟ ṡ + ḟ, then F column by column."""
    F, s = symbols["F"], sp.Matrix(len(symbols["s"]), 1, list(symbols["s"]))  # (0, 1) without velocities
    return [*symbols["A"], *symbols["r"], *(F * s + symbols["f"]), *symbols["zeta"], *F.T]


def row_expressions(symbols: dict) -> list:
    """The row of a joint's compiled values: :func:`value_expressions` (A, r, w, ζ, F⁶), then its
    rates q̇ = K ṡ + k (n_q entries), which the compiled kernels read for ẋ
    (:mod:`projeq.assembly.given`)."""
    s = sp.Matrix(len(symbols["s"]), 1, list(symbols["s"]))
    return [*value_expressions(symbols), *(symbols["K"] * s + symbols["k"])]


def printed_values(symbols: dict, parameters=()):
    """``make(*p)`` -> ``values(q_n, ṡ_n, t)``, the flat array of :func:`row_expressions` at
    the ``parameters``' values p, printed as scalar numpy code that numba compiles, the values
    its constants (:func:`projeq.symbolic.codegen.numeric_function`; the parameters renamed
    p0, p1, … there, names numba can read)."""
    arguments = [("q", list(symbols["q"])), ("s", list(symbols["s"])), ("t", symbols["t"])]
    names = [sp.Symbol(f"p{i}") for i in range(len(parameters))]
    expressions = [e.xreplace(dict(zip(parameters, names))) for e in row_expressions(symbols)]
    return codegen.numeric_function("relative_values", arguments, expressions, names)


def _evaluates(values, at):
    """The scalar code ``values`` (``math``) if it evaluates at ``at`` (q0, ṡ, t), else None (a
    function ``math`` does not have, or a domain error there): then the numpy form serves."""
    try:
        values(*(list(map(float, a)) if np.ndim(a) else a for a in at))
    except (NameError, TypeError, ValueError, ZeroDivisionError):
        return None
    return values


def _compile_constraints(C, p, q, q_dot, t):
    """Residual function (p, q, q̇, t) of the original velocity constraints C (expressions in the
    parameters p, q, q̇, t; None: no constraints) and their number."""
    if C is None:
        return None, 0
    fun = sp.lambdify([p, q, list(q_dot), t], list(C), modules="numpy", cse=True)
    return (lambda p_n, q_n, q_dot_n, time: np.asarray(fun(p_n, q_n, q_dot_n, time), dtype=float)), len(C)


def wrap_user_functions(cls, n_q, n_s, pose, F, K, *, f, k, parent, q0, r_pn, orientation,
                        constraints=None, n_c=0):
    """A :class:`UserJoint` from callables (see ``UserJoint.from_functions``)."""
    n_q, n_s = count("n_q", n_q, 0), count("n_s", n_s, 0)
    for call, function in (("pose(q, t)", pose), ("F(q, t)", F), ("K(q, t)", K), ("f(q, t)", f), ("k(q, t)", k),
                           ("constraints(q, q_dot, t)", constraints)):
        if function is not None and not callable(function):
            raise ValueError(f"{call.split('(')[0]}: expected a callable {call}, got {type(function).__name__} "
                             f"{function!r}")
    zero6, zero_q = np.zeros(6), np.zeros(n_q)
    f = f if f is not None else (lambda q_n, time: zero6)
    k = k if k is not None else (lambda q_n, time: zero_q)

    def q_dot(q_n, s_dot_n, time):
        return K(q_n, time) @ s_dot_n + k(q_n, time)

    def relative(q_n, s_dot_n, time):
        A, r = pose(q_n, time)
        F_n = numeric(F(q_n, time))
        # complex step along (q̇, 1): Im F(q + iε q̇, t + iε)/ε = Ḟ exactly to round-off
        x, rate = np.append(q_n, time), np.append(q_dot(q_n, s_dot_n, time), 1.0)
        F_dot = derivative_along(lambda x: F(x[:-1], x[-1]), x, rate)
        f_dot = derivative_along(lambda x: f(x[:-1], x[-1]), x, rate)
        w = F_n @ s_dot_n + numeric(f(q_n, time))
        return Relative(numeric(A), numeric(r), F_n, w, F_dot @ s_dot_n + f_dot)

    joint = cls(parent, n_q, n_s, relative, K, q_dot, q0=q0, r_pn=r_pn, orientation=orientation,
                constraints=constraints, n_c=n_c)
    _check_callables(joint, pose, F, f, k)
    joint.constraint_residual(joint.default_q(), np.zeros(n_q), 0.0)  # ValueError naming constraints
    _check_shapes(joint)
    _check_pose(joint)
    return joint


def _check_callables(joint, pose, F, f, k) -> None:
    """Shapes of the user's callables at q0, before anything is combined from them."""
    q0 = joint.default_q()
    pose_q0 = _called("pose", pose, q0)
    try:
        A, r = pose_q0
    except (TypeError, ValueError) as exc:
        raise ValueError(f"pose: must return (A, r) = (3×3 rotation, 3-vector) at (q, t): {exc}") from exc
    for name, value, shape in (
        ("pose A", A, (3, 3)),
        ("pose r", r, (3,)),
        ("F", _called("F", F, q0), (6, joint.n_s)),
        ("K", _called("K", joint.K, q0), (joint.n_q, joint.n_s)),
        ("f", _called("f", f, q0), (6,)),
        ("k", _called("k", k, q0), (joint.n_q,)),
    ):
        finite_array(name, value, shape)


def _called(name: str, function, q0):
    """``function(q0, 0)``; an exception of the user's callable as a ValueError naming the
    parameter and the callable."""
    try:
        return function(q0, 0.0)
    except Exception as exc:  # noqa: BLE001 - the user's callable, reported by name
        raise ValueError(f"{name}: {callable_name(function)} raised {type(exc).__name__}: {exc} at "
                         f"q0 = {q0.tolist()}, t = 0") from exc


def _check_shapes(joint) -> None:
    q0, s0 = joint.default_q(), np.ones(joint.n_s)
    try:
        rel = joint.relative(q0, s0, 0.0)
    except TypeError as exc:
        raise ValueError(
            "F: the callables must accept complex arguments for complex-step "
            f"differentiation (use numpy functions): {exc}"
        ) from exc
    for name, value, shape in (
        ("pose A", rel.A, (3, 3)),
        ("pose r", rel.r, (3,)),
        ("F", rel.F, (6, joint.n_s)),
        ("K", joint.K(q0, 0.0), (joint.n_q, joint.n_s)),
    ):
        finite_array(name, value, shape)


def _check_K(joint, q_n) -> None:
    """K(q) must be finite and of full column rank: else the minimal velocities do not
    parametrise the rates (a coordinate singularity, e.g. Euler angles at 90° tilt)."""
    if joint.n_s == 0:
        return
    with np.errstate(all="ignore"):
        K = np.asarray(joint.K(q_n, 0.0), dtype=float)
    cond = np.linalg.cond(K) if np.all(np.isfinite(K)) else np.inf
    if not cond < _SINGULAR_CONDITION:
        raise ValueError(
            f"K: q̇ = K(q) ṡ is singular at q0 = {np.round(q_n, 6).tolist()} (condition number "
            f"{cond:.3g}): a coordinate singularity of the chosen coordinates; start away from "
            "it or use other coordinates (another Euler sequence, quaternions)"
        )


def _check_pose(joint) -> None:
    """The pose's time derivative must be the twist F ṡ + f (at q0 and a nearby point)."""
    _check_K(joint, joint.default_q())
    rng = np.random.default_rng(0)
    for q_n in (joint.default_q(), joint.default_q() + 0.1 * rng.standard_normal(joint.n_q)):
        s_dot = rng.standard_normal(joint.n_s)
        check_rotation("pose A", joint.relative(q_n, s_dot, 0.3).A, f"at q = {np.round(q_n, 4).tolist()}, t = 0.3")
        error = pose_twist_mismatch(joint, q_n, s_dot, 0.3)
        scale = 1.0 + np.abs(joint.relative(q_n, s_dot, 0.3).w).max()
        if not error <= _POSE_TOLERANCE * scale:
            raise ValueError(
                f"F: the relative twist F ṡ + f differs by {error:.3g} from the time derivative "
                f"of the pose (A, r) along q̇ = K ṡ + k at q = {np.round(q_n, 4).tolist()}; "
                "F, K and the pose must describe the same motion"
            )

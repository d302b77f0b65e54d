"""Compiling user-defined joints (:class:`projeq.joints.UserJoint`).

From sympy: F, A, r, K (and the rheonomic f, k) are checked for unknown symbols,
Ḟ ṡ + ḟ is derived by differentiating along q̇ = K ṡ + k, and everything is lambdified
once with common subexpressions. From callables: Ḟ ṡ + ḟ by complex-step
differentiation, exact to round-off. Either way the pose is checked against F and K.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from projeq.analysis.differentiation import derivative_along
from projeq.checks import check_rotation, finite_array
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
    """A :class:`UserJoint` from sympy expressions (see ``UserJoint.from_sympy``)."""
    q, s = list(q), list(s)
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
    allowed = set(q) | {t} | set(values)
    for name, expr in exprs.items():
        _check_symbols(name, expr, allowed, q, t, s)
    A, r, F, K, f, k = (e.xreplace(values) for e in exprs.values())

    s_vec = sp.Matrix(s)
    rates = K * s_vec + k  # q̇

    def d_dt(M: sp.Matrix) -> sp.Matrix:
        return sum((M.diff(qi) * rates[i] for i, qi in enumerate(q)), M.diff(t))

    zeta = d_dt(F) * s_vec + d_dt(f)
    rel = sp.lambdify([q, s, t], [A, r, F, F * s_vec + f, zeta], modules="numpy", cse=True)
    symbols = {"q": q, "s": s, "t": t, "A": A, "r": r, "F": F, "K": K, "f": f, "k": k, "zeta": zeta}
    # the same numbers as one flat list of scalars (Joint.relative_values): for real arguments
    at = ([0.0] * n_q if q0 is None else q0, [1.0] * n_s, 0.3)
    scalar = _scalar_code([q, s, t], value_expressions(symbols), at)
    scalar_rates = _scalar_code([q, s, t], list(rates), at)  # q̇ = K ṡ + k, the same way
    K_fun = sp.lambdify([q, t], K, modules="numpy", cse=True)
    q_dot_fun = sp.lambdify([q, s, t], rates, modules="numpy", cse=True)

    def relative(q_n, s_dot_n, time):
        A_, r_, F_, w_, z_ = rel(q_n, s_dot_n, time)
        return Relative(
            numeric(A_),
            numeric(r_).ravel(),
            numeric(F_),
            numeric(w_).ravel(),
            numeric(z_).ravel(),
        )

    residual, n_c = _compile_constraints(constraints, q, q_dot, t, values)
    joint = cls(
        parent, n_q, n_s, relative,
        lambda q_n, time: numeric(K_fun(q_n, time)),
        lambda q_n, s_dot_n, time: numeric(q_dot_fun(q_n, s_dot_n, time)).ravel(),
        q0=q0, r_pn=r_pn, orientation=orientation, constraints=residual, n_c=n_c,
        symbols=symbols, values=scalar,
        rates=scalar_rates,
    )
    _check_pose(joint)
    return joint


def value_expressions(symbols: dict) -> list:
    """The entries of :meth:`projeq.joints.base.Joint.relative_values` of a joint from sympy:
    A row by row, r, w = F ṡ + f, ζ = Ḟ ṡ + ḟ, then F column by column."""
    F, s = symbols["F"], sp.Matrix(symbols["s"])
    return [*symbols["A"], *symbols["r"], *(F * s + symbols["f"]), *symbols["zeta"], *F.T]


_COMPILED_VALUES: dict = {}  # the expressions of value_expressions -> their numeric_function


def compiled_values(symbols: dict):
    """``values(q_n, ṡ_n, t)`` -> the flat array of :func:`value_expressions`, printed as scalar
    numpy code that numba compiles (:func:`projeq.symbolic.codegen.numeric_function`), built
    once per expressions in a process."""
    expressions = value_expressions(symbols)
    key = tuple(expressions)
    if key not in _COMPILED_VALUES:
        arguments = [("q", list(symbols["q"])), ("s", list(symbols["s"])), ("t", symbols["t"])]
        _COMPILED_VALUES[key] = codegen.numeric_function("relative_values", arguments, expressions)()
    return _COMPILED_VALUES[key]


def _scalar_code(args, expressions, at):
    """The expressions lambdified to scalar code (``math``) for Python floats, or None where
    it cannot evaluate them (a function ``math`` does not have): then the numpy form serves."""
    values = sp.lambdify(args, expressions, modules="math", cse=True)
    try:
        values(*(list(map(float, a)) if np.ndim(a) else a for a in at))
    except (NameError, TypeError, ValueError, ZeroDivisionError):
        return None
    return values


def _compile_constraints(constraints, q, q_dot, t, values):
    """Residual function of the original velocity constraints (expressions in q, q̇, t)."""
    if constraints is None:
        return None, 0
    if q_dot is None or len(q_dot) != len(q):
        raise ValueError("q_dot: give one symbol for each coordinate's rate to state constraints")
    C = sp.Matrix(list(constraints))
    _check_symbols("constraints", C, set(q) | set(q_dot) | {t} | set(values), q, t)
    fun = sp.lambdify([q, list(q_dot), t], list(C.xreplace(values)), modules="numpy", cse=True)
    return (lambda q_n, q_dot_n, time: np.asarray(fun(q_n, q_dot_n, time), dtype=float)), len(C)


def wrap_user_functions(cls, n_q, n_s, pose, F, K, *, f, k, parent, q0, r_pn, orientation,
                        constraints=None, n_c=0):
    """A :class:`UserJoint` from callables (see ``UserJoint.from_functions``)."""
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
    try:
        A, r = pose(q0, 0.0)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"pose: must return (A, r) = (3×3 rotation, 3-vector) at (q, t): {exc}") from exc
    for name, value, shape in (
        ("pose A", A, (3, 3)),
        ("pose r", r, (3,)),
        ("F", F(q0, 0.0), (6, joint.n_s)),
        ("K", joint.K(q0, 0.0), (joint.n_q, joint.n_s)),
        ("f", f(q0, 0.0), (6,)),
        ("k", k(q0, 0.0), (joint.n_q,)),
    ):
        finite_array(name, value, shape)


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

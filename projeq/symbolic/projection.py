"""The Projection Equation in sympy, from mass-centre velocities (B(10)–(12) of Bremer (2009), docs/theory.md §2).

For each body, with all vectors in the coordinates of a reference frame R rotating with
ω_IR, p = m v_c and L = I_c ω_c (B(10)):

    Σ_i [(∂v_c/∂ṡ)ᵀ (∂ω_c/∂ṡ)ᵀ]_i [ṗ + ω̃_IR p − fᵉ ; L̇ + ω̃_IR L − Mᵉ]_i = 0.

Time derivatives of the components are total: d/dt x(q, ṡ, t) = ∂x/∂ṡ s̈ + ∂x/∂q K ṡ +
∂x/∂t with q̇ = K(q) ṡ. Collecting s̈ gives the Gauss form M(q) s̈ = rhs(q, ṡ, t); M is
never inverted symbolically — the compiled evaluator solves it numerically.

Parameters are plain sympy symbols in the inputs, declared in ``parameters``; numbers
are given to :meth:`GaussForm.evaluator` (``values={m: 1200.0}``).
"""

from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from .validation import check_symbols, matrix, symbol_vector

__all__ = ["Body", "GaussForm", "projection_equation", "SymbolicEvaluator", "t"]

t = sp.Symbol("t")  # time in every symbolic derivation of projeq


@dataclass(frozen=True)
class Body:
    """One rigid body of B(10): velocities and loads in the reference frame R's coordinates.

    v_c, omega : 3-vectors of expressions in q, ṡ, t (mass-centre velocity and angular velocity)
    m : mass; I_c : 3×3 inertia about the mass centre (in R, may depend on q, t)
    f, M : impressed force and torque about the mass centre (default zero)
    omega_IR : angular velocity of R w.r.t. the inertial frame (default zero: R = I;
        ``omega_IR=omega`` for a body-fixed R)
    """

    v_c: object
    omega: object
    m: object
    I_c: object
    f: object = (0, 0, 0)
    M: object = (0, 0, 0)
    omega_IR: object = (0, 0, 0)

    def vectors(self, name: str) -> dict:
        """The body's inputs as sympy matrices, shapes checked; errors name ``name.field``."""
        out = {}
        for key in ("v_c", "omega", "f", "M", "omega_IR"):
            out[key] = matrix(f"{name}.{key}", getattr(self, key))
            if out[key].shape != (3, 1):
                raise ValueError(f"{name}.{key}: expected a 3-vector, got shape {out[key].shape}")
        out["I_c"] = matrix(f"{name}.I_c", self.I_c)
        if out["I_c"].shape != (3, 3):
            raise ValueError(f"{name}.I_c: expected a 3×3 inertia matrix, got shape {out['I_c'].shape}")
        out["m"] = sp.sympify(self.m)
        return out


@dataclass(frozen=True)
class GaussForm:
    """M(q) s̈ = rhs(q, ṡ, t), sympy matrices (docs/theory.md §5); ``q``, ``s`` the symbols, ``t`` time,
    ``K`` the kinematics q̇ = K ṡ, ``parameters`` the symbols left for the evaluator."""

    M: sp.Matrix
    rhs: sp.Matrix
    q: tuple
    s: tuple
    K: sp.Matrix
    t: sp.Symbol = t
    parameters: tuple = field(default=())

    def latex(self) -> str:
        r"""LaTeX of M \ddot{s} = rhs."""
        s_ddot = sp.Matrix([sp.Symbol(rf"\ddot{{{sp.latex(x)}}}") for x in self.s])
        return f"{sp.latex(self.M)} {sp.latex(s_ddot)} = {sp.latex(self.rhs)}"

    def evaluator(self, values=None) -> "SymbolicEvaluator":
        """Compiled numeric evaluator (lambdify with ``cse=True``); ``values`` maps every
        parameter symbol to a number."""
        values = dict(values or {})
        missing = [str(p) for p in self.parameters if p not in values]
        if missing:
            raise ValueError(f"values: no number given for the parameters {', '.join(missing)}")
        unknown = [str(k) for k in values if k not in self.parameters]
        if unknown:
            raise ValueError(f"values: {', '.join(unknown)} are not parameters of this Gauss form")
        return SymbolicEvaluator(self, values)


def operation_count(replacements, reduced) -> int:
    """sympy.count_ops over the output of sympy.cse: its replacements and reduced expressions."""
    return sum(sp.count_ops(e) for _, e in replacements) + sum(sp.count_ops(e) for e in reduced)


class SymbolicEvaluator:
    """``accelerations(q, s_dot, t)`` from a compiled Gauss form, for :func:`projeq.simulate`.

    ``n_ops`` is the operation count of the compiled expressions after common-subexpression
    elimination (``sympy.count_ops`` over the CSE replacements and reduced expressions)."""

    def __init__(self, gauss: GaussForm, values: dict):
        M, rhs = (x.xreplace({k: sp.Float(v) for k, v in values.items()}) for x in (gauss.M, gauss.rhs))
        replacements, reduced = sp.cse([M, rhs])
        self.n_ops = operation_count(replacements, reduced)
        self._M_rhs = sp.lambdify([list(gauss.q), list(gauss.s), gauss.t], [M, rhs], modules="numpy",
                                  cse=lambda expressions: (replacements, reduced))  # the CSE counted above
        self.n_q, self.n_s = len(gauss.q), len(gauss.s)

    def gauss_form(self, q, s_dot, t=0.0):
        """Numeric (M, rhs) at a state."""
        M, rhs = self._M_rhs(np.asarray(q, float), np.asarray(s_dot, float), float(t))
        return np.asarray(M, float), np.asarray(rhs, float).reshape(-1)

    def accelerations(self, q, s_dot, t=0.0):
        """s̈ = M⁻¹ rhs, by a numeric solve."""
        M, rhs = self.gauss_form(q, s_dot, t)
        return np.linalg.solve(M, rhs)


def projection_equation(bodies, q, s, K=None, parameters=(), trace: list | None = None) -> GaussForm:
    """Gauss form of B(10) for ``bodies`` (a mapping name → :class:`Body`).

    q, s : sequences of sympy symbols, the coordinates and the minimal velocities ṡ
    K : matrix of q̇ = K(q) ṡ (default: identity, ṡ = q̇, needs len(q) == len(s))
    parameters : the other symbols the inputs may contain
    trace : a list to which each body's intermediate expressions are appended, by name (its
        projections J_v = ∂v/∂ṡ, J_ω = ∂ω/∂ṡ and its momentum balances), for
        counting the effort of the derivation (:mod:`projeq.studies.effort_growth`)

    >>> m, c, C0, vx, wz, g = sp.symbols("m c C0 v_x omega_z gamma")
    >>> car = Body(v_c=(vx, c * wz, 0), omega=(0, 0, wz), m=m, I_c=sp.diag(0, 0, C0 - m * c**2),
    ...            omega_IR=(0, 0, wz))
    >>> K = sp.Matrix([[sp.cos(g), 0], [sp.sin(g), 0], [0, 1]])
    >>> gf = projection_equation({"car": car}, sp.symbols("x y gamma"), (vx, wz), K, (m, c, C0))
    >>> gf.M, list(sp.expand(gf.rhs))   # B(9): M = diag(m, C°), rhs = −G ṡ
    (Matrix([
    [m,  0],
    [0, C0]]), [c*m*omega_z**2, -c*m*omega_z*v_x])
    """
    q, s, parameters = tuple(symbol_vector("q", q)), tuple(symbol_vector("s", s)), tuple(symbol_vector("parameters", parameters))
    if not s:
        raise ValueError("s: no minimal velocities (a system without degrees of freedom has no equations of motion)")
    if K is None:
        if len(q) != len(s):
            raise ValueError(f"K: required when the {len(s)} speeds are not the derivatives of the {len(q)} coordinates")
        K = sp.eye(len(q))
    K = matrix("K", K)
    if K.shape != (len(q), len(s)):
        raise ValueError(f"K: expected shape ({len(q)}, {len(s)}) for q̇ = K ṡ, got {K.shape}")
    declared = set(q) | set(s) | {t} | set(parameters)
    check_symbols("K", K, set(q) | {t} | set(parameters))
    q_dot = K * sp.Matrix(s)
    M, rhs = sp.zeros(len(s), len(s)), sp.zeros(len(s), 1)
    for name, body in dict(bodies).items():
        b = body.vectors(name)
        for key, value in b.items():
            check_symbols(f"{name}.{key}", value, declared)
        M_i, rhs_i, steps = _body_terms(b, q, s, q_dot)
        M, rhs = M + M_i, rhs + rhs_i
        if trace is not None:
            trace.append(steps)
    return GaussForm(M, rhs, q, s, K, t, parameters)


def _rest_of_derivative(x, q, q_dot):
    """d/dt x(q, ṡ, t) without its s̈ terms: ∂x/∂q q̇ + ∂x/∂t."""
    return x.jacobian(q) * q_dot + x.diff(t)


def _body_terms(b, q, s, q_dot):
    """One body's share of B(10): M_i = m J_vᵀJ_v + J_ωᵀ I_c J_ω and rhs_i = −Jᵀ(… − fᵉ, … − Mᵉ), and the
    expressions formed on the way, by name."""
    J_v, J_w = b["v_c"].jacobian(s), b["omega"].jacobian(s)
    m, I_c, w_IR = b["m"], b["I_c"], b["omega_IR"]
    p, L = m * b["v_c"], I_c * b["omega"]
    p_dot_rest = m * _rest_of_derivative(b["v_c"], q, q_dot)  # m constant
    I_c_dot = sum((I_c.diff(q_k) * q_dot_k for q_k, q_dot_k in zip(q, q_dot)), I_c.diff(t))
    L_dot_rest = I_c * _rest_of_derivative(b["omega"], q, q_dot) + I_c_dot * b["omega"]
    M_i = m * J_v.T * J_v + J_w.T * I_c * J_w
    force, moment = p_dot_rest + w_IR.cross(p) - b["f"], L_dot_rest + w_IR.cross(L) - b["M"]
    rhs_i = -J_v.T * force - J_w.T * moment
    steps = {"projections J_v, J_ω": [*J_v, *J_w], "momentum balances": [*force, *moment]}
    return M_i, rhs_i, steps

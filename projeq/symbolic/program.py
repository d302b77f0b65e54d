"""Program constraints: the generalized program motion equations (GPME), docs/theory.md §11.

Jarzębowska's algorithm (Jarzębowska (2002) eqs. 6.29–6.33) for constraints of order p,
``c(t, q, q̇, …, q^(p)) = 0``, linear in the p-th derivatives:

* solve the constraints for n − l dependent p-th derivatives (6.29),
  ``q_ρ^(p) = Σ_λ a_ρλ q_λ^(p) + a_ρ``;
* ``P_p = [T^(p) − (p+1) T_0^(p)]/p`` with ``T_0^(p) = Σ ∂T/∂q_σ q_σ^(p)`` (6.30, 6.25);
* ``R_p = P_p − Σ q_σ^(p) Q_σ`` (6.31);
* the l equations ``∂R_p*/∂q_λ^(p) = ∂R_p/∂q_λ^(p) + Σ_ρ ∂R_p/∂q_ρ^(p) a_ρλ = 0`` (6.33).

By Tsenov's identity ∂T^(p)/∂q^(p) = p d/dt ∂T/∂q̇ + ∂T/∂q, so ∂R_p/∂q^(p) is the Lagrange
expression d/dt ∂T/∂q̇ − ∂T/∂q − Q for every p: the GPME are second order, the
constraints of order p, and both are integrated together as the linear system for the
highest derivative q^(m), m = max(2, p), with state (q, q̇, …, q^(m−1)).

The same left-hand sides for p = 1 and p = 2 are Nielsen's equations (5.1) and Tzenoff's
equations of the second kind (5.2) (:func:`nielsen_equations`, :func:`tzenoff_equations`); none of
this assumes T quadratic in q̇ (Jarzębowska (2002), remark after (6.7)). Grioli's condition for a
pseudo-regular precession, (4.1) with the body rates (4.1a), is a second-order program constraint
(:func:`pseudo_regular_precession`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Mapping, Sequence

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
from sympy.core.function import AppliedUndef

__all__ = ["ProgramEquations", "nielsen_equations", "program_motion_equations", "pseudo_regular_precession",
           "tzenoff_equations"]


def _order(expr: sp.Expr, q: Sequence, t: sp.Symbol) -> int:
    """Highest time derivative of any coordinate in ``expr`` (0 if none)."""
    orders = [0]
    for d in expr.atoms(sp.Derivative):
        if d.expr in q:
            orders.append(d.derivative_count)
    return max(orders)


def replace_derivatives(expr, q: Sequence, t: sp.Symbol, names: Sequence[Sequence]):
    """``expr`` with q^(k)(t) replaced by the plain symbols ``names[k]`` (for lambdify)."""
    for k in range(len(names) - 1, -1, -1):  # highest first, so q(t) stays inside Derivative until its turn
        expr = expr.subs({qi.diff(t, k) if k else qi: name for qi, name in zip(q, names[k])})
    return expr


def check_declared(exprs: Sequence, q: Sequence, t: sp.Symbol, parameters: Mapping, name: str) -> None:
    """ValueError naming symbols and functions of t that are neither coordinates, t nor parameters."""
    functions = set().union(*(sp.sympify(e).atoms(AppliedUndef) for e in exprs)) - set(q)
    symbols = set().union(*(sp.sympify(e).free_symbols for e in exprs)) - {t} - set(parameters)
    unknown = sorted(map(str, functions | symbols))
    if unknown:
        raise ValueError(f"{name}: undeclared symbols {', '.join(unknown)}; declare them as "
                         f"coordinates q or give their values in parameters")


def _linear_in(c: sp.Expr, D: Sequence) -> bool:
    """Whether ``c`` is affine in the derivatives ``D`` and depends on at least one of them."""
    first = [sp.diff(c, d) for d in D]
    return any(f != 0 for f in first) and not any(f.has(*D) for f in first)


def choose_dependent(J: sp.Matrix, q: Sequence, dependent, rng=np.random.default_rng(0)) -> list[int]:
    """Indices ρ of the dependent p-th derivatives: the given ones, or the first columns of
    ``J = ∂c/∂q^(p)`` that are independent at a random point."""
    if dependent is not None:
        index = [list(q).index(d) if d in q else -1 for d in dependent]
        if -1 in index or len(index) != J.rows:
            raise ValueError(f"dependent: expected {J.rows} of the coordinates q, got {list(dependent)}")
        return index
    J_num = J
    for atoms in (sorted(J.atoms(sp.Derivative), key=lambda d: -d.derivative_count),
                  J.atoms(AppliedUndef), J.free_symbols):
        J_num = J_num.subs({a: rng.uniform(0.3, 1.3) for a in atoms})
    J_num = np.array(J_num.evalf(), dtype=float)
    chosen: list[int] = []
    for j in range(J.cols):
        if np.linalg.matrix_rank(J_num[:, chosen + [j]]) == len(chosen) + 1:
            chosen.append(j)
        if len(chosen) == J.rows:
            return chosen
    raise ValueError("constraints: the Jacobian ∂c/∂q^(p) is rank deficient (constraints dependent)")


@dataclass(frozen=True)
class ProgramEquations:
    """The GPME of Jarzębowska (2002) eqs. 6.29–6.33 and their constraints.

    Attributes
    ----------
    q, t : coordinates (functions of t) and time.
    p : order of the constraints.
    independent, dependent : the coordinates q_λ and q_ρ of (6.29).
    a : sympy Matrix a_ρλ of (6.29); ``a_rho`` the column a_ρ.
    equations : the l equations ∂R_p*/∂q_λ^(p) = 0 as written in (6.33) (left-hand sides).
    constraints : the constraints c = 0 (of order p) used in the simulation.
    """

    q: tuple
    t: sp.Symbol
    p: int
    independent: tuple
    dependent: tuple
    a: sp.Matrix
    a_rho: sp.Matrix
    equations: sp.Matrix
    constraints: sp.Matrix
    equations_regular: sp.Matrix = field(repr=False)
    parameters: Mapping = field(default_factory=dict, repr=False)

    @property
    def m(self) -> int:
        """Order of the integrated system, max(2, p); the state is (q, q̇, …, q^(m−1))."""
        return max(2, self.p)

    @cached_property
    def _compiled(self):
        """A(t, x) q^(m) = b(t, x) from the (m−2)-times differentiated GPME and the
        (m−p)-times differentiated constraints, lambdified with common subexpressions."""
        t, m, n = self.t, self.m, len(self.q)
        rows = [sp.diff(e, t, m - 2) for e in self.equations_regular]
        rows += [sp.diff(c, t, m - self.p) for c in self.constraints]
        rows = sp.Matrix(rows).subs(self.parameters)
        names = [[sp.Dummy(f"{qi.func.__name__}_{k}") for qi in self.q] for k in range(m + 1)]
        rows = replace_derivatives(rows, self.q, t, names)
        A = rows.jacobian(names[m])
        b = -rows.subs({s: 0 for s in names[m]})
        state = [s for level in names[:m] for s in level]
        return (sp.lambdify([t, state], A, modules="numpy", cse=True),
                sp.lambdify([t, state], b, modules="numpy", cse=True), n)

    def rhs(self, t: float, x: np.ndarray) -> np.ndarray:
        """dx/dt for the state x = (q, q̇, …, q^(m−1)): the last block solves A q^(m) = b."""
        A, b, n = self._compiled
        q_m = np.linalg.solve(np.asarray(A(t, x), dtype=float), np.asarray(b(t, x), dtype=float).ravel())
        return np.concatenate([x[n:], q_m])

    def simulate(self, x0, t_span, t_eval=None, rtol: float = 1e-10, atol: float = 1e-12):
        """Integrate from ``x0 = (q, q̇, …, q^(m−1))`` at ``t_span[0]`` (DOP853).

        As in Jarzębowska (2002), §6.4, the initial state includes the accelerations when p = 3;
        it need not satisfy the constraint c = 0 itself: only its derivative of order
        m − p is imposed, so c keeps its initial value (Fig. 3).
        """
        x0 = np.asarray(x0, dtype=float).ravel()
        size = self.m * len(self.q)
        if x0.size != size:
            raise ValueError(f"x0: expected {size} values (q, q̇, …, q^({self.m - 1})), got {x0.size}")
        return solve_ivp(self.rhs, t_span, x0, method="DOP853", t_eval=t_eval, rtol=rtol, atol=atol)


def program_motion_equations(T, q: Sequence, constraints: Sequence, t: sp.Symbol, Q: Sequence | None = None,
                             parameters: Mapping | None = None, dependent: Sequence | None = None,
                             differentiate: bool = False) -> ProgramEquations:
    """Generalized program motion equations for constraints of order p (Jarzębowska (2002) 6.30–6.33).

    Parameters
    ----------
    T : sympy expression, kinetic energy in q(t), q̇(t) (and t).
    q : coordinates, undefined functions of ``t`` (e.g. ``dynamicsymbols``).
    constraints : expressions c = 0, all of the same order p ≥ 1, linear in the q^(p).
    t : the time symbol.
    Q : generalized forces (default zero), one per coordinate, free of q^(p).
    parameters : values of the other symbols, ``{symbol: number}``.
    dependent : the coordinates q_ρ solved for in (6.29) (default: the first possible).
    differentiate : differentiate constraints in time until linear in their highest
        derivatives (as Jarzębowska (2002) does with the curvature constraint (4.3)).

    Examples
    --------
    A particle whose speed is prescribed by ẋ² + ẏ² = 1 (p = 1, differentiated to p = 2):

    >>> from sympy.physics.mechanics import dynamicsymbols
    >>> t = sp.Symbol("t"); x, y = dynamicsymbols("x y")
    >>> T = (x.diff(t)**2 + y.diff(t)**2) / 2
    >>> gpme = program_motion_equations(T, [x, y], [x.diff(t)**2 + y.diff(t)**2 - 1], t, differentiate=True)
    >>> gpme.p, gpme.dependent
    (2, (x(t),))
    """
    parameters = dict(parameters or {})
    q, Q = _checked(T, q, t, Q, parameters)
    c = [sp.sympify(ci) for ci in constraints]
    if not 0 < len(c) < len(q):
        raise ValueError(f"constraints: expected between 1 and {len(q) - 1} constraints, got {len(c)}")
    check_declared(c, q, t, parameters, "constraints")
    c = [_linearised(ci, q, t, differentiate) for ci in c]
    orders = sorted({_order(ci, q, t) for ci in c})
    if len(orders) > 1:
        raise ValueError(f"constraints: all must have the same order p, got orders {orders}; "
                         f"differentiate the lower-order ones in time")
    p = orders[0]
    D = [qi.diff(t, p) for qi in q]
    J = sp.Matrix(c).jacobian(D)
    rho = choose_dependent(J, q, dependent)
    lam = [j for j in range(len(q)) if j not in rho]
    J_d, J_i = J[:, rho], J[:, lam]
    c0 = sp.Matrix(c).subs({d: 0 for d in D})
    a, a_rho = -J_d.LUsolve(J_i), -J_d.LUsolve(c0)
    g = _gpme_gradient(T, q, t, p, Q)
    g_lam, g_rho = g.extract(lam, [0]), g.extract(rho, [0])
    equations = (g_lam + a.T * g_rho).applyfunc(sp.simplify)
    equations_regular = J_d.det() * g_lam - (J_d.adjugate() * J_i).T * g_rho  # (6.33) × det J_d, pole-free
    return ProgramEquations(q, t, p, tuple(q[j] for j in lam), tuple(q[j] for j in rho), a, a_rho,
                            equations, sp.Matrix(c), equations_regular, parameters)


def _linearised(c: sp.Expr, q: Sequence, t: sp.Symbol, differentiate: bool) -> sp.Expr:
    """The constraint itself if linear in its highest derivatives, else (if allowed) its time derivative."""
    p = _order(c, q, t)
    if p == 0:
        raise ValueError(f"constraints: {c} = 0 is holonomic (order 0); differentiate it to order ≥ 1")
    D = [qi.diff(t, p) for qi in q]
    if _linear_in(c, D):
        return c
    if not differentiate:
        raise ValueError(f"constraints: {c} = 0 is of order {p} but not linear in any of the derivatives "
                         f"{', '.join(map(str, D))}; pass differentiate=True to differentiate it in time "
                         f"(its derivative is linear in the order-{p + 1} derivatives)")
    return _linearised(sp.diff(c, t), q, t, differentiate)


def _gpme_gradient(T, q: Sequence, t: sp.Symbol, p: int, Q: sp.Matrix) -> sp.Matrix:
    """∂R_p/∂q^(p) with P_p = [T^(p) − (p+1) T_0^(p)]/p, R_p = P_p − Σ q^(p) Q (6.30, 6.31, 6.25).

    ∂T_0^(p)/∂q_σ^(p) is taken as ∂T/∂q_σ, the coefficient of q_σ^(p) in (6.25). For p ≥ 2 that is
    the plain partial derivative; for p = 1 it holds the q̇ inside ∂T/∂q fixed, which gives
    Nielsen's form ∂Ṫ/∂q̇ − 2 ∂T/∂q = Q (differentiating that q̇ too would add Σ ∂²T/∂q∂q̇ q̇ and
    break the equivalence with Lagrange's equations).
    """
    D = [qi.diff(t, p) for qi in q]
    T_p = sp.diff(T, t, p)
    return sp.Matrix([sp.expand((sp.diff(T_p, d) - (p + 1) * sp.diff(T, qi)) / p - Qi)
                      for qi, d, Qi in zip(q, D, Q)])


def _checked(T, q: Sequence, t: sp.Symbol, Q, parameters: Mapping) -> tuple[tuple, sp.Matrix]:
    """(q, Q as a column, zero by default) after checking q, Q and the symbols of T and Q."""
    q = tuple(q)
    if not q or not all(isinstance(qi, AppliedUndef) and qi.args == (t,) for qi in q):
        raise ValueError(f"q: expected functions of {t} such as dynamicsymbols('x'), got {list(q)}")
    Q = sp.Matrix(Q if Q is not None else [0] * len(q))
    if Q.shape != (len(q), 1):
        raise ValueError(f"Q: expected {len(q)} generalized forces (one per coordinate), got {Q.rows}")
    check_declared([T, *Q], q, t, parameters, "T, Q")
    return q, Q


def _program_equations(T, q: Sequence, t: sp.Symbol, p: int, Q, parameters) -> sp.Matrix:
    """(6.7) of order ``p`` minus Q, after checking the input."""
    q, Q = _checked(T, q, t, Q, dict(parameters or {}))
    return _gpme_gradient(sp.sympify(T), q, t, p, Q)


def nielsen_equations(T, q: Sequence, t: sp.Symbol, Q: Sequence | None = None,
                      parameters: Mapping | None = None) -> sp.Matrix:
    """Nielsen's equations, Jarzębowska (2002) eq. (5.1): the left-hand sides of
    ∂Ṫ/∂q̇_σ − 2 ∂T/∂q_σ − Q_σ = 0 (the GPME (6.7) for p = 1), for any T(t, q, q̇) — by the identity
    (6.6) they equal d/dt ∂T/∂q̇ − ∂T/∂q − Q, also when T is not quadratic in q̇.
    ``parameters``: the other symbols of T and Q (their values are not used here)."""
    return _program_equations(T, q, t, 1, Q, parameters)


def tzenoff_equations(T, q: Sequence, t: sp.Symbol, Q: Sequence | None = None,
                      parameters: Mapping | None = None) -> sp.Matrix:
    """Tzenoff's equations of the second kind, Jarzębowska (2002) eq. (5.2): the left-hand sides of
    ½ (∂T̈/∂q̈_σ − 3 ∂T/∂q_σ) − Q_σ = 0 (the GPME (6.7) for p = 2), for any T(t, q, q̇)."""
    return _program_equations(T, q, t, 2, Q, parameters)


def pseudo_regular_precession(phi, psi, theta, t: sp.Symbol, lam) -> sp.Expr:
    """Grioli's condition for a pseudo-regular precession, Jarzębowska (2002) eq. (4.1),

        p q̇ − q ṗ + r (p² + q²) − λ (p² + q²)^{3/2} = 0,

    with the body rates (4.1a) of the Euler angles φ (spin), ψ (precession), ϑ (nutation),
    p = ψ̇ sin ϑ sin φ + ϑ̇ cos φ, q = ψ̇ sin ϑ cos φ − ϑ̇ sin φ, r = ψ̇ cos ϑ + φ̇: a second-order program
    constraint, linear in ψ̈ and ϑ̈. Expanded it is the paper's (4.2) with ψ̇² sin² ϑ in the radicand
    (p² + q² = ψ̇² sin² ϑ + ϑ̇²), where (4.2) prints φ̇² sin² ϑ, a misprint (tests/symbolic/test_program.py).
    Geometrically the symmetry axis moves on a circular cone of half-angle arccot λ (λ is the
    geodesic curvature of its path on the unit sphere), at any rate: the regular precession
    (ϑ̇ = 0, φ̇, ψ̇ constant) satisfies it iff λ = cot ϑ.
    """
    rate = [f.diff(t) for f in (phi, psi, theta)]
    p = rate[1] * sp.sin(theta) * sp.sin(phi) + rate[2] * sp.cos(phi)
    q = rate[1] * sp.sin(theta) * sp.cos(phi) - rate[2] * sp.sin(phi)
    r = rate[1] * sp.cos(theta) + rate[0]
    unit = {sp.cos(phi) ** 2: 1 - sp.sin(phi) ** 2}  # φ drops out: sin²φ + cos²φ = 1
    transverse, turning = (sp.expand(sp.expand(e).subs(unit))
                           for e in (p**2 + q**2, p * q.diff(t) - q * p.diff(t)))
    return sp.expand(turning + r * transverse) - lam * transverse ** sp.Rational(3, 2)

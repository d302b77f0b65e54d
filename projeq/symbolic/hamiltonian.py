"""Hamiltonian tools: Poisson brackets, constants of motion, Hamilton–Jacobi separation.

For canonical variables (q, p) and functions u(q, p, t), v(q, p, t) (the problem-seminar book
on Lagrange's equations, lecture notes §VI.2 eqs. (165)–(166), §VII eqs. (181)–(190); Seminars
10 and 11):

* the Poisson bracket [u, v] = Σ_i (∂u/∂q_i ∂v/∂p_i − ∂u/∂p_i ∂v/∂q_i)   (165);
* the rate of u along the motion, du/dt = [u, H] + ∂u/∂t   (166), so u is a constant of
  motion iff [u, H] + ∂u/∂t ≡ 0;
* Hamilton's characteristic function W(q, α) with H(q, ∂W/∂q) = E   (183), found by additive
  separation W = Σ_i W_i(q_i, α)   (188)–(190) when H is separable: every cyclic coordinate q_c
  (∂H/∂q_c = 0) has p_c = α_c and W_c = α_c q_c; the rest of H must then be a sum
  Σ_j f_j(q_j, p_j) (+ a constant), each f_j(q_j, ∂W_j/∂q_j) = α_j with one α replaced by
  E − Σ of the others, and W_j = ∫ p_j(q_j, α_j) dq_j.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import sympy as sp

__all__ = ["Separation", "constant_of_motion_rate", "is_constant_of_motion", "poisson_bracket",
           "separate_hamilton_jacobi"]


def _pairs(q: Sequence, p: Sequence) -> tuple[tuple, tuple]:
    q, p = tuple(q), tuple(p)
    if len(q) != len(p) or not q:
        raise ValueError(f"q, p: expected as many momenta as coordinates (at least one), got {len(q)} and {len(p)}")
    if not all(isinstance(x, sp.Symbol) for x in q + p):
        raise ValueError(f"q, p: expected sympy Symbols, got {list(q + p)}")
    return q, p


def poisson_bracket(u, v, q: Sequence, p: Sequence) -> sp.Expr:
    """[u, v] = Σ_i (∂u/∂q_i ∂v/∂p_i − ∂u/∂p_i ∂v/∂q_i) (the book's eq. (165); Seminar 11, eq. (1)).

    >>> x, px = sp.symbols("x p_x")
    >>> poisson_bracket(x, px, [x], [px])
    1
    """
    q, p = _pairs(q, p)
    u, v = sp.sympify(u), sp.sympify(v)
    return sp.Add(*(u.diff(qi) * v.diff(pi) - u.diff(pi) * v.diff(qi) for qi, pi in zip(q, p)))


def constant_of_motion_rate(f, H, q: Sequence, p: Sequence, t: sp.Symbol | None = None) -> sp.Expr:
    """df/dt = [f, H] + ∂f/∂t along the motion of the Hamiltonian ``H`` (the book's eq. (166)), simplified."""
    rate = poisson_bracket(f, H, q, p) + (sp.sympify(f).diff(t) if t is not None else 0)
    return sp.simplify(sp.expand(rate))


def is_constant_of_motion(f, H, q: Sequence, p: Sequence, t: sp.Symbol | None = None) -> bool:
    """True iff [f, H] + ∂f/∂t ≡ 0 (eq. (166)): f(q, p, t) keeps its value along every motion of ``H``."""
    return constant_of_motion_rate(f, H, q, p, t) == 0


@dataclass(frozen=True)
class Separation:
    """Additively separated characteristic function W(q, α) = Σ_i W_i(q_i, α) (eqs. (183), (188)).

    ``W``: the pieces W_i in the order of ``q``; ``momenta``: p_i = ∂W_i/∂q_i; ``functions``:
    f_i(q_i, p_i) (or p_c for a cyclic q_c) whose value is the separation constant ``constants[i]``
    (an expression in ``alpha`` and ``E``; these f_i are the constants of motion the separation
    finds); ``E``: the energy symbol, H = E.
    """

    q: tuple
    p: tuple
    W: tuple
    momenta: tuple
    functions: tuple
    constants: tuple
    E: sp.Symbol

    @property
    def characteristic_function(self) -> sp.Expr:
        """W = Σ_i W_i."""
        return sp.Add(*self.W)


def separate_hamilton_jacobi(H, q: Sequence, p: Sequence, E: sp.Symbol | None = None, root: int = -1,
                             integrate: bool = True, cyclic: bool = True) -> Separation:
    """Separate H(q, ∂W/∂q) = E additively (the book's §VII.3–4, eqs. (183), (188)–(190)).

    Cyclic coordinates first (p_c = α_c, W_c = α_c q_c, as in Problem 41's p_θ = α₂;
    ``cyclic=False`` treats them like the others, as Problem 40's first solution does); the
    remaining H must be a sum of terms each in one pair (q_j, p_j) only (Problem 40's
    p_x²/2m + p_y²/2m + m g y). Each f_j(q_j, p_j) = α_j is solved for p_j (``root``: which of
    sympy's roots, default the last, the positive square root for a quadratic), the last pair
    takes α = E − Σ of the others, and W_j = ∫ p_j dq_j (``integrate=False``, or if sympy fails:
    an unevaluated Integral). Symbols: α_i = ``alpha_<q_i>``, E (default ``Symbol("E")``).

    ValueError if H depends on time (the symbol ``t``), a term couples two non-cyclic pairs
    (not additively separable in these coordinates).
    """
    q, p = _pairs(q, p)
    H = sp.expand(sp.sympify(H))
    E = sp.Symbol("E") if E is None else E
    if sp.Symbol("t") in H.free_symbols:
        raise ValueError("H: depends on t; the characteristic function W needs a conserved H = E")
    alpha = {qi: sp.Symbol(f"alpha_{qi}") for qi in q}
    ignorable = [i for i, qi in enumerate(q) if cyclic and H.diff(qi) == 0]
    ignorable = ignorable[:-1] if len(ignorable) == len(q) else ignorable  # one pair carries E
    H = sp.expand(H.subs({p[i]: alpha[q[i]] for i in ignorable}))
    rest = [i for i in range(len(q)) if i not in ignorable]
    parts, constant = {i: sp.S.Zero for i in rest}, sp.S.Zero
    for term in sp.Add.make_args(H):
        owners = [i for i in rest if term.has(q[i]) or term.has(p[i])]
        if len(owners) > 1:
            raise ValueError(f"H: the term {term} couples {[q[i] for i in owners]}; not additively separable in q")
        if owners:
            parts[owners[0]] += term
        else:
            constant += term
    W, momenta, functions, constants = [], [], [], []
    for i, qi in enumerate(q):
        if i in ignorable:
            W.append(alpha[qi] * qi)
            momenta.append(alpha[qi])
            functions.append(p[i])
            constants.append(alpha[qi])
            continue
        value = (E - constant - sum(alpha[q[j]] for j in rest if j != i)) if i == rest[-1] else alpha[qi]
        roots = sp.solve(sp.Eq(parts[i], value), p[i])
        if not roots:
            raise ValueError(f"H: cannot solve its {qi}-part {parts[i]} = {value} for {p[i]}")
        p_i = sp.simplify(roots[root])
        W.append(_integral(p_i, qi, integrate))
        momenta.append(p_i)
        functions.append(parts[i])
        constants.append(value)
    return Separation(q, p, tuple(W), tuple(momenta), tuple(functions), tuple(constants), E)


def _integral(p_i, q_i, integrate: bool) -> sp.Expr:
    """W_i = ∫ p_i dq_i, unevaluated if sympy cannot (or is not asked to) integrate."""
    if not integrate:
        return sp.Integral(p_i, q_i)
    result = sp.integrate(p_i, q_i)
    return result if not result.has(sp.Integral) else sp.Integral(p_i, q_i)

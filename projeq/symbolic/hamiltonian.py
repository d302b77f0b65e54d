"""Hamiltonian tools: Poisson brackets, constants of motion, Hamilton–Jacobi separation, canonical
transformations, action-angle variables, Routh's elimination of cyclic coordinates.

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
  E − Σ of the others, and W_j = ∫ p_j(q_j, α_j) dq_j;
* Hamilton's principal function S = W − E t   (187), a solution of H(q, ∂S/∂q) + ∂S/∂t = 0 (174);
* canonical transformations from a generating function F of one of the four types (q, Q), (q, P),
  (p, Q), (p, P)   (162)–(164), and the new Hamiltonian K = H + ∂F/∂t;
* the action J = ∮ p dq of a libration and its frequency ν = ∂H/∂J = 1/τ   (202)–(207);
* Routh's modified Lagrangian L' = L − Σ c_k q̇_k for cyclic coordinates q_k with momenta
  ∂L/∂q̇_k = c_k   (the book's lecture notes §II.7, eq. (47)).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import sympy as sp
from scipy.integrate import quad

__all__ = ["CanonicalTransformation", "Libration", "Routhian", "Separation", "canonical_transformation",
           "constant_of_motion_rate", "is_constant_of_motion", "poisson_bracket", "principal_function",
           "routhian", "separate_hamilton_jacobi"]


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


def principal_function(separation: Separation, t: sp.Symbol | None = None) -> sp.Expr:
    """Hamilton's principal function S(q, α, t) = W(q, α) − E t (the book's eq. (187)) of a
    conservative system, from its separated characteristic function W (H = E)."""
    t = sp.Symbol("t") if t is None else t
    return separation.characteristic_function - separation.E * t


#: The relations (163) of the four generating functions: (old pair solved from ∂F, new pair from ∂F),
#: as (variable, sign, argument of F): variable = sign · ∂F/∂argument.
_GENERATING_RELATIONS = {1: (("p", 1, "q"), ("P", -1, "Q")), 2: (("p", 1, "q"), ("Q", 1, "P")),
                         3: (("q", -1, "p"), ("P", -1, "Q")), 4: (("q", -1, "p"), ("Q", 1, "P"))}


@dataclass(frozen=True)
class CanonicalTransformation:
    """(q, p) → (Q, P) generated by F of ``kind`` 1–4 (the book's eqs. (162)–(164)).

    ``relations``: the 2n expressions that vanish on the transformation,
    F₁(q, Q, t): p = ∂F/∂q, P = −∂F/∂Q;   F₂(q, P, t): p = ∂F/∂q, Q = ∂F/∂P;
    F₃(p, Q, t): q = −∂F/∂p, P = −∂F/∂Q;   F₄(p, P, t): q = −∂F/∂p, Q = ∂F/∂P.
    """

    kind: int
    F: sp.Expr
    q: tuple
    p: tuple
    Q: tuple
    P: tuple
    t: sp.Symbol | None
    relations: tuple

    def old_variables(self, root: int = -1) -> dict:
        """{q_i: q_i(Q, P, t), p_i: p_i(Q, P, t)}: the relations solved for the old variables
        (``root``: which of sympy's solutions, default the last)."""
        solutions = sp.solve(list(self.relations), list(self.q + self.p), dict=True)
        if not solutions:
            raise ValueError(f"F: sympy cannot solve the relations {list(self.relations)} for q, p")
        return solutions[root]

    def new_hamiltonian(self, H, root: int = -1) -> sp.Expr:
        """K(Q, P, t) = H + ∂F/∂t (the book's eq. (164)), in the new variables."""
        old = self.old_variables(root)
        rate = self.F.diff(self.t) if self.t is not None else 0
        return sp.simplify((sp.sympify(H) + rate).subs(old))


def canonical_transformation(F, kind: int, q: Sequence, p: Sequence, Q: Sequence, P: Sequence,
                             t: sp.Symbol | None = None) -> CanonicalTransformation:
    """The canonical transformation generated by ``F`` of type ``kind`` (1: F(q, Q, t), 2: F(q, P, t),
    3: F(p, Q, t), 4: F(p, P, t); the book's eqs. (162)–(163)).

    >>> q, p, Q, P = sp.symbols("q p Q P")
    >>> canonical_transformation(q * P, 2, [q], [p], [Q], [P]).relations   # the identity
    (-P + p, Q - q)
    """
    if kind not in _GENERATING_RELATIONS:
        raise ValueError(f"kind: expected 1, 2, 3 or 4 (F(q, Q), F(q, P), F(p, Q), F(p, P)), got {kind!r}")
    variables = {"q": tuple(q), "p": tuple(p), "Q": tuple(Q), "P": tuple(P)}
    _pairs(variables["q"], variables["p"])
    _pairs(variables["Q"], variables["P"])
    if len(variables["q"]) != len(variables["Q"]):
        raise ValueError(f"Q, P: expected {len(variables['q'])} new pairs (as many as q), "
                         f"got {len(variables['Q'])}")
    F = sp.sympify(F)
    (old, sign_old, arg_old), (new, sign_new, arg_new) = _GENERATING_RELATIONS[kind]
    allowed = set(variables[arg_old] + variables[arg_new]) | ({t} if t is not None else set())
    foreign = (F.free_symbols - allowed) & set().union(*map(set, variables.values()))
    if foreign:
        raise ValueError(f"F: a type-{kind} generating function depends on ({arg_old}, {arg_new}, t) only, "
                         f"got {sorted(map(str, foreign))}")
    relations = tuple(v - sign_old * F.diff(a) for v, a in zip(variables[old], variables[arg_old]))
    relations += tuple(v - sign_new * F.diff(a) for v, a in zip(variables[new], variables[arg_new]))
    return CanonicalTransformation(kind, F, *variables.values(), t, relations)


_E = sp.Dummy("E")  # the energy while p(q, E) is differentiated and integrated numerically


@dataclass(frozen=True)
class Libration:
    """A libration of one degree of freedom, H(q, p) = E between the turning points q₋ < q₊ (the
    book's §VII.5, eqs. (202)–(207)): the action J = ∮ p dq = 2 ∫ p(q, E) dq over [q₋, q₊] and the
    frequency ν = ∂H/∂J = 1/(∂J/∂E) = 1/τ of the angle variable w = ν t + β.

    Numerically (``E`` and the turning points numbers), q = c + h sin φ (c, h the centre and half
    width of [q₋, q₊]) removes the square-root singularities of p and ∂p/∂E = 1/q̇ at the turning
    points and the integrals are Gauss–Kronrod quadratures (``scipy.integrate.quad``, to 1e-11
    relative); symbolically (``E`` a symbol) sympy integrates over q.
    """

    H: sp.Expr
    q: sp.Symbol
    p: sp.Symbol

    def momentum(self, E) -> sp.Expr:
        """p(q, E) on the upper branch of the loop: sympy's last root of H(q, p) = E (the positive
        square root when H is quadratic in p)."""
        roots = sp.solve(sp.Eq(self.H, E), self.p)
        if not roots:
            raise ValueError(f"H: cannot solve H = E for {self.p}")
        return roots[-1]

    def _check(self, E, turning_points):
        q_minus, q_plus = (sp.sympify(v) for v in turning_points)
        for q_turn in (q_minus, q_plus):
            rest = sp.sympify(self.H).subs({self.q: q_turn, self.p: 0}) - E
            scale = max(1.0, abs(float(E))) if sp.sympify(E).is_number else 1.0
            close = rest.is_number and abs(float(rest)) <= 1e-9 * scale
            if not close and sp.simplify(rest) != 0:
                raise ValueError(f"turning_points: H({self.q} = {q_turn}, {self.p} = 0) ≠ E = {E}")
        if (q_plus - q_minus).is_number and not float(q_plus - q_minus) > 0:
            raise ValueError(f"turning_points: expected q₋ < q₊, got {turning_points}")
        return q_minus, q_plus

    def _loop_integral(self, integrand, E, turning_points) -> float:
        """2 ∫ integrand dq over [q₋, q₊] with q = c + h sin φ, by quadrature."""
        q_minus, q_plus = (float(v) for v in self._check(E, turning_points))
        c, h = (q_plus + q_minus) / 2, (q_plus - q_minus) / 2
        f = sp.lambdify(self.q, integrand.subs(_E, E), modules="numpy")
        value, _ = quad(lambda phi: f(c + h * np.sin(phi)) * h * np.cos(phi), -np.pi / 2, np.pi / 2,
                        epsabs=0, epsrel=1e-11, limit=200)
        return 2 * value

    def action(self, E, turning_points) -> sp.Expr | float:
        """J(E) = ∮ p dq (eq. (202))."""
        if not sp.sympify(E).is_number:
            q_minus, q_plus = self._check(E, turning_points)
            return sp.simplify(2 * sp.integrate(self.momentum(E), (self.q, q_minus, q_plus)))
        return self._loop_integral(self.momentum(_E), E, turning_points)

    def frequency(self, E, turning_points) -> sp.Expr | float:
        """ν = ∂H/∂J (eq. (205)) = 1/τ (eq. (207)), with ∂J/∂E = ∮ ∂p/∂E dq (the boundary terms
        vanish: p = 0 at the turning points)."""
        if not sp.sympify(E).is_number:
            return sp.simplify(1 / sp.diff(self.action(E, turning_points), E))
        return 1 / self._loop_integral(sp.diff(self.momentum(_E), _E), E, turning_points)


@dataclass(frozen=True)
class Routhian:
    """Routh's modified Lagrangian L' = L − Σ c_k q̇_k with the cyclic velocities eliminated by
    ∂L/∂q̇_k = c_k (the book's lecture notes §II.7, steps (a)–(b), eq. (47)).

    ``R``: L' in the remaining (q, q̇) and the constants ``c``; Lagrange's equations of L' in the
    remaining coordinates are those of L with q̇_k = ``cyclic_velocities[k]`` (q, q̇, c).
    """

    R: sp.Expr
    cyclic: tuple
    c: tuple
    cyclic_velocities: dict


def routhian(L, q: Sequence, q_dot: Sequence, cyclic: Sequence, momenta: Sequence | None = None) -> Routhian:
    """Eliminate the cyclic coordinates ``cyclic`` (∂L/∂q_k = 0) of L(q, q̇) given in plain symbols
    ``q``, ``q_dot`` (the book's §II.7, eq. (47)); ``momenta``: the symbols c_k of the conserved
    momenta ∂L/∂q̇_k (default ``c_<q_k>``)."""
    q, q_dot, cyclic = tuple(q), tuple(q_dot), tuple(cyclic)
    _pairs(q, q_dot)
    L = sp.sympify(L)
    if not cyclic or any(qk not in q for qk in cyclic):
        raise ValueError(f"cyclic: expected some of the coordinates {list(q)}, got {list(cyclic)}")
    coupled = [qk for qk in cyclic if L.diff(qk) != 0]
    if coupled:
        raise ValueError(f"cyclic: L depends on {coupled}; only coordinates absent from L are cyclic")
    c = tuple(momenta) if momenta is not None else tuple(sp.Symbol(f"c_{qk}") for qk in cyclic)
    if len(c) != len(cyclic):
        raise ValueError(f"momenta: expected {len(cyclic)} symbols (one per cyclic coordinate), got {len(c)}")
    velocities = [q_dot[q.index(qk)] for qk in cyclic]
    momenta_equations = sp.Matrix([L.diff(v) - ck for v, ck in zip(velocities, c)])
    A = momenta_equations.jacobian(velocities)
    if A.has(*velocities):  # not quadratic in the cyclic velocities: sympy's general solver
        solutions = sp.solve(list(momenta_equations), velocities, dict=True)
        if len(solutions) != 1:
            raise ValueError(f"L: ∂L/∂q̇_k = c_k has {len(solutions)} solutions for {velocities}; "
                             f"expected one")
        column = sp.Matrix([solutions[0][v] for v in velocities])
    else:
        column = A.LUsolve(-momenta_equations.subs({v: 0 for v in velocities}))
    solved = {v: sp.factor(sp.cancel(e)) for v, e in zip(velocities, column)}
    R = (L - sum(ck * v for ck, v in zip(c, velocities))).subs(solved)
    return Routhian(sp.expand(R), cyclic, c, solved)

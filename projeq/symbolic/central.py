"""Bremer's Central Equation B(2) as code: one description, four formulations (docs/theory.md §12).

H. Bremer, "Problems in fast moving non-holonomic elastic systems", eq. (2):

    d/dt[(∂T/∂ṡ) δs] − δT − δW = 0,    ṡ = H(q) q̇,  q̇ = K ṡ,  K = H⁻¹.

:func:`central_equation` takes what B(2) needs — the bodies (their mass-centre velocities v_c and
angular velocities ω in the minimal velocities ṡ, in the coordinates of a frame R turning with ω_IR,
which give T = Σ ½ (m v_cᵀ v_c + ωᵀ I_c ω)), the impressed forces and torques (which give
δW = Qᵀ δs, Q = Σ (∂v_c/∂ṡ)ᵀ f + (∂ω/∂ṡ)ᵀ M), H(q), and the speeds that non-holonomic constraints
hold at zero (ṡ_ν = 0) — and derives each formulation by the step the paper names:

* **Hamel**, B(3)–(4): ṡ = H q̇ kept with every speed; d δs − δ ds = Σ β ṡ δs; the constraints go in
  after the derivation (B(8) → B(9));
* **Projection Equation**, B(10)–(12): the Cartesian velocities with the constraints already in
  (B(11)), projected with their functional matrix; no derivative of T;
* **Kane**: B(10) with the accelerations instead of the momenta, Σ (∂v_c/∂u)ᵀ(m a − f) +
  (∂ω/∂u)ᵀ(I_c α + ω × I_c ω − M) = 0 (a, α inertial, in R's coordinates);
* **Lagrange with multipliers**: ṡ = q̇ (H = E) in all coordinates, the constrained rows of H as the
  Pfaffian constraints A q̇ = 0 adjoined with λ: d/dt ∂T/∂q̇ − ∂T/∂q − Hᵀ Q = Aᵀ λ.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Mapping, Sequence

import sympy as sp

from .algebra import trig_normal
from .hamel import check_regular, hamel_equations
from .lagrange import MultiplierSystem, multiplier_system
from .projection import Body, GaussForm, projection_equation, t
from .validation import check_symbols, matrix, symbol_vector

__all__ = ["CentralEquation", "central_equation"]


@dataclass(frozen=True)
class CentralEquation:
    """B(2) for ``bodies`` in the speeds ``s`` (ṡ = H q̇); ``constrained``: the speeds held at zero.

    Attributes ``T`` and ``Q`` are B(2)'s kinetic energy and the generalised forces of δW = Qᵀ δs, in
    (q, ṡ); ``independent`` the speeds left free by the constraints; ``K`` = H⁻¹.
    """

    bodies: Mapping[str, Body]
    q: tuple
    s: tuple
    H: sp.Matrix
    constrained: tuple
    parameters: tuple

    @cached_property
    def K(self) -> sp.Matrix:
        """q̇ = K ṡ, K = H⁻¹."""
        return self.H.inv().applyfunc(sp.simplify)

    @cached_property
    def _vectors(self) -> dict:
        return {name: body.vectors(name) for name, body in self.bodies.items()}

    @cached_property
    def T(self) -> sp.Expr:
        """T = Σ ½ (m v_cᵀ v_c + ωᵀ I_c ω), with every speed (constrained ones included), reduced modulo
        sin² + cos² = 1 (:func:`trig_normal`; velocities in a turning frame R carry its rotation,
        which cancels in T and would otherwise swell every derivative Hamel's equations take)."""
        T = sum((b["m"] * b["v_c"].dot(b["v_c"]) + b["omega"].dot(b["I_c"] * b["omega"])) / 2
                for b in self._vectors.values())
        return sp.expand(trig_normal(T, self.q))

    @cached_property
    def Q(self) -> sp.Matrix:
        """δW = Qᵀ δs: Q = Σ (∂v_c/∂ṡ)ᵀ f + (∂ω/∂ṡ)ᵀ M."""
        s = sp.Matrix(self.s)
        return sum((b["v_c"].jacobian(s).T * b["f"] + b["omega"].jacobian(s).T * b["M"]
                    for b in self._vectors.values()), sp.zeros(len(self.s), 1))

    @property
    def independent(self) -> tuple:
        return tuple(x for x in self.s if x not in self.constrained)

    @cached_property
    def _free(self) -> list[int]:
        return [self.s.index(x) for x in self.independent]

    @cached_property
    def K_independent(self) -> sp.Matrix:
        """q̇ = K_I u on the constraints: the columns of K of the independent speeds u."""
        return self.K.extract(list(range(len(self.q))), self._free)

    def _on_constraints(self, expr):
        return expr.subs({x: 0 for x in self.constrained})

    def _gauss(self, residual: sp.Matrix, s_ddot: Sequence) -> GaussForm:
        """The Gauss form M s̈ = rhs of residuals linear in s̈ (independent speeds)."""
        M, rhs = sp.linear_eq_to_matrix([sp.expand(r) for r in residual], list(s_ddot))
        return GaussForm(M, rhs, self.q, self.independent, self.K_independent, t, self.parameters)

    def hamel_residuals(self, s_ddot: Sequence | None = None) -> sp.Matrix:
        """B(3) for every speed, before the constraints (the car's B(8)); s̈ as ``s_ddot``
        (default ``<s>_dot``)."""
        s_ddot = s_ddot or sp.symbols([f"{x}_dot" for x in self.s])
        return hamel_equations(self.T, self.q, self.s, self.H, self.Q, s_ddot, t, self.parameters)

    def hamel(self) -> GaussForm:
        """Hamel's equations B(3) of the independent speeds, the constraints inserted after the
        derivation (B(8) → B(9))."""
        s_ddot = sp.symbols([f"{x}_dot" for x in self.s])
        residual = self.hamel_residuals(s_ddot).extract(self._free, [0])
        residual = residual.subs({s_ddot[self.s.index(x)]: 0 for x in self.constrained})
        return self._gauss(self._on_constraints(residual), [s_ddot[j] for j in self._free])

    def _constrained_bodies(self) -> dict:
        """The bodies with ṡ_ν = 0 already in their velocities (B(11))."""
        return {name: Body(*(self._on_constraints(b[k]) for k in ("v_c", "omega")), b["m"], b["I_c"],
                           *(self._on_constraints(b[k]) for k in ("f", "M", "omega_IR")))
                for name, b in self._vectors.items()}

    def projection(self) -> GaussForm:
        """The Projection Equation B(10) with the constraints in the velocities first (B(11)–(12))."""
        return projection_equation(self._constrained_bodies(), self.q, self.independent, self.K_independent,
                                   self.parameters)

    def kane(self) -> GaussForm:
        """Kane's equations F_r + F_r* = 0 for the independent speeds u: partial velocities ∂v_c/∂u,
        ∂ω/∂u of the constrained velocities; inertia forces from the inertial accelerations
        a = v̇_c + ω_IR × v_c, α = ω̇ + ω_IR × ω (in R's coordinates) and Euler's I_c α + ω × I_c ω."""
        u = sp.Matrix(self.independent)
        u_dot = sp.Matrix(sp.symbols([f"{x}_dot" for x in self.independent]))
        q_dot = self.K_independent * u

        def rate(x):  # d/dt x(q, u, t) with u̇ = u_dot
            return x.jacobian(u) * u_dot + x.jacobian(sp.Matrix(self.q)) * q_dot + x.diff(t)

        residual = sp.zeros(len(u), 1)
        for b in self._constrained_bodies().values():
            b = b.vectors("body")
            v, w, w_IR = b["v_c"], b["omega"], b["omega_IR"]
            a, alpha = rate(v) + w_IR.cross(v), rate(w) + w_IR.cross(w)
            residual += (v.jacobian(u).T * (b["m"] * a - b["f"])
                         + w.jacobian(u).T * (b["I_c"] * alpha + w.cross(b["I_c"] * w) - b["M"]))
        return self._gauss(residual, list(u_dot))

    def lagrange(self, values: Mapping | None = None) -> MultiplierSystem:
        """Lagrange's equations with multipliers in all coordinates (ṡ = q̇, H = E): L = T(q, H q̇), the
        generalised forces Hᵀ Q, the constrained rows of H as A q̇ = 0 (``MultiplierSystem``; its
        ``lagrange_equations()`` are d/dt ∂L/∂q̇ − ∂L/∂q − Hᵀ Q − Aᵀ λ). ``values``: numbers for the
        parameters (default: the parameters stand for themselves)."""
        q_t = [sp.Function(str(x))(t) for x in self.q]
        on_q = dict(zip(self.q, q_t))
        H = self.H.subs(on_q)
        on_speeds = dict(zip(self.s, H * sp.Matrix([x.diff(t) for x in q_t])))
        L = self.T.subs(on_q).subs(on_speeds)
        Q = H.T * self.Q.subs(on_q).subs(on_speeds)
        A = H.extract([self.s.index(x) for x in self.constrained], list(range(len(self.q))))
        return multiplier_system(L, q_t, t, A=A if A.rows else None, Q=Q,
                                 parameters=dict(values) if values is not None else {p: p for p in self.parameters})


def central_equation(bodies: Mapping[str, Body], q: Sequence, s: Sequence, H, constrained: Sequence = (),
                     parameters: Sequence = ()) -> CentralEquation:
    """Bremer's Central Equation B(2) for ``bodies`` (name → :class:`Body`, velocities in q, ṡ and t in
    the coordinates of their frame R), the minimal velocities ``s`` with ṡ = ``H``(q) q̇ (square,
    regular), the speeds ``constrained`` to zero by non-holonomic constraints, and the ``parameters``
    (other symbols). Its methods derive Hamel's equations, the Projection Equation, Kane's equations
    and Lagrange's equations with multipliers from it (module docstring).

    >>> m, c, C0, vx, vy, wz = sp.symbols("m c C0 v_x v_y omega_z")
    >>> x, y, g = q = sp.symbols("x y gamma")
    >>> car = Body(v_c=(vx, vy + c * wz, 0), omega=(0, 0, wz), m=m, I_c=sp.diag(0, 0, C0 - m * c**2),
    ...            omega_IR=(0, 0, wz))
    >>> H = sp.Matrix([[sp.cos(g), sp.sin(g), 0], [-sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
    >>> b2 = central_equation({"car": car}, q, (vx, vy, wz), H, constrained=[vy], parameters=(m, c, C0))
    >>> b2.hamel().M, list(b2.hamel().rhs)   # B(9)
    (Matrix([
    [m,  0],
    [0, C0]]), [c*m*omega_z**2, -c*m*omega_z*v_x])
    """
    q, s = tuple(symbol_vector("q", q)), tuple(symbol_vector("s", s))
    parameters = tuple(symbol_vector("parameters", parameters))
    H = matrix("H", H)
    if H.shape != (len(s), len(q)):
        raise ValueError(f"H: expected shape ({len(s)}, {len(q)}) for ṡ = H q̇ (one row per speed), got {H.shape}")
    check_symbols("H", H, set(q) | {t} | set(parameters))
    check_regular(H, q)
    constrained = tuple(symbol_vector("constrained", constrained))
    if any(x not in s for x in constrained) or len(constrained) >= len(s):
        raise ValueError(f"constrained: expected some (not all) of the speeds {list(s)}, got {list(constrained)}")
    if not bodies:
        raise ValueError("bodies: expected at least one body (name → Body)")
    declared = set(q) | set(s) | {t} | set(parameters)
    for name, body in dict(bodies).items():
        for key, value in body.vectors(name).items():
            check_symbols(f"{name}.{key}", value, declared)
    return CentralEquation(dict(bodies), q, s, H, constrained, parameters)

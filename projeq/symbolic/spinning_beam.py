"""The spinning beam of B(16)–(23): Hamilton's principle versus the Projection Equation.

H. Bremer, "Problems in fast moving non-holonomic elastic systems", B(16)–(23). A beam
along x spins with the prescribed angle α(t) about its own axis; v(x, t), w(x, t) are its
bending deflections in the co-rotating frame R (ω_IR = (α̇, 0, 0)); the section is
circular (polar ρI_x = 2ρI). The field equations are derived here with sympy and
linearised in (v, w):

* :func:`hamilton_field_equations` — Hamilton's principle with the Cardan rates
  (α̇, −ẇ′, v̇′) of B(17); reproduces B(18).
* :func:`projection_field_equations` — Newton–Euler residuals of a slice in R projected
  with the operator D̄ of B(22) and its adjoint D (B(21)); reproduces B(23) (with the
  signs of docs/theory.md, "The spinning beam's rotary inertia"); the same integration by
  parts gives the boundary operators B₀, B₁ (:func:`projection_boundary_operators`);
  at constant spin they make a boundary-value problem for the whirl modes (:func:`whirl_equations`),
  solved without Ritz functions by :func:`whirl_frequencies` (Chebyshev collocation).

They differ only in the ρI α̈ coupling of the v equation (:func:`field_difference`): the
Cardan axes (x, y′, z″) are not orthogonal, so Hamilton's v equation is the directional
derivative along the Cardan v′ axis, which picks up the torsional balance ρI_x α̈ times w′
(the x component of that axis). :func:`ritz_models` discretises both with the clamped
polynomial functions (x/L)^(k+1) of ``RitzBeam(family="polynomial")``, and a third model,
:func:`_torsion_free_ritz`: the beam without torsional strain (κ_x = 0), which a finely
segmented chain of rigid slices joined by bending joints tends to
(:mod:`projeq.subsystems.beam.slice_chain`, the independent check).

Interpretation. Under spin-up the slices carry the spin-up torque ρI_x α̈ about x; what
it does on a variation of (v, w) depends on how the slices turn about x when the beam
bends — a second-order effect in (v, w) that the two documents' equations treat
differently, and neither as the beam without torsional strain:

* B(17)'s Cardan slices are turned by −½v′w′ about x (rotation-vector component of
  R_y(−w′) R_z(v′)): B(18) is exact for that constraint, its coupling symmetric
  (−ρI α̈ ∂²(∫v′w′ dx)/∂a²);
* B(23) projects the balance on D̄'s rows (−ẇ′, v̇′) only: the slice's virtual turn about x
  (first order on the bent beam) has no row, and what reaches the equations is the part of
  the torque that the R components of the y, z balances carry (ρI α̈ θ × e_x): the extra
  coupling ρI α̈ (w′δv′ − v′δw′) (skew, circulatory); projecting in the slice frame instead
  (projeq's RitzBeam before issue 18) gives its negative;
* without torsional strain the slices turn by τ(x) = ½∫₀ˣ(v′w″ − w′v″)dξ
  (:func:`geometric_twist`), and the coupling is ρI_x α̈ ∂²(∫τ dx)/∂a²: the transmitted
  spin-up torque ρI_x α̈ (L − x) working on the twist rate ½(v′w″ − w′v″).

At constant spin all coincide (and conserve the energy relative to R, the Jacobi
integral); under spin-up the motions differ at first order in ρI. projeq's numeric
``RitzBeam`` is the beam without torsional strain (tests/symbolic/test_spinning_beam.py).
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import numpy as np
import sympy as sp

from projeq.symbolic.algebra import skew

x, t, L = sp.symbols("x t L", positive=True)
rho_A, rho_I, EI = sp.symbols("rho_A rho_I EI", positive=True)
alpha = sp.Function("alpha")(t)
v = sp.Function("v")(x, t)
w = sp.Function("w")(x, t)
_eps = sp.Symbol("epsilon")


def _d(f, *args):
    return sp.diff(f, *args) if args else f


def _order(expr, k: int, fields=None):
    """The part of ``expr`` of order k in the deflections (default (v, w))."""
    fields = (v, w) if fields is None else fields
    scaled = expr.subs({f: _eps * f for f in fields}, simultaneous=True).doit()
    return sp.expand(sp.diff(scaled, _eps, k).subs(_eps, 0) / sp.factorial(k))


def _linear(expr):
    """First-order part in the deflections (v, w) of ``expr``."""
    return _order(expr, 1)


def cardan_angular_velocity() -> sp.Matrix:
    """ω_c of a slice in its own frame, B(17): Cardan rates (α̇, −ẇ′, v̇′), second order."""
    vp, wp = _d(v, x), _d(w, x)
    A = sp.Matrix([[1 - vp**2 / 2 - wp**2 / 2, vp, 0], [-vp, 1 - vp**2 / 2, 0], [-wp, 0, 1]])
    return A * sp.Matrix([_d(alpha, t), -_d(wp, t), _d(vp, t)])


def slice_velocity() -> sp.Matrix:
    """v_c of the slice centre in R, B(17): ṙ + ω̃_IR r with r = (x, v, w)."""
    r = sp.Matrix([x, v, w])
    omega_IR = sp.Matrix([_d(alpha, t), 0, 0])
    return _d(r, t) + omega_IR.cross(r)


def _variational_terms(density, f) -> list:
    """The terms of δ/δf of ∫∫ density dx dt: ∂density/∂f and, for each derivative ∂ₓⁱ∂ₜʲ f in the
    density, (−1)^(i+j) ∂ₓⁱ∂ₜʲ ∂density/∂(∂ₓⁱ∂ₜʲ f) (its integrations by parts in x and t)."""
    terms = [sp.diff(density, f)]
    for d in density.atoms(sp.Derivative):
        if d.expr != f:
            continue
        orders = dict(d.variable_count)
        i, j = orders.get(x, 0), orders.get(t, 0)
        terms.append((-1) ** (i + j) * _d(sp.diff(density, d), *([x] * i + [t] * j)))
    return terms


def hamilton_field_steps() -> dict:
    """The expressions Hamilton's principle forms on the way to B(18), by name: the quadratic density
    T − V per length (B(16)–(17)), its integrations by parts (:func:`_variational_terms`, per field) and
    the field equations."""
    density = _quadratic_density()
    by_parts = {f: _variational_terms(density, f) for f in (v, w)}
    return {"T − V per length (B(16)–(17))": [density],
            "integrations by parts (δ/δv, δ/δw)": [term for terms in by_parts.values() for term in terms],
            "field equations (B(18))": [_linear(-sum(by_parts[f])) for f in (v, w)]}


@lru_cache(maxsize=None)
def hamilton_field_equations() -> tuple[sp.Expr, sp.Expr]:
    """The v and w field equations from Hamilton's principle, B(16)–(18), linear in (v, w).

    Lagrangian density ½ρA v_cᵀv_c + ½ω_cᵀ ρ diag(2I, I, I) ω_c − ½EI(v″² + w″²); sign
    chosen so that the ρA v̈ (ρA ẅ) term is positive.
    """
    return tuple(hamilton_field_steps()["field equations (B(18))"])


@lru_cache(maxsize=None)
def _quadratic_density() -> sp.Expr:
    """The part of T − V per length, B(16)–(17), quadratic in (v, w) — all that linear
    equations need: ½ρA v_cᵀv_c + ½ω_cᵀ ρ diag(2I, I, I) ω_c − ½EI(v″² + w″²)."""
    v_c, omega_c = slice_velocity(), cardan_angular_velocity()
    T = rho_A * v_c.dot(v_c) / 2 + (omega_c.T * rho_I * sp.diag(2, 1, 1) * omega_c)[0] / 2
    return _order(T - EI * (_d(v, x, 2) ** 2 + _d(w, x, 2) ** 2) / 2, 2)


def _newton_euler_residuals() -> sp.Matrix:
    """dṗ + ω̃_IR dp and dL̇ + ω̃_IR dL of a slice in R, per length, linear (B(19))."""
    omega_IR = sp.Matrix([_d(alpha, t), 0, 0])
    theta = sp.Matrix([0, -_d(w, x), _d(v, x)])  # small Cardan angles (−w′, v′)
    A_Rc = sp.eye(3) + skew(theta)
    J_R = A_Rc * rho_I * sp.diag(2, 1, 1) * A_Rc.T
    p = rho_A * slice_velocity()
    L_c = J_R * (omega_IR + _d(theta, t))
    f = _d(p, t) + omega_IR.cross(p)
    m = _d(L_c, t) + omega_IR.cross(L_c)
    return sp.Matrix([_linear(e) for e in list(f) + list(m)])


@lru_cache(maxsize=None)
def _slice_residual() -> tuple:
    """B(23)'s middle factor dMÿ + dGẏ − dQ on the rows of D_BAR: (f_y, f_z, m_y, m_z, EIv″, EIw″)."""
    f_m = _newton_euler_residuals()
    return (f_m[1], f_m[2], f_m[4], f_m[5], EI * _d(v, x, 2), EI * _d(w, x, 2))


# D̄ of B(22), the rows of ẏ = (v̇_y, v̇_z, −ẇ′, v̇′, v̇″, ẇ″) that depend on (v̇, ẇ):
# entry -> (field, coefficient, order of ∂/∂x). The α̇ row only enters the α equation.
D_BAR = ((v, 1, 0), (w, 1, 0), (w, -1, 1), (v, 1, 1), (v, 1, 2), (w, 1, 2))


def projection_field_steps() -> dict:
    """The expressions the Projection Equation forms on the way to B(23), by name: the slice's
    Newton–Euler residuals in R (B(19)), their projections with the adjoint D of D̄ (B(21)) and the
    field equations."""
    residuals = _newton_euler_residuals()
    r = _slice_residual()
    projections = {field: [c * (-1) ** k * _d(r_i, *([x] * k))
                           for r_i, (f, c, k) in zip(r, D_BAR) if f == field] for field in (v, w)}
    return {"slice residuals (B(19))": list(residuals),
            "projections D r (B(21))": [term for terms in projections.values() for term in terms],
            "field equations (B(23))": [sp.expand(sum(projections[field])) for field in (v, w)]}


@lru_cache(maxsize=None)
def projection_field_equations() -> tuple[sp.Expr, sp.Expr]:
    """The v and w field equations of the Projection Equation, B(19)–(23), linear in (v, w).

    The slice residual r = (f_y, f_z, m_y, m_z, EIv″, EIw″) (B(23)'s middle factor) is
    projected with D = adjoint of D̄ (B(21)): odd derivatives change sign.
    """
    return tuple(projection_field_steps()["field equations (B(23))"])


@lru_cache(maxsize=None)
def projection_boundary_operators() -> dict:
    """Bremer's boundary operators B₀, B₁ of B(21) for the v and w fields: ``{v: (B₀, B₁), w: (B₀, B₁)}``.

    The virtual work B(20) with δy = D̄ ∘ δs (B(22)) is integrated by parts in x; each row of D̄ with a
    k-th derivative, ∫ c δf⁽ᵏ⁾ rᵢ dx, gives (−1)ᵏ ∫ c δf rᵢ⁽ᵏ⁾ dx (the field equations,
    :func:`projection_field_equations`) and the boundary terms Σ_{j<k} [c (−1)^(k−1−j) δf⁽ʲ⁾ rᵢ^(k−1−j)]₀ᴸ
    ("successive degeneration of the differentiation grade with once more changing sign", after B(22)).
    Collected by δf⁽ʲ⁾: δW_bound = [Σ_f (δf B₀,f + δf′ B₁,f)]₀ᴸ, so that

        ∫₀ᴸ δyᵀ r dx = ∫₀ᴸ (δv E_v + δw E_w) dx + [δv B₀,v + δv′ B₁,v + δw B₀,w + δw′ B₁,w]₀ᴸ.

    At a clamped end δf = δf′ = 0; at a free end B₀ = B₁ = 0 are the dynamic boundary conditions:
    B₁ = EI f″ (no bending moment) and B₀ the shear force with the slice's rotary inertia
    (for v: ρI(v̈′ + α̇² v′ + α̈ w′) − EI v‴, at α̇ = 0 the Rayleigh beam's free end).
    """
    r = _slice_residual()
    operators = {}
    for field in (v, w):
        B = [sp.S.Zero, sp.S.Zero]
        for r_i, (f, c, k) in zip(r, D_BAR):
            if f == field:
                for j in range(k):
                    B[j] += c * (-1) ** (k - 1 - j) * _d(r_i, *([x] * (k - 1 - j)))
        operators[field] = tuple(sp.expand(b) for b in B)
    return operators


def field_difference() -> tuple[sp.Expr, sp.Expr]:
    """Hamilton minus Projection Equation, per equation: (2ρI α̈ w″, 0).

    2ρI α̈ w″ = ∂ₓ(w′ · ρI_x α̈) with ρI_x = 2ρI: the torsional balance of the slice
    projected by the x component (−w′ in R) of the Cardan v′ axis and moved to v by
    integration by parts — the directional derivative along a non-orthogonal axis.
    """
    return tuple(sp.expand(h - p) for h, p in zip(hamilton_field_equations(), projection_field_equations()))


class RitzModel(NamedTuple):
    """Linear Ritz model M ä + α̇ G ȧ + (K − α̇² K_c + α̈ C) a = 0, a = (a_v, a_w)."""

    M: np.ndarray
    G: np.ndarray
    K: np.ndarray
    K_c: np.ndarray
    C: np.ndarray

    def accelerations(self, a, a_dot, alpha_dot: float, alpha_ddot: float) -> np.ndarray:
        """ä of the model at (a, ȧ) for the spin rate α̇ and spin acceleration α̈."""
        stiffness = self.K - alpha_dot**2 * self.K_c + alpha_ddot * self.C
        return np.linalg.solve(self.M, -(alpha_dot * self.G @ a_dot + stiffness @ a))

    def energy(self, a, a_dot, alpha_dot: float) -> float:
        """E = ½ȧᵀMȧ + ½aᵀ(K − α̇²K_c)a, the energy relative to R (Jacobi integral at α̈ = 0)."""
        return 0.5 * a_dot @ self.M @ a_dot + 0.5 * a @ (self.K - alpha_dot**2 * self.K_c) @ a

    def drive_power(self, a, a_dot, alpha_dot: float, alpha_ddot: float) -> float:
        """dE/dt along the motion: −α̈ ȧᵀCa − α̇α̈ aᵀK_c a (G is skew and does no work)."""
        return -alpha_ddot * a_dot @ self.C @ a - alpha_dot * alpha_ddot * a @ self.K_c @ a


def _ritz_coordinates(n: int):
    """a_v, a_w (functions of t) and the substitution v = Σ φ_k a_v,k, w = Σ φ_k a_w,k."""
    a_v = [sp.Function(f"a_v{k}")(t) for k in range(1, n + 1)]
    a_w = [sp.Function(f"a_w{k}")(t) for k in range(1, n + 1)]
    phi = [(x / L) ** (k + 1) for k in range(1, n + 1)]
    fields = {v: sum(p * a for p, a in zip(phi, a_v)), w: sum(p * a for p, a in zip(phi, a_w))}
    return a_v + a_w, phi, fields


_Om, _Om_dot = sp.symbols("Omega Omega_dot")


def _state_symbols(a):
    """Plain symbols (q, q̇, q̈) for a, ȧ, ä and (Ω, Ω̇) for (α̇, α̈), and the substitution."""
    q, q_dot, q_ddot = (sp.symbols(f"{name}0:{len(a)}") for name in ("q", "qd", "qdd"))
    rates = {_d(alpha, t, 2): _Om_dot, _d(alpha, t): _Om}
    rates.update({_d(ai, t, 2): s for ai, s in zip(a, q_ddot)})
    rates.update({_d(ai, t): s for ai, s in zip(a, q_dot)})
    rates.update(dict(zip(a, q)))
    return (q, q_dot, q_ddot), rates


def _matrices(E: sp.Matrix, q, q_dot, q_ddot) -> RitzModel:
    """Split linear equations E (in q, q̇, q̈; polynomial in Ω, Ω̇) into M, G, K, K_c, C."""
    K_all = E.jacobian(q)
    return RitzModel(
        M=E.jacobian(q_ddot), G=E.jacobian(q_dot).diff(_Om), K=K_all.subs({_Om: 0, _Om_dot: 0}),
        K_c=-K_all.diff(_Om, 2) / 2, C=K_all.diff(_Om_dot),
    )


def _lagrange_steps(Lagrangian, q, q_dot, q_ddot) -> dict:
    """Lagrange's equations d/dt ∂L/∂ȧ − ∂L/∂a = 0 of a discretised Lagrangian in the plain
    symbols of :func:`_state_symbols`, with the expressions formed on the way, by name; α̇ is
    prescribed, so d/dt also acts through α̈."""
    p = sp.Matrix([Lagrangian]).jacobian(q_dot).T
    p_dot = p.jacobian(q) * sp.Matrix(q_dot) + p.jacobian(q_dot) * sp.Matrix(q_ddot) + p.diff(_Om) * _Om_dot
    dL_dq = sp.Matrix([Lagrangian]).jacobian(q).T
    return {"∂L/∂ȧ": list(p), "d/dt ∂L/∂ȧ": list(p_dot), "∂L/∂a": list(dL_dq), "equations": p_dot - dL_dq}


def _lagrange_ritz(Lagrangian, q, q_dot, q_ddot) -> RitzModel:
    """The :class:`RitzModel` of Lagrange's equations (:func:`_lagrange_steps`)."""
    return _matrices(_lagrange_steps(Lagrangian, q, q_dot, q_ddot)["equations"], q, q_dot, q_ddot)


@lru_cache(maxsize=None)
def hamilton_ritz_steps(n: int) -> tuple[dict, tuple]:
    """Hamilton's principle, B(16), with the Cardan rates of B(17), discretised with n functions per plane:
    the expressions formed on the way by name (T − V per length with the Ritz fields, L = ∫(T − V) dx,
    ∂L/∂ȧ, d/dt ∂L/∂ȧ, ∂L/∂a, the equations) and the plain symbols (a, ȧ, ä); cached (shared: read only)."""
    a, phi, fields = _ritz_coordinates(n)
    symbols, rates = _state_symbols(a)
    density = sp.expand(_quadratic_density().subs(fields).doit().subs(rates))
    Lagrangian = sp.integrate(density, (x, 0, L))
    steps = {"T − V per length": [density], "L = ∫(T − V) dx": [Lagrangian],
             **_lagrange_steps(Lagrangian, *symbols)}
    return steps, symbols


@lru_cache(maxsize=None)
def _hamilton_ritz(n: int) -> RitzModel:
    """Hamilton's principle, B(16), with the Cardan rates of B(17), discretised
    (:func:`hamilton_ritz_steps`)."""
    steps, symbols = hamilton_ritz_steps(n)
    return _matrices(steps["equations"], *symbols)


def geometric_twist(v_field, w_field) -> sp.Expr:
    """τ(x) = ½ ∫₀ˣ (v′w″ − w′v″) dξ: the turn about x (rotation-vector component) of the
    slices of a beam without torsional strain, relative to the frame R spinning with the
    clamped root. κ_x = τ′ − ½(θ × θ′)_x = 0 for θ = (τ, −w′, v′) (the body curvature of
    exp(θ̃) to second order)."""
    xi = sp.Symbol("xi")
    rate = (_d(v_field, x) * _d(w_field, x, 2) - _d(w_field, x) * _d(v_field, x, 2)) / 2
    return sp.integrate(sp.expand(rate.subs(x, xi)), (xi, 0, x))


def torsion_free_angular_velocity(v_field, w_field) -> sp.Matrix:
    """ω_c of a slice of a beam without torsional strain, in its own frame, to second order:
    ω_c = (E − θ̃ + ½θ̃²)(α̇, 0, 0) + (E − ½θ̃) θ̇ with the rotation vector
    θ = (τ, −w′, v′) of the slice relative to R (:func:`geometric_twist`)."""
    theta = sp.Matrix([geometric_twist(v_field, w_field), -_d(w_field, x), _d(v_field, x)])
    theta_skew = skew(theta)
    E = sp.eye(3)
    return (E - theta_skew + theta_skew**2 / 2) * sp.Matrix([_d(alpha, t), 0, 0]) + (E - theta_skew / 2) * _d(theta, t)


@lru_cache(maxsize=None)
def _torsion_free_ritz(n: int) -> RitzModel:
    """Lagrange's equations of the beam whose slices have no torsional strain (κ_x = 0):
    the kinematics a finely segmented chain of rigid slices joined by bending joints tends
    to (:mod:`projeq.subsystems.beam.slice_chain`); only the slices' rotation differs from
    :func:`_hamilton_ritz` (B(17)'s Cardan slices are twisted by −½v′w′ instead of τ)."""
    a, phi, fields = _ritz_coordinates(n)
    (q, q_dot, q_ddot), rates = _state_symbols(a)
    v_c, omega_c = slice_velocity().subs(fields).doit(), torsion_free_angular_velocity(fields[v], fields[w])
    T = rho_A * v_c.dot(v_c) / 2 + (omega_c.T * rho_I * sp.diag(2, 1, 1) * omega_c)[0] / 2
    density = (T - EI * (_d(fields[v], x, 2) ** 2 + _d(fields[w], x, 2) ** 2) / 2).subs(rates)
    quadratic = _order(density, 2, fields=tuple(q) + tuple(q_dot))
    Lagrangian = sp.integrate(quadratic, (x, 0, L))
    return _lagrange_ritz(Lagrangian, q, q_dot, q_ddot)


@lru_cache(maxsize=None)
def projection_ritz_steps(n: int) -> tuple[dict, tuple]:
    """∫ Ψᵀ r dx = 0 with Ψ = D̄ ∘ φ (B(20), B(22)), n functions per plane, no boundary terms needed: the
    expressions formed on the way by name (the slice residual r of B(19) with the Ritz fields, the
    projected integrands Ψᵀ r, the equations) and the plain symbols (a, ȧ, ä); cached (shared: read only)."""
    a, phi, fields = _ritz_coordinates(n)
    r = [sp.expand(r_i.subs(fields).doit()) for r_i in _slice_residual()]
    symbols, rates = _state_symbols(a)
    integrands = [sp.expand(sum(c * _d(phi_i, *([x] * k)) * r_i
                                for r_i, (f, c, k) in zip(r, D_BAR) if f == field).subs(rates))
                  for field in (v, w) for phi_i in phi]
    equations = sp.Matrix([sp.integrate(integrand, (x, 0, L)) for integrand in integrands])
    return {"slice residual r": r, "projections Ψᵀ r": integrands, "equations": equations}, symbols


@lru_cache(maxsize=None)
def _projection_ritz(n: int) -> RitzModel:
    """The Projection Equation's Ritz model (:func:`projection_ritz_steps`)."""
    steps, symbols = projection_ritz_steps(n)
    return _matrices(steps["equations"], *symbols)


_RITZ = {"hamilton": _hamilton_ritz, "projection": _projection_ritz, "torsion_free": _torsion_free_ritz}


def ritz_models(n: int = 2, length: float = 1.0, rho_A_value: float = 1.0, rho_I_value: float = 0.01,
                EI_value: float = 1.0, kinds=tuple(_RITZ)) -> dict[str, RitzModel]:
    """Numeric Ritz models ``{"hamilton": …, "projection": …, "torsion_free": …}`` (or the
    ``kinds`` asked for) with n functions per plane.

    Coordinates a = (a_v1 … a_vn, a_w1 … a_wn), shapes (x/L)^(k+1) as in
    ``RitzBeam(family="polynomial")``. They differ only in C (the ρI α̈ coupling):
    symmetric for Hamilton's B(18), skew-symmetric for the Projection Equation's B(23),
    ρI_x ∂²(∫τ dx)/∂a² for the beam without torsional strain (:func:`_torsion_free_ritz`).
    """
    if int(n) != n or n < 1:
        raise ValueError(f"n: number of Ritz functions per plane must be a positive integer, got {n!r}")
    unknown = [kind for kind in kinds if kind not in _RITZ]
    if unknown:
        raise ValueError(f"kinds: unknown {unknown}; available: {list(_RITZ)}")
    values = {L: length, rho_A: rho_A_value, rho_I: rho_I_value, EI: EI_value}
    for symbol, value in values.items():
        if not (value >= 0 if symbol == rho_I else value > 0):  # ρI = 0: the Euler–Bernoulli beam
            raise ValueError(f"{symbol}: must be {'≥ 0' if symbol == rho_I else 'positive'}, got {value!r}")
    return {
        kind: RitzModel(*(np.array(m.subs(values), dtype=float) for m in _RITZ[kind](int(n))))
        for kind in kinds
    }


def simulate_ritz(model: RitzModel, motion, a0, a_dot0, t_end: float, rtol: float = 1e-9, atol: float = 1e-12):
    """Integrate a :class:`RitzModel` under the prescribed spin ``motion(t) -> (α, α̇, α̈)``.

    Returns ``(t, a, a_dot, E, W)``: E the energy relative to R (:meth:`RitzModel.energy`),
    W the drive work ∫ dE/dt dt (:meth:`RitzModel.drive_power`) integrated alongside, so
    that E − E(0) = W is the work balance of the model.
    """
    from scipy.integrate import solve_ivp

    n = len(model.M)

    def rhs(time, state):
        a, a_dot = state[:n], state[n:2 * n]
        _, alpha_dot, alpha_ddot = motion(time)
        a_ddot = model.accelerations(a, a_dot, alpha_dot, alpha_ddot)
        return np.concatenate([a_dot, a_ddot, [model.drive_power(a, a_dot, alpha_dot, alpha_ddot)]])

    state0 = np.concatenate([np.asarray(a0, float), np.asarray(a_dot0, float), [0.0]])
    times = np.linspace(0.0, t_end, 201)
    sol = solve_ivp(rhs, (0.0, t_end), state0, t_eval=times, rtol=rtol, atol=atol, method="DOP853")
    a, a_dot, W = sol.y[:n].T, sol.y[n:2 * n].T, sol.y[2 * n]
    E = np.array([model.energy(ai, adi, motion(ti)[1]) for ti, ai, adi in zip(sol.t, a, a_dot)])
    return sol.t, a, a_dot, E, W


_lam, _U = sp.Symbol("lambda"), sp.Function("U")


@lru_cache(maxsize=None)
def whirl_equations() -> tuple[sp.Expr, sp.Expr, sp.Expr]:
    """The boundary-value problem of the constant spin α̇ = Ω for a whirl v + i w = U(x) e^{iλt}.

    The field equation E_v of :func:`projection_field_equations` and the boundary operators B₀,v, B₁,v of
    :func:`projection_boundary_operators` with v = U cos λt, w = U sin λt, α = Ω t, at t = 0 (the w plane
    gives the same at λt = π/2):

        E = EI U⁗ + ρI(λ² − Ω²) U″ − ρA(λ + Ω)² U,   B₀ = −EI U‴ − ρI(λ² − Ω²) U′,   B₁ = EI U″.

    Returned as ``(E, B₀, B₁)`` in ``U(x)`` with the symbols ``lambda`` and ``Omega``; U(0) = U′(0) = 0
    (clamped) and B₀ = B₁ = 0 at x = L (free) close the problem (B(21): δv, δv′ free at L).
    """
    whirl = {alpha: _Om * t, v: _U(x) * sp.cos(_lam * t), w: _U(x) * sp.sin(_lam * t)}
    B0, B1 = projection_boundary_operators()[v]
    return tuple(sp.expand(e.subs(whirl).doit().subs(t, 0))
                 for e in (projection_field_equations()[0], B0, B1))


def _operator_rows(expr, values: dict, derivatives: list) -> np.ndarray:
    """The rows Σₖ cₖ(λ) U⁽ᵏ⁾ of ``expr`` as an array [λ power, rows of the ``derivatives`` matrices]:
    result[j] = Σₖ (coefficient of λʲ U⁽ᵏ⁾) derivatives[k]."""
    polynomial = sp.Poly(expr.subs(values), _lam, *[_d(_U(x), *([x] * k)) for k in range(5)])
    rows = np.zeros((3,) + derivatives[0].shape)
    for (power, *orders), coefficient in polynomial.terms():
        rows[power] += float(coefficient) * derivatives[orders.index(1)]
    return rows


def whirl_frequencies(omega: float, rho_I_value: float, count: int = 3, degree: int = 18, length: float = 1.0,
                      rho_A_value: float = 1.0, EI_value: float = 1.0) -> np.ndarray:
    """The lowest ``count`` co-rotating frequencies |λ| of the spinning beam's boundary-value problem
    (:func:`whirl_equations`), ascending: the PDE's own, without Ritz functions.

    Chebyshev spectral collocation (numpy.polynomial.chebyshev): U is a Chebyshev series of ``degree``
    on [0, L]; the field equation holds at degree − 3 Gauss–Chebyshev points, the four boundary
    conditions U(0) = U′(0) = 0, B₀(L) = B₁(L) = 0 close the system. The quadratic eigenproblem
    (A₀ + λA₁ + λ²A₂) c = 0 is solved in companion form by ``scipy.linalg.eig``; the boundary rows make
    A₂ singular, and the infinite eigenvalues this gives are dropped; each of the lowest is then refined
    by Newton's method (:func:`_newton_polish`). The error falls exponentially in ``degree``: at ρI = 0,
    Ω = 1.3 (ρA = EI = L = 1) against |ω_k ± Ω| the first three are within 9e-8 relative at degree 12 and
    1e-14 at 18 (the default) to 32.
    Each whirl (forward and backward) counts once; at Ω = 0 they coincide and each |λ| appears twice.
    """
    from numpy.polynomial import chebyshev as cheb
    from scipy.linalg import eig

    values = {L: length, rho_A: rho_A_value, rho_I: rho_I_value, EI: EI_value, _Om: omega}
    for symbol, value in values.items():
        if not np.isfinite(value) or not (value >= 0 if symbol in (rho_I, _Om) else value > 0):
            raise ValueError(f"{symbol}: must be {'≥ 0' if symbol in (rho_I, _Om) else 'positive'} "
                             f"and finite, got {value!r}")
    if int(degree) != degree or degree < 8:
        raise ValueError(f"degree: the Chebyshev degree must be an integer ≥ 8, got {degree!r}")
    if int(count) != count or not 1 <= count <= degree // 4:
        raise ValueError(f"count: must be an integer from 1 to degree // 4 = {degree // 4}, got {count!r}")
    inside = cheb.chebpts1(degree - 3)
    scale = 2.0 / length  # d/dx = (2/L) d/dξ, x = L(ξ + 1)/2

    def derivative_matrices(xi):
        identity = np.eye(degree + 1)
        return [scale**k * cheb.chebvander(xi, degree) @ np.column_stack(
            [np.pad(cheb.chebder(column, k), (0, k)) for column in identity]) for k in range(5)]

    at_root, at_tip, field = (derivative_matrices(np.atleast_1d(xi)) for xi in (-1.0, 1.0, inside))
    E, B0, B1 = whirl_equations()
    A = np.concatenate([
        np.stack([at_root[0], 0 * at_root[0], 0 * at_root[0]]),
        np.stack([at_root[1], 0 * at_root[1], 0 * at_root[1]]),
        _operator_rows(B0, values, at_tip), _operator_rows(B1, values, at_tip),
        _operator_rows(E, values, field),
    ], axis=1)
    A /= np.abs(A).max(axis=(0, 2))[None, :, None]  # rows to unit size: k-th derivative rows grow as degree²ᵏ
    size = degree + 1
    zero, one = np.zeros((size, size)), np.eye(size)
    eigenvalues = eig(np.block([[zero, one], [-A[0], -A[1]]]), np.block([[one, zero], [zero, A[2]]]),
                      right=False)
    finite = eigenvalues[np.isfinite(eigenvalues)]
    real = finite[np.abs(finite.imag) < 1e-6 * (1 + np.abs(finite))].real
    return np.sort([abs(_newton_polish(A, lam)) for lam in real[np.argsort(np.abs(real))][:count]])


def _newton_polish(A: np.ndarray, lam: float, steps: int = 4) -> float:
    """λ of (A₀ + λA₁ + λ²A₂) x = 0 refined from the QZ value by Newton's method on the eigenpair
    (inverse iteration with T′(λ), Ruhe 1973, "Algorithms for the nonlinear eigenvalue problem", SIAM J.
    Numer. Anal. 10): the QZ step loses ~1e-9 to the boundary rows of A₂; this recovers rounding level."""
    x = np.linalg.svd(A[0] + lam * A[1] + lam**2 * A[2])[2][-1]
    for _ in range(steps):
        u = np.linalg.solve(A[0] + lam * A[1] + lam**2 * A[2], (A[1] + 2 * lam * A[2]) @ x)
        lam -= (x @ x) / (x @ u)
        x = u / np.linalg.norm(u)
    return lam

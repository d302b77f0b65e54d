"""``gauss_form(system)``: the symbolic Projection Equation of a numeric :class:`projeq.System`.

The chain of docs/theory.md §4 is written out in sympy in body coordinates, as the numeric
evaluators do: for each subsystem n with predecessor p (ẏ = (v_O, ω) in n's frame)

    ẏ_n = T_np ẏ_p + F_n ṡ_n + f_n,        ÿ_n = T_np ÿ_p + F_n s̈_n + ζ_n,
    ζ_n = T_np ζ_p + Ṫ_np ẏ_p + Ḟ_n ṡ_n + ḟ_n   (Ṫ_np ẏ_p = (T_np ẏ_p) × w_n, w_n the joint's twist),

and Σ J_nᵀ (M_n ÿ_n − h_n) = 0 (B(10), docs/theory.md §2) is assembled by the backward recursion
of docs/theory.md §6 instead of the products J_nᵀ M_n J_n: the composite inertias
M̄_p = M_p + Σ T_npᵀ M̄_n T_np give M(q) column block by column block, and the bias forces
β_p = M_p ζ_p − h_p + Σ T_npᵀ β_n give rhs = −F_nᵀ β_n (+ joint forces τ). Every rotation
then acts on a vector or on a composite inertia (m, first moment, I_O) by the
parallel-axis formulas, so no R Rᵀ products need trigonometric simplification.

Supported: every joint with a symbolic form (``Joint.symbolic_relative``: Revolute,
Prismatic, Fixed, Planar, Free with a unit quaternion, Prescribed with its motion given as
a parameter, ``UserJoint.from_sympy``; coupled joints too), the subsystems whose terms are
rigid-body terms (``rigid_inertia``: RigidBody, PointMass, PlanarBody — the spatial terms,
equal on planar motion — and massless ``Frame`` s; not a subclass that restates
``gauss_terms``), gravity and the force laws with a symbolic form (those of
:mod:`projeq.forces` with constant loads). Anything else raises ``ValueError`` naming the
joint, subsystem or force.

Parameters are made symbolic with ``parameters={"link1.m": m1, "link1.r_c": ..., "link1.I_c":
..., "link2.r_pn": ..., "gravity": ..., "arm.motion": θ(t)}``: the sympy value replaces
the number the system was built with; every free symbol of these values other than
``t`` is a parameter of the resulting :class:`GaussForm`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np
import sympy as sp

from .algebra import cross, cross_motion, exact, mul, skew
from .joints import relative
from .loads import body_wrenches, check_loads, joint_forces
from .projection import GaussForm, t

__all__ = ["gauss_form"]


@dataclass
class _Link:
    """One subsystem in the chain: T_np as (A = A_np, r = r_pn), F_n, ẏ_n, ζ_n, its pose
    (R_n, r_n) in the inertial frame and gravity in its coordinates."""

    A: sp.Matrix
    r_pn: sp.Matrix
    F: sp.Matrix
    twist: sp.Matrix
    zeta: sp.Matrix
    R: sp.Matrix
    r: sp.Matrix
    g: sp.Matrix


@dataclass
class _Inertia:
    """A (composite) rigid inertia about the frame origin: mass m, first moment c = m r_c, I_O."""

    m: sp.Expr
    c: sp.Matrix
    I_O: sp.Matrix

    def __mul__(self, twist: sp.Matrix) -> sp.Matrix:
        """M ẏ = (m v − c × ω ; c × v + I_O ω) for M = [[m E, −c̃], [c̃, I_O]] (docs/theory.md §3)."""
        v, omega = twist[:3, :], twist[3:, :]
        return sp.Matrix.vstack(self.m * v - cross(self.c, omega), cross(self.c, v) + mul(self.I_O, omega))

    def __add__(self, other: "_Inertia") -> "_Inertia":
        return _Inertia(self.m + other.m, self.c + other.c, self.I_O + other.I_O)

    def to_parent(self, link: _Link) -> "_Inertia":
        """T_npᵀ M T_np: rotated into p and moved to O_p by r_pn (parallel axes)."""
        A_pn, r = link.A.T, link.r_pn
        c = mul(A_pn, self.c)
        r_, c_ = skew(r), skew(c)
        I_O = mul(A_pn, self.I_O, link.A) - self.m * mul(r_, r_) - mul(r_, c_) - mul(c_, r_)
        return _Inertia(self.m, c + self.m * r, I_O)


def gauss_form(system, parameters=None) -> GaussForm:
    """M(q) s̈ = rhs(q, ṡ, t) of ``system`` in sympy (B(10), docs/theory.md §2–4, §6), nothing inverted.

    ``.q``, ``.s``: the coordinates and minimal velocities in the system's order, named by them
    (``bob1.angle`` is the symbol ``bob1_angle``, ``bob1.angle_dot`` ``bob1_angle_dot``:
    :func:`named_symbols`); time is ``.t``; ``.K`` is K(q) of q̇ = K ṡ (+ k). See the module
    docstring for ``parameters``.

    >>> import projeq as pq
    >>> gf = gauss_form(pq.scenes.double_pendulum(), {"bob1.m": sp.Symbol("m_1")})
    >>> gf.parameters
    (m_1,)
    >>> gf.q
    (bob1_angle, bob2_angle)
    """
    parameters = _check_parameters(system, dict(parameters or {}))
    q = named_symbols([name for name, _ in system.coordinates()], "q")
    s = named_symbols([name for name, _ in system.velocities()], "s")
    q_all, s_all = np.array(q, dtype=object), np.array(s, dtype=object)
    q_joint = [list(system.joint_q_getter(n)(q_all)) for n in range(len(system.names))]
    s_joint = [list(system.joint_s_dot_getter(n)(s_all)) for n in range(len(system.names))]
    rels = [relative(joint, name, q_joint[n], s_joint[n], t, parameters)
            for n, (name, joint) in enumerate(zip(system.names, system.joints))]
    K, k = _kinematics(system, rels)
    q_dot = dict(zip(q, mul(K, sp.Matrix(s)) + k))
    links = _forward(system, parameters, rels, s_joint, q_dot)
    rigids = [_rigid(body, name, parameters) for name, body in zip(system.names, system.subsystems)]
    inertias = [_inertia(rigid) for rigid in rigids]
    beta = _bias(system, links, rigids, inertias)
    M_joint, rhs_joint = _backward(system, links, inertias, beta, joint_forces(system, q_joint, s_joint))
    M, rhs = _to_minimal(system, M_joint, rhs_joint)
    symbols = set().union(*(sp.sympify(v).free_symbols for v in parameters.values())) - {t}
    return GaussForm(M, rhs, q, s, K, t, tuple(sorted(symbols, key=str)))


def named_symbols(names: list[str], letter: str) -> tuple:
    """Symbols for the coordinates ``names`` (``"bob1.angle"`` → ``bob1_angle``: each character
    that cannot be in a Python name as ``_``, so that the compiled functions take them); where
    two names would coincide, or one begins with a digit, ``letter_1``, ``letter_2``, … instead."""
    identifiers = [re.sub(r"\W", "_", name) for name in names]
    if len(set(identifiers)) == len(identifiers) and all(i.isidentifier() for i in identifiers):
        return tuple(sp.Symbol(i) for i in identifiers)
    return tuple(sp.Symbol(f"{letter}_{i}") for i in range(1, len(names) + 1))


def _kinematics(system, rels) -> tuple[sp.Matrix, sp.Matrix]:
    """K and k of q̇ = K ṡ + k, block-diagonal over the uncoupled joints."""
    K, k = sp.zeros(system.n_q, system.n_s), sp.zeros(system.n_q, 1)
    for n, (joint, rel) in enumerate(zip(system.joints, rels)):
        if not joint.coupling:
            K[system.q_slice[n], system.s_slice[n]] = rel.K
            k[system.q_slice[n], :] = rel.k
    return K, k


def _d_dt(x: sp.Matrix, q_dot: dict) -> sp.Matrix:
    """Total time derivative along q̇: ∂x/∂q q̇ + ∂x/∂t (only the q that x contains)."""
    return sum((x.diff(q_i) * q_dot[q_i] for q_i in x.free_symbols & set(q_dot)), x.diff(t))


def _carry(link: _Link, twist: sp.Matrix) -> sp.Matrix:
    """T_np ẏ_p = (A_np (v_p + ω_p × r_pn), A_np ω_p) (docs/theory.md §4)."""
    v, omega = twist[:3, :], twist[3:, :]
    return sp.Matrix.vstack(mul(link.A, v + cross(omega, link.r_pn)), mul(link.A, omega))


def _carry_back(link: _Link, wrench: sp.Matrix) -> sp.Matrix:
    """T_npᵀ (f; M) = (A_pn f, r_pn × A_pn f + A_pn M): a wrench on n seen from p."""
    f, moment = mul(link.A.T, wrench[:3, :]), mul(link.A.T, wrench[3:, :])
    return sp.Matrix.vstack(f, cross(link.r_pn, f) + moment)


def _forward(system, parameters, rels, s_joint, q_dot) -> list[_Link]:
    """Root → leaves: T_np, ẏ_n, ζ_n, the pose and gravity of every subsystem."""
    gravity = parameters.get("gravity", exact(system.gravity))
    ground = _Link(sp.eye(3), sp.zeros(3, 1), sp.zeros(6, 0), sp.zeros(6, 1), sp.zeros(6, 1), sp.eye(3),
                   sp.zeros(3, 1), gravity)
    links = []
    for n, (name, joint, rel) in enumerate(zip(system.names, system.joints, rels)):
        p = links[system.parent[n]] if system.parent[n] >= 0 else ground
        orientation = exact(joint.orientation)
        A_pn = mul(orientation, rel.A)
        r_pn = parameters.get(f"{name}.r_pn", exact(joint.r_pn)) + mul(orientation, rel.r)
        link = _Link(A_pn.T, r_pn, rel.F, None, None, mul(p.R, A_pn), p.r + mul(p.R, r_pn), mul(A_pn.T, p.g))
        u = _carry(link, p.twist)
        s_n = sp.Matrix(len(s_joint[n]), 1, s_joint[n])
        w = mul(rel.F, s_n) + rel.f
        link.twist = u + w
        F_dot_s, f_dot = mul(_d_dt(rel.F, q_dot), s_n), _d_dt(rel.f, q_dot)
        link.zeta = _carry(link, p.zeta) + cross_motion(u, w) + F_dot_s + f_dot  # Ṫ_np ẏ_p = u × w
        links.append(link)
    return links


def _rigid(body, name: str, parameters) -> tuple:
    """(m, r_c, I_c) of a subsystem with rigid-body terms (``rigid_inertia``), parameters put in."""
    m, r_c, I_c = body.rigid_inertia
    return (parameters.get(f"{name}.m", exact(m)), parameters.get(f"{name}.r_c", exact(r_c)),
            parameters.get(f"{name}.I_c", exact(I_c)))


def _inertia(rigid) -> _Inertia:
    """M_n as (m, c = m r_c, I_O = I_c − m r̃_c r̃_c) (docs/theory.md §3)."""
    m, r_c, I_c = rigid
    return _Inertia(m, m * r_c, I_c - m * mul(skew(r_c), skew(r_c)))


def _h(rigid, link: _Link) -> sp.Matrix:
    """h = Q − G ẏ = (m g − ω × p ; r_c × (m g − ω × p) − ω × I_c ω), p = m (v + ω × r_c) (docs/theory.md §3):
    the symbolic twin of :func:`projeq.subsystems.rigid.rigid_h`."""
    m, r_c, I_c = rigid
    v, omega = link.twist[:3, :], link.twist[3:, :]
    force = m * link.g - cross(omega, m * (v + cross(omega, r_c)))
    return sp.Matrix.vstack(force, cross(r_c, force) - cross(omega, mul(I_c, omega)))


def _bias(system, links, rigids, inertias) -> list:
    """β_n = M_n ζ_n − h_n − (loads on n): the Projection Equation's terms of n at s̈ = 0."""
    wrenches = body_wrenches(system, links)
    beta = []
    for n, (link, rigid, inertia) in enumerate(zip(links, rigids, inertias)):
        beta.append(inertia * link.zeta - _h(rigid, link) - wrenches.get(n, sp.zeros(6, 1)))
    return beta


def _backward(system, links, inertias, beta, tau) -> tuple[dict, dict]:
    """Leaves → root: composite inertias and bias forces; M and rhs per pair of joints."""
    N = len(links)
    composite, beta = list(inertias), list(beta)
    M, rhs = {}, {}
    for n in reversed(range(N)):
        link, p = links[n], system.parent[n]
        rhs[n] = -mul(link.F.T, beta[n]) + tau.get(n, sp.zeros(link.F.shape[1], 1))
        if link.F.shape[1]:
            X = sp.Matrix.hstack(*(composite[n] * link.F[:, k] for k in range(link.F.shape[1])))
            j = n
            while j >= 0:
                M[j, n] = mul(links[j].F.T, X)
                X = sp.Matrix.hstack(*(_carry_back(links[j], X[:, k]) for k in range(X.shape[1])))
                j = system.parent[j]
        if p >= 0:
            beta[p] = beta[p] + _carry_back(link, beta[n])
            composite[p] = composite[p] + composite[n].to_parent(link)
    return M, rhs


def _to_minimal(system, M_joint: dict, rhs_joint: dict) -> tuple[sp.Matrix, sp.Matrix]:
    """M = Σ P_jᵀ M_jn P_n, rhs = Σ P_nᵀ rhs_n with ṡ_n = P_n ṡ (coupled joints share ṡ)."""
    P = []
    for n in range(len(system.names)):
        columns, weights = system.joint_s_columns(n)
        P_n = sp.zeros(len(weights), system.n_s)
        for k, column in enumerate(columns):
            P_n[:, int(column)] = exact(weights[:, k])
        P.append(P_n)
    M, rhs = sp.zeros(system.n_s, system.n_s), sp.zeros(system.n_s, 1)
    for (j, n), block in M_joint.items():
        M += mul(P[j].T, block, P[n])
        if j != n:
            M += mul(P[n].T, block.T, P[j])
    for n, block in rhs_joint.items():
        rhs += mul(P[n].T, block)
    return M, rhs


def _check_parameters(system, parameters) -> dict:
    """Refuse the subsystems the symbolic chain does not cover, by name; parameters as sympy values."""
    for name, body in zip(system.names, system.subsystems):
        if body.rigid_inertia is None:
            raise ValueError(f"system: subsystem {name!r} ({type(body).__name__}) is not supported "
                             "symbolically: its gauss_terms are numeric, not the rigid-body terms of a mass, "
                             "mass centre and inertia (its rigid_inertia is None)")
    check_loads(system)
    shapes = {"m": (), "r_c": (3, 1), "I_c": (3, 3), "r_pn": (3, 1), "motion": ()}
    out = {}
    for key, value in parameters.items():
        name, _, field = key.rpartition(".")
        shape = (3, 1) if key == "gravity" else shapes.get(field)
        if key != "gravity" and (name not in system.names or shape is None):
            raise ValueError(f"parameters: unknown key {key!r}; use 'gravity' or '<name>.m', '.r_c', '.I_c', "
                             "'.r_pn', '.motion'")
        if field == "motion" and field not in system.joint(name).symbolic_parameters:
            raise ValueError(f"parameters: {key!r} is for Prescribed joints; joint {name!r} is a "
                             f"{type(system.joint(name)).__name__}")
        value = sp.sympify(value) if shape == () else sp.Matrix(value)
        if shape and value.shape != shape:
            raise ValueError(f"parameters: {key!r} must have shape {shape}, got {value.shape}")
        out[key] = value
    return out

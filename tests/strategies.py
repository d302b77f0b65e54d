"""Hypothesis strategies for random multibody systems (STYLE §4.8, "our autoTree").

``trees(max_n, planar)`` draws a :class:`Tree`: a random :class:`projeq.System` together
with a random state (q, ṡ, t) at which to evaluate it.

- *Structure* is drawn by hypothesis, so that a failing example shrinks to a small,
  readable one: the number of bodies, each body's parent (the previous body half of the
  time, else any earlier body or the ground, so both deep chains and wide branching
  occur), each joint's kind, and the kinds of the force laws.
- *Numbers* (masses, inertias, offsets, axes, gravity, the state) come from a numpy
  generator seeded by one drawn integer, so that they are always valid (unit axes, proper
  rotations, inertias of real mass distributions) and the example prints compactly.

Spatial trees use every joint projeq knows: Revolute and Prismatic about random axes,
Planar in a random plane, Free (quaternion), Fixed, Prescribed (rheonomic revolute or
prismatic) and four user joints built with ``UserJoint.from_functions`` from numpy
callables that accept complex input (a Cardan spherical joint, a screw, Bremer's
non-holonomic car joint B(11) and a rheonomic slider on a turntable). Planar trees hold
only ``PlanarBody`` objects in the x–y plane on joints that keep them there (revolute
about z, prismatic in the plane, ``Planar("xy")``, fixed, prescribed, and the car joint,
from callables and from sympy).

Masses are log-uniform in [1e-2, 1e2] kg. An inertia tensor is built from the second
moments J_i = m ρ_i² (ρ_i ∈ [0.02, 0.5] m) of a mass distribution along random principal
axes, I = R diag(J_y + J_z, J_x + J_z, J_x + J_y) Rᵀ, so it satisfies the triangle
inequality by construction.
"""

from __future__ import annotations

import copy
from functools import cache

import numpy as np
import sympy as sp
from hypothesis import strategies as st

import projeq as pq
from projeq.spatial import rotation, rotation_x, rotation_y, rotation_z

SPATIAL_KINDS = (
    "revolute",
    "prismatic",
    "planar",
    "free",
    "fixed",
    "prescribed",
    "spherical",
    "screw",
    "car",
    "turntable",
)
PLANAR_KINDS = ("revolute", "prismatic", "planar", "fixed", "prescribed", "car", "car_sympy")
RHEONOMIC_KINDS = ("prescribed", "turntable")  # joints with f ≠ 0: the system is rheonomic
FORCE_KINDS = ("force", "torque", "joint_spring", "joint_force", "spring_damper")
CONSERVATIVE_FORCE_KINDS = ("joint_spring", "spring_damper")  # undamped: they have a potential

_ONE_DOF_Q_EQ_S = ("revolute", "prismatic", "screw", "spherical")  # q̇ = ṡ: JointSpring allowed


# -- random numbers that are always valid ----------------------------------------------
def unit_vector(rng) -> np.ndarray:
    v = rng.standard_normal(3)
    while np.linalg.norm(v) < 1e-3:
        v = rng.standard_normal(3)
    return v / np.linalg.norm(v)


def random_rotation(rng) -> np.ndarray:
    return rotation(unit_vector(rng), rng.uniform(-np.pi, np.pi))


def random_mass(rng) -> float:
    return float(10 ** rng.uniform(-2, 2))


def random_inertia(rng, m: float, R=None) -> np.ndarray:
    """I_c of a real mass distribution: second moments J_i = m ρ_i² along principal axes R."""
    J = m * rng.uniform(0.02, 0.5, 3) ** 2
    R = random_rotation(rng) if R is None else R
    return R @ np.diag([J[1] + J[2], J[0] + J[2], J[0] + J[1]]) @ R.T


# -- user joints from callables ------------------------------------------------------------
def spherical_joint(parent=None, r_pn=(0.0, 0.0, 0.0)) -> pq.UserJoint:
    """A ball joint: Cardan angles q = (a, b, c), A = R_z(a) R_y(b) R_x(c), ṡ = q̇ and
    ω = ȧ R_xᵀR_yᵀ e_z + ḃ R_xᵀ e_y + ċ e_x in child coordinates (regular for |b| < π/2)."""

    def pose(q, t):
        return rotation_z(q[0]) @ rotation_y(q[1]) @ rotation_x(q[2]), np.zeros(3)

    def F(q, t):
        _, b, c = q
        cb, sb, cc, sc = np.cos(b), np.sin(b), np.cos(c), np.sin(c)
        F6 = np.zeros((6, 3), dtype=np.result_type(q, float))
        F6[3:, 0] = (-sb, cb * sc, cb * cc)
        F6[3:, 1] = (0.0, cc, -sc)
        F6[3, 2] = 1.0
        return F6

    return pq.UserJoint.from_functions(3, 3, pose, F, lambda q, t: np.eye(3), parent=parent, r_pn=r_pn)


def screw_joint(axis, pitch: float, parent=None, r_pn=(0.0, 0.0, 0.0), orientation=None) -> pq.UserJoint:
    """A screw: rotation θ about the unit axis e and translation pitch·θ along it;
    F⁶ = [pitch e; e] (e is the same in joint and child coordinates), q̇ = ṡ."""
    e = np.asarray(axis, dtype=float) / np.linalg.norm(axis)

    def pose(q, t):
        return rotation(e, q[0]), pitch * q[0] * e

    F6 = np.concatenate((pitch * e, e))[:, None]
    return pq.UserJoint.from_functions(
        1, 1, pose, lambda q, t: F6, lambda q, t: np.eye(1), parent=parent, r_pn=r_pn, orientation=orientation
    )


def car_joint(parent=None, r_pn=(0.0, 0.0, 0.0), orientation=None) -> pq.UserJoint:
    """Bremer's car (B(6), B(11)): q = (x, y, γ), ṡ = (v_x, ω_z) with v_y = 0 inserted up
    front; A = R_z(γ), r = (x, y, 0), F⁶ columns (1,0,0,0,0,0) and (0,0,0,0,0,1),
    K = [[cos γ, 0], [sin γ, 0], [0, 1]]."""
    F6 = np.zeros((6, 2))
    F6[0, 0] = F6[5, 1] = 1.0

    def pose(q, t):
        return rotation_z(q[2]), np.array([q[0], q[1], 0 * q[0]])

    def K(q, t):
        c, s = np.cos(q[2]), np.sin(q[2])
        return np.array([[c, 0 * c], [s, 0 * c], [0 * c, 1 + 0 * c]])

    return pq.UserJoint.from_functions(
        3, 2, pose, lambda q, t: F6, K, parent=parent, r_pn=r_pn, orientation=orientation
    )


@cache
def _car_sympy_template() -> pq.UserJoint:
    g = sp.Symbol("gamma")
    q = sp.symbols("x y gamma")
    s = sp.symbols("v_x omega_z")
    A = sp.Matrix([[sp.cos(g), -sp.sin(g), 0], [sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
    F = sp.Matrix([[1, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0, 1]])
    K = sp.Matrix([[sp.cos(g), 0], [sp.sin(g), 0], [0, 1]])
    return pq.UserJoint.from_sympy(q, s, A, [q[0], q[1], 0], F, K)


def car_joint_sympy(parent=None, r_pn=(0.0, 0.0, 0.0), orientation=None) -> pq.UserJoint:
    """The car joint of :func:`car_joint` from sympy expressions (compiled once, placed by copy)."""
    joint = copy.copy(_car_sympy_template())
    joint.parent = parent
    joint.r_pn = np.asarray(r_pn, dtype=float)
    joint.orientation = np.eye(3) if orientation is None else np.asarray(orientation, dtype=float)
    return joint


def turntable_joint(spin: float, parent=None, r_pn=(0.0, 0.0, 0.0), orientation=None) -> pq.UserJoint:
    """A slider x on a turntable turning at the prescribed rate Ω about z (rheonomic):
    A = R_z(Ω t), r = R_z(Ω t) (x, 0, 0); the child's twist is F⁶ ẋ + f⁶ with
    F⁶ = e_x (translation) and f⁶ = (0, Ω x, 0, 0, 0, Ω), which depends on q and t."""
    F6 = np.zeros((6, 1))
    F6[0, 0] = 1.0

    def pose(q, t):
        A = rotation_z(spin * t)
        return A, A @ np.array([q[0], 0 * q[0], 0 * q[0]])

    def f(q, t):
        z = 0 * q[0] + 0 * t
        return np.array([z, spin * q[0] + 0 * t, z, z, z, spin + z])

    return pq.UserJoint.from_functions(
        1,
        1,
        pose,
        lambda q, t: F6,
        lambda q, t: np.eye(1),
        f=f,
        parent=parent,
        r_pn=r_pn,
        orientation=orientation,
    )


def _prescribed(inner: pq.Joint, rng) -> pq.Prescribed:
    """θ(t) = a sin(w t + φ) on an inner revolute or prismatic joint."""
    a, w, phi = rng.uniform(0.2, 1.0), rng.uniform(0.5, 2.0), rng.uniform(-np.pi, np.pi)

    def motion(t):
        return (a * np.sin(w * t + phi), a * w * np.cos(w * t + phi), -a * w * w * np.sin(w * t + phi))

    return pq.Prescribed(inner, motion=motion)


# -- joints ----------------------------------------------------------------------------------
def spatial_joint(kind: str, parent, rng) -> pq.Joint:
    """A random joint of ``kind`` on ``parent``, placed at a random r_pn (and orientation)."""
    r_pn = rng.uniform(-1, 1, 3)
    orientation = random_rotation(rng) if rng.random() < 0.5 else None
    axis = unit_vector(rng)
    if kind == "revolute":
        return pq.Revolute(parent, axis, r_pn, orientation)
    if kind == "prismatic":
        return pq.Prismatic(parent, axis, r_pn, orientation)
    if kind == "planar":
        return pq.Planar(parent, ("xy", "yz", "zx", "xz")[rng.integers(4)], r_pn, orientation)
    if kind == "free":
        return pq.Free(parent, r_pn, orientation)
    if kind == "fixed":
        return pq.Fixed(parent, r_pn, random_rotation(rng))
    if kind == "prescribed":
        inner = (pq.Revolute if rng.random() < 0.5 else pq.Prismatic)(parent, axis, r_pn, orientation)
        return _prescribed(inner, rng)
    if kind == "spherical":
        return spherical_joint(parent, r_pn)
    if kind == "screw":
        return screw_joint(axis, rng.uniform(-0.5, 0.5), parent, r_pn, orientation)
    if kind == "car":
        return car_joint(parent, r_pn, orientation)
    if kind == "turntable":
        return turntable_joint(rng.uniform(-2, 2), parent, r_pn, orientation)
    raise ValueError(f"kind: unknown spatial joint kind {kind!r}")


def planar_joint(kind: str, parent, rng) -> pq.Joint:
    """A random joint of ``kind`` that keeps an x–y planar body in its plane."""
    r_pn = np.append(rng.uniform(-1, 1, 2), rng.uniform(-0.2, 0.2))  # an offset along z is harmless
    orientation = rotation_z(rng.uniform(-np.pi, np.pi)) if rng.random() < 0.5 else None
    angle = rng.uniform(-np.pi, np.pi)
    in_plane = np.array([np.cos(angle), np.sin(angle), 0.0])
    if kind == "revolute":
        return pq.Revolute(parent, "z" if rng.random() < 0.7 else "-z", r_pn, orientation)
    if kind == "prismatic":
        return pq.Prismatic(parent, in_plane, r_pn, orientation)
    if kind == "planar":
        return pq.Planar(parent, "xy", r_pn, orientation)
    if kind == "fixed":
        return pq.Fixed(parent, r_pn, rotation_z(angle))
    if kind == "prescribed":
        inner = (
            pq.Revolute(parent, "z", r_pn, orientation)
            if rng.random() < 0.5
            else pq.Prismatic(parent, in_plane, r_pn)
        )
        return _prescribed(inner, rng)
    if kind == "car":
        return car_joint(parent, r_pn, orientation)
    if kind == "car_sympy":
        return car_joint_sympy(parent, r_pn, orientation)
    raise ValueError(f"kind: unknown planar joint kind {kind!r}")


# -- forces --------------------------------------------------------------------------------
def _force(kind, names, kinds, dofs, rng, planar: bool, damped: bool, constant: bool = False):
    """A random force law of ``kind`` (None when the tree has no joint it can act on) on the
    joints ``names`` of ``kinds`` with ``dofs`` minimal velocities each; loads given as callables
    half of the time unless ``constant``."""
    body = names[rng.integers(len(names))]
    point = rng.uniform(-0.5, 0.5, 3)
    if planar:
        point[2] = 0.0
    if kind == "force":
        f0 = rng.uniform(-5, 5, 3)
        if planar:
            f0[2] = 0.0
        if constant or rng.random() < 0.5:
            return pq.Force(body, f0, point, frame="world" if planar or rng.random() < 0.5 else "body")
        # a load that depends on time and state (s_dot in it makes it non-conservative)
        return pq.Force(
            body,
            lambda t, q, s_dot: f0 * np.cos(t + np.sum(q)) + 0.1 * f0 * np.sum(s_dot),
            point,
            frame="world",
        )
    if kind == "torque":
        tau = rng.uniform(-3, 3, 3)
        if planar:
            tau[:2] = 0.0
        return pq.Torque(body, tau, frame="world" if planar or rng.random() < 0.5 else "body")
    damping = rng.uniform(0.1, 2.0) if damped else 0.0
    if kind == "joint_spring":
        candidates = [name for name, k in zip(names, kinds) if k in _ONE_DOF_Q_EQ_S]
        if not candidates:
            return None
        joint = candidates[rng.integers(len(candidates))]
        return pq.JointSpring(joint, rng.uniform(0.5, 20.0), damping, q_ref=rng.uniform(-0.5, 0.5))
    if kind == "joint_force":
        candidates = [name for name, k in zip(names, kinds) if k not in ("fixed", "prescribed")]
        if not candidates:
            return None
        joint = candidates[rng.integers(len(candidates))]
        tau = rng.uniform(-3, 3, dofs[names.index(joint)])
        if constant or rng.random() < 0.5:
            return pq.JointForce(joint, tau)
        return pq.JointForce(joint, lambda t, q, s_dot: tau * np.sin(2 * t))
    if kind == "spring_damper":
        a = None if rng.random() < 0.3 else body
        others = [name for name in names if name != a]
        b = others[rng.integers(len(others))] if others else None
        if a is None and b is None:
            return None
        return pq.SpringDamper(
            a,
            point if a is not None else rng.uniform(-1, 1, 3) * (1, 1, 0 if planar else 1),
            b,
            rng.uniform(-0.5, 0.5, 3) * (1, 1, 0 if planar else 1),
            stiffness=rng.uniform(0.5, 20.0),
            damping=damping,
            length=rng.uniform(0.0, 1.0),
        )
    raise ValueError(f"kind: unknown force kind {kind!r}")


# -- the tree ------------------------------------------------------------------------------
class Tree:
    """A random system and a state (q, ṡ, t) at which to evaluate it; ``rng`` continues the
    generator that built it (for further random numbers in a test). Its repr names the
    structure and the seed, which is all a failing example needs to be rebuilt."""

    def __init__(self, system, q, s_dot, t, kinds, parents, force_kinds, seed, planar, rng):
        self.system, self.q, self.s_dot, self.t = system, q, s_dot, t
        self.kinds, self.parents, self.force_kinds = kinds, parents, force_kinds
        self.seed, self.planar, self.rng = seed, planar, rng

    def __repr__(self) -> str:
        return (
            f"Tree({'planar' if self.planar else 'spatial'}, n={len(self.kinds)}, seed={self.seed}, "
            f"kinds={self.kinds}, parents={self.parents}, forces={self.force_kinds})"
        )

    @property
    def n(self) -> int:
        return len(self.kinds)


def random_state(system: pq.System, rng, speed: float = 1.0):
    """q (normalised), ṡ and t: coordinates in [−1, 1], velocities in [−speed, speed]."""
    q = system.normalized(rng.uniform(-1, 1, system.n_q))
    return q, rng.uniform(-speed, speed, system.n_s), float(rng.uniform(0, 3))


@st.composite
def trees(
    draw,
    max_n: int = 30,
    planar: bool = False,
    min_n: int = 1,
    kinds=None,
    forces: str | bool = True,
    scleronomic: bool = False,
    max_forces: int = 4,
):
    """A random :class:`Tree` with ``min_n`` … ``max_n`` bodies.

    ``kinds``: the joint kinds to draw from (default: all of ``SPATIAL_KINDS`` or
    ``PLANAR_KINDS``); ``scleronomic=True`` leaves out the rheonomic ones.
    ``forces``: ``True`` (any force laws, damped or not), ``"conservative"`` (undamped
    joint springs and spring-dampers only: T + V is conserved), ``"constant"`` (any, with
    constant loads only: what the symbolic Gauss form takes), or ``False`` (gravity only).
    """
    pool = kinds or (PLANAR_KINDS if planar else SPATIAL_KINDS)
    if scleronomic:
        pool = tuple(k for k in pool if k not in RHEONOMIC_KINDS)
    n = draw(st.integers(min_n, max_n), label="n")
    parents = [
        -1 if i == 0 else draw(st.one_of(st.just(i - 1), st.integers(-1, i - 1)), label=f"parent{i}")
        for i in range(n)
    ]
    joint_kinds = [draw(st.sampled_from(pool), label=f"kind{i}") for i in range(n)]
    if forces:
        force_pool = CONSERVATIVE_FORCE_KINDS if forces == "conservative" else FORCE_KINDS
        force_kinds = draw(st.lists(st.sampled_from(force_pool), max_size=max_forces), label="forces")
    else:
        force_kinds = []
    seed = draw(st.integers(0, 2**32 - 1), label="seed")
    rng = np.random.default_rng(seed)

    names = [f"b{i}" for i in range(n)]
    subsystems, joints = {}, {}
    for i, name in enumerate(names):
        parent = None if parents[i] < 0 else names[parents[i]]
        m = random_mass(rng)
        r_c = rng.uniform(-0.5, 0.5, 3)
        if planar:
            subsystems[name] = pq.PlanarBody(
                m, r_c, random_inertia(rng, m, rotation_z(rng.uniform(-np.pi, np.pi))), "xy"
            )
            joints[name] = planar_joint(joint_kinds[i], parent, rng)
        else:
            subsystems[name] = pq.RigidBody(m, r_c, random_inertia(rng, m))
            joints[name] = spatial_joint(joint_kinds[i], parent, rng)
    dofs = [joints[name].n_s for name in names]
    laws = [_force(k, names, joint_kinds, dofs, rng, planar, damped=forces in (True, "constant"),
                   constant=forces == "constant") for k in force_kinds]
    gravity = rng.uniform(-10, 10, 3)
    if planar:
        gravity[2] = 0.0
    system = pq.System(subsystems, joints, gravity=gravity, forces=[f for f in laws if f is not None])
    q, s_dot, t = random_state(system, rng)
    return Tree(system, q, s_dot, t, joint_kinds, parents, force_kinds, seed, planar, rng)


def with_couplings(tree: Tree, n_coupled: int = 3) -> pq.System:
    """``tree``'s System with up to ``n_coupled`` more bodies on revolute or prismatic joints
    (random axes and frames) that are *coupled*: each follows Σ ratio · coordinate of one or
    two of the tree's own revolute or prismatic joints (gears, ropes: shared minimal
    velocities, docs/theory.md §4), each on a rigid body of the tree (a beam's stations are
    no place for a random offset); the tree itself unchanged if it has no such joint."""
    system, rng = tree.system, tree.rng
    leaders = [name for name, kind in zip(system.names, tree.kinds) if kind in ("revolute", "prismatic")]
    subsystems, joints = dict(zip(system.names, system.subsystems)), dict(zip(system.names, system.joints))
    for i in range(n_coupled if leaders else 0):
        name, parent = f"c{i}", str(rng.choice([n for n, body in subsystems.items() if not body.n_e]))
        m = random_mass(rng)
        subsystems[name] = pq.RigidBody(m, rng.uniform(-0.5, 0.5, 3), random_inertia(rng, m))
        follows = {str(leader): float(rng.uniform(-2, 2)) for leader in rng.choice(leaders, min(2, len(leaders)))}
        kind = pq.Revolute if rng.random() < 0.5 else pq.Prismatic
        joints[name] = kind(parent, unit_vector(rng), rng.uniform(-1, 1, 3), random_rotation(rng), coupling=follows)
    return pq.System(subsystems, joints, gravity=system.gravity, forces=system.forces)


def with_every_law(tree) -> pq.System:
    """``tree``'s System carrying one more law of every kind with constant loads (and a
    force and a torque in the other frame than the first ones drawn), damped: every law has a
    row in the fast evaluator's compiled loop (projeq/assembly/loads.py)."""
    system, rng = tree.system, tree.rng
    kinds = tree.kinds + [type(joint).__name__.lower() for joint in system.joints[len(tree.kinds):]]  # beams' joints
    dofs = [joint.n_s for joint in system.joints]
    laws = [_force(kind, list(system.names), kinds, dofs, rng, tree.planar, damped=True, constant=True)
            for kind in FORCE_KINDS + ("force", "torque", "spring_damper")]
    return pq.System(dict(zip(system.names, system.subsystems)), dict(zip(system.names, system.joints)),
                     gravity=system.gravity, forces=list(system.forces) + [law for law in laws if law is not None])

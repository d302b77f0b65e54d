"""Impressed forces beyond gravity: they add to h_n = Q_n − G_n ẏ_n of the subsystems.

A force law is bound to a System by names (``bind``), then, at each evaluation, adds its
wrenches to the subsystems' h_n given the kinematic state (``add_to``) and reports its
potential energy (``potential``). Loads on a body enter as a wrench (f, M_O) about the
body's origin in body coordinates, selected by the body's S. A generalized force τ on a
joint's minimal velocities enters as an equal and opposite pair: h_n += w, h_p −= T_npᵀ w
with F_nᵀ w = τ (w = F_n (F_nᵀF_n)⁻¹ τ), whose projection Σ J_nᵀ h_n is exactly τ on ṡ_n
(B(14)); so the assemblers never special-case joint forces.

Callables receive ``(t, q, s_dot)`` and return the load; the compiled evaluator compiles them
with numba (``compiled_load``; numbers they read from their closure or module are frozen then,
as ``numba.njit`` does), and runs one numba cannot compile in Python, saying so once.

Each law states its symbolic form next to its numeric one (:class:`ForceLaw`):
``symbolic_wrenches`` (body wrenches) or ``symbolic_joint_forces`` (τ on minimal
velocities), which :func:`projeq.symbolic.gauss_form` adds; a law that has none says why
in ``symbolic_unsupported`` (a load given as a callable has values, not expressions).

The numeric terms are stated once, as plain functions on arrays and scalars in the style
numba compiles (:func:`body_wrench`, :func:`spring_end`, :func:`spring_damper`,
:func:`spring_force`, :func:`joint_wrench`): a law's ``add_to`` calls them (the reference
evaluators), and the compiled evaluator calls the same source from its loop over the laws'
rows (:mod:`projeq.assembly.loads`), which each law of this module gives by ``compiled_terms``
(a load given as a callable by ``compiled_load`` too). They index matrices as ``R[i][j]``, so
``add_to`` hands them nested lists of Python numbers (several times faster interpreted than
numpy scalars) and the compiled loop arrays; they take complex numbers too (a complex step), so they compare
real parts only.
"""

from __future__ import annotations

import functools
from typing import Callable

import numpy as np
from numpy.typing import NDArray

from projeq.checks import drop_inherited_twins, finite_array, non_negative
from projeq.joints import statement
from projeq.symbolic import lazy_import
from projeq.spatial import numeric

sp = lazy_import("sympy")
algebra = lazy_import("projeq.symbolic.algebra")

_ZERO = (0.0, 0.0, 0.0)  # the torque of a force, the force and point of a torque


def body_wrench(R, force, point, torque, world, wrench) -> None:
    """The wrench (f; M_O) = (f; p × f + τ) about a body's origin, in its coordinates, of a
    force f at its point p and a torque τ: f = Rᵀ f_world and τ = Rᵀ τ_world when given in
    world coordinates (``world``), else as given; written into ``wrench`` (6). The statement
    of :class:`Force` and :class:`Torque` (and of each end of a :class:`SpringDamper`)."""
    for a in range(3):
        if world:
            wrench[a] = R[0][a] * force[0] + R[1][a] * force[1] + R[2][a] * force[2]
            wrench[3 + a] = R[0][a] * torque[0] + R[1][a] * torque[1] + R[2][a] * torque[2]
        else:
            wrench[a] = force[a]
            wrench[3 + a] = torque[a]
    wrench[3] += point[1] * wrench[2] - point[2] * wrench[1]
    wrench[4] += point[2] * wrench[0] - point[0] * wrench[2]
    wrench[5] += point[0] * wrench[1] - point[1] * wrench[0]


def spring_end(R, r, twist, point) -> tuple:
    """(x, v) of a body's point p as six scalars: its world position x = r + R p and
    velocity v = R (v_O + ω × p), the body's pose (R, r) and twist (v_O, ω) in its own
    coordinates (the ground: R = E, r = 0, twist = 0, p in world coordinates)."""
    u0 = twist[0] + twist[4] * point[2] - twist[5] * point[1]
    u1 = twist[1] + twist[5] * point[0] - twist[3] * point[2]
    u2 = twist[2] + twist[3] * point[1] - twist[4] * point[0]
    R0, R1, R2 = R[0], R[1], R[2]
    return (r[0] + R0[0] * point[0] + R0[1] * point[1] + R0[2] * point[2],
            r[1] + R1[0] * point[0] + R1[1] * point[1] + R1[2] * point[2],
            r[2] + R2[0] * point[0] + R2[1] * point[1] + R2[2] * point[2],
            R0[0] * u0 + R0[1] * u1 + R0[2] * u2,
            R1[0] * u0 + R1[1] * u1 + R1[2] * u2,
            R2[0] * u0 + R2[1] * u1 + R2[2] * u2)


def spring_damper(R_a, r_a, twist_a, point_a, R_b, r_b, twist_b, point_b, stiffness, damping, length,
                  wrench_a, wrench_b) -> bool:
    """The wrenches of a linear spring-damper between the point p_a of body a and p_b of body b
    (:func:`spring_end`): the tension k (ℓ − ℓ₀) + d ℓ̇ along e = (x_b − x_a)/ℓ, ℓ = |x_b − x_a|,
    ℓ̇ = e · (v_b − v_a), pulls a towards b (force tension·e at p_a) and b towards a
    (:func:`body_wrench`, world coordinates); written into ``wrench_a`` and ``wrench_b``.
    False (nothing written) when the points coincide: no direction."""
    xa0, xa1, xa2, va0, va1, va2 = spring_end(R_a, r_a, twist_a, point_a)
    xb0, xb1, xb2, vb0, vb1, vb2 = spring_end(R_b, r_b, twist_b, point_b)
    d0, d1, d2 = xb0 - xa0, xb1 - xa1, xb2 - xa2
    ell = (d0 * d0 + d1 * d1 + d2 * d2) ** 0.5
    if abs(ell.real) < 1e-12:
        return False
    e0, e1, e2 = d0 / ell, d1 / ell, d2 / ell
    tension = stiffness * (ell - length) + damping * (e0 * (vb0 - va0) + e1 * (vb1 - va1) + e2 * (vb2 - va2))
    body_wrench(R_a, (tension * e0, tension * e1, tension * e2), point_a, (0.0, 0.0, 0.0), True, wrench_a)
    body_wrench(R_b, (-tension * e0, -tension * e1, -tension * e2), point_b, (0.0, 0.0, 0.0), True, wrench_b)
    return True


def spring_force(stiffness, damping, q_n, q_ref, s_n, tau) -> None:
    """τ = −k (q_n − q_ref) − d ṡ_n of a linear spring-damper on a joint's coordinates
    (q̇_n = ṡ_n), written into ``tau``: the statement of :class:`JointSpring`."""
    for i in range(len(tau)):
        tau[i] = -stiffness * (q_n[i] - q_ref[i]) - damping * s_n[i]


def joint_wrench(F, T, tau, L, y, w_n, w_p) -> None:
    """A generalized force τ on a joint's minimal velocities as an equal and opposite pair
    (module docstring, B(14)): w_n += w and w_p −= Tᵀ w (T = T_np, w_p on the parent) with
    w = F (FᵀF)⁻¹ τ, so F_nᵀ w = τ (F: n_y × k, full column rank); FᵀF = L Lᵀ by Cholesky
    and y = (FᵀF)⁻¹ τ in the scratch ``L`` (k × k) and ``y`` (k)."""
    m, k = len(F), len(tau)
    for i in range(k):  # L Lᵀ = FᵀF row by row, y = L⁻¹ τ
        for j in range(i + 1):
            total = 0.0
            for a in range(m):
                total += F[a][i] * F[a][j]
            for l in range(j):
                total -= L[i][l] * L[j][l]
            L[i][j] = np.sqrt(total) if i == j else total / L[j][j]
        total = tau[i]
        for l in range(i):
            total -= L[i][l] * y[l]
        y[i] = total / L[i][i]
    for i in range(k - 1, -1, -1):  # y = L⁻ᵀ y = (FᵀF)⁻¹ τ
        total = y[i]
        for l in range(i + 1, k):
            total -= L[l][i] * y[l]
        y[i] = total / L[i][i]
    for a in range(m):
        w_a, F_a, T_a = 0.0, F[a], T[a]
        for j in range(k):
            w_a += F_a[j] * y[j]
        w_n[a] += w_a
        for b in range(len(w_p)):
            w_p[b] -= T_a[b] * w_a


def _load(name: str, value, shape: tuple) -> Callable:
    """A constant or a callable ``(t, q, s_dot) -> array`` as a checked callable; where one
    number is expected (shape (1,), a one-dof joint's τ) a scalar is taken as it."""
    if callable(value):
        def load(t, q, s_dot):
            out = _one_number(numeric(value(t, q, s_dot)), shape)  # complex in a complex step
            finite_array(name, np.real(out), shape)
            return out
        load.constant, load.function = None, value  # the callable, for the compiled loop (compiled_load)
        return load
    constant = finite_array(name, _one_number(value, shape), shape)

    def load(t, q, s_dot):
        return constant

    load.constant, load.function = constant, None  # the value, for the symbolic forms
    return load


def _one_number(value, shape: tuple):
    """``value`` as shape (1,) if it is a scalar and ``shape`` is (1,), else unchanged."""
    return np.reshape(value, (1,)) if shape == (1,) and np.ndim(value) == 0 else value


def _callable(parameter: str, load: Callable) -> str | None:
    """Why a law with this load has no symbolic form (None for a constant load)."""
    if load.constant is None:
        return (f"has a callable {parameter}, which is not supported symbolically; give a constant or use "
                "projection_equation")
    return None


def _index(system, name, parameter: str) -> int:
    """Position of subsystem ``name`` in ``system``; an unknown name is an error naming ``parameter``."""
    if name not in system.names:
        raise ValueError(f"{parameter}: unknown subsystem {name!r}; the system has {list(system.names)}")
    return system.index(name)


def _frame(frame: str) -> str:
    if frame not in ("world", "body"):
        raise ValueError(f"frame: expected 'world' or 'body', got {frame!r}")
    return frame


class ForceLaw:
    """The force-law contract: bound to a System by names (:meth:`bind`, which returns the
    law), it adds its loads to the subsystems' h_n at each evaluation (:meth:`add_to`) and
    reports its potential energy (:meth:`potential`).

    Its symbolic form: :meth:`symbolic_wrenches` and :meth:`symbolic_joint_forces`, and
    :meth:`symbolic_unsupported` (None when it has one); its row of the compiled evaluator:
    :meth:`compiled_terms` (and :meth:`compiled_load`). A subclass that restates ``add_to``, ``wrench`` or
    ``generalized_force`` loses the symbolic form and the compiled row it inherits unless
    it restates them too, so an override is never bypassed.
    """

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        drop_inherited_twins(cls, ForceLaw, ("add_to", "wrench", "generalized_force"),
                             ("symbolic_unsupported", "symbolic_wrenches", "symbolic_joint_forces",
                              "compiled_terms", "compiled_load"))

    def bind(self, system) -> "ForceLaw":
        """Resolve the names the law was given in ``system`` (indices, selections) and return
        the law; the System binds a copy when it is built."""
        raise NotImplementedError

    def add_to(self, h, kin, t, q, s_dot) -> None:
        """Add the law's wrenches to the list h of h_n at the kinematic state ``kin``."""
        raise NotImplementedError

    def potential(self, kin, q) -> float:
        """Potential energy of the law at the kinematic state ``kin`` (0 for a law without one)."""
        return 0.0

    def compiled_terms(self) -> tuple | None:
        """(kind, indices, constants) of the bound law for the compiled evaluator's loop
        (:mod:`projeq.assembly.loads`, which names the kinds and their layouts), the same
        statement its ``add_to`` calls; None (the default): the compiled evaluator calls ``add_to``."""
        return None

    def compiled_load(self) -> tuple | None:
        """(function, at, size) where the law's load is a callable ``function(t, q, s_dot)`` of ``size``
        entries: the compiled loop writes its value into the row's constants from entry ``at`` on at
        each evaluation (numba compiles it, :func:`projeq.assembly.generated.load_callbacks`; one it
        cannot compile keeps the law on ``add_to``); None (the default): the constants are the load."""
        return None

    def symbolic_unsupported(self) -> str | None:
        """Why the law has no symbolic form (completing "forces[i] (Law) ..."), else None."""
        return "is not supported symbolically"

    def symbolic_wrenches(self, links) -> dict:
        """{n: wrench (f; M_O) in body n's coordinates, sympy} given the symbolic chain's
        ``links`` (pose ``R``, ``r`` and ``twist`` of each subsystem)."""
        return {}

    def symbolic_joint_forces(self, q_joint, s_joint) -> dict:
        """{n: τ on joint n's minimal velocities, sympy}; ``q_joint[n]``, ``s_joint[n]`` are
        the joint's coordinates and velocities (symbols or the coupling's combinations)."""
        return {}


class _BodyLoad(ForceLaw):
    """A wrench on one body, given as a force at a point and/or a torque."""

    def __init__(self, body: str, frame: str):
        self.body = body
        self.frame = _frame(frame)

    def bind(self, system) -> "_BodyLoad":
        self.index = _index(system, self.body, "body")
        self.S = system.subsystems[self.index].S
        return self

    def add_to(self, h, kin, t, q, s_dot) -> None:
        n = self.index
        wrench = self.wrench(kin.R[n], t, q, s_dot)
        h[n] += wrench if self.S is None else self.S @ wrench


class Force(_BodyLoad):
    """A force on ``body`` acting at ``point`` (body coordinates, m).

    ``force`` is a 3-vector (N) or a callable ``(t, q, s_dot) -> 3-vector``, in world
    coordinates (``frame="world"``) or body coordinates (``frame="body"``).
    """

    def __init__(self, body: str, force, point=(0.0, 0.0, 0.0), frame: str = "world"):
        super().__init__(body, frame)
        self.force = _load("force", force, (3,))
        self.point = finite_array("point", point, (3,))

    def wrench(self, R, t, q, s_dot) -> NDArray:
        wrench = [0.0] * 6
        body_wrench(R.tolist(), self.force(t, q, s_dot).tolist(), self.point.tolist(), _ZERO, self.frame == "world",
                    wrench)
        return np.array(wrench)

    def compiled_terms(self) -> tuple | None:
        force = _ZERO if self.force.function is not None else self.force.constant  # compiled_load's
        return "wrench", (self.index, self.frame == "world"), np.concatenate((force, self.point, _ZERO))

    def compiled_load(self) -> tuple | None:
        return None if self.force.function is None else (self.force.function, 0, 3)

    def symbolic_unsupported(self) -> str | None:
        return _callable("force", self.force)

    def symbolic_wrenches(self, links) -> dict:
        f = algebra.exact(self.force.constant)
        f = algebra.mul(links[self.index].R.T, f) if self.frame == "world" else f
        return {self.index: sp.Matrix.vstack(f, algebra.cross(algebra.exact(self.point), f))}


class Torque(_BodyLoad):
    """A torque (N m) on ``body``: a 3-vector or callable, world or body coordinates."""

    def __init__(self, body: str, torque, frame: str = "world"):
        super().__init__(body, frame)
        self.torque = _load("torque", torque, (3,))

    def wrench(self, R, t, q, s_dot) -> NDArray:
        wrench = [0.0] * 6
        body_wrench(R.tolist(), _ZERO, _ZERO, self.torque(t, q, s_dot).tolist(), self.frame == "world", wrench)
        return np.array(wrench)

    def compiled_terms(self) -> tuple | None:
        torque = _ZERO if self.torque.function is not None else self.torque.constant  # compiled_load's
        return "wrench", (self.index, self.frame == "world"), np.concatenate((_ZERO, _ZERO, torque))

    def compiled_load(self) -> tuple | None:
        return None if self.torque.function is None else (self.torque.function, 6, 3)

    def symbolic_unsupported(self) -> str | None:
        return _callable("torque", self.torque)

    def symbolic_wrenches(self, links) -> dict:
        tau = algebra.exact(self.torque.constant)
        tau = algebra.mul(links[self.index].R.T, tau) if self.frame == "world" else tau
        return {self.index: sp.Matrix.vstack(sp.zeros(3, 1), tau)}


class BodyLoad(ForceLaw):
    """A load on one body stated once: ``statement(R, r, v, omega, t, m)`` returns its wrench
    (f; M_O) about the body's origin in body coordinates (six entries) from the body's pose (R body →
    world, r) and twist (v, ω, body coordinates), written as plain scalar code over the namespace
    ``m`` (:mod:`projeq.joints.statement`: ``m.sqrt``, ``m.vector``, …). From that one statement:
    :meth:`add_to` (numpy, the reference evaluators; complex under a complex step),
    :meth:`symbolic_wrenches` (traced with sympy, for :func:`projeq.symbolic.gauss_form`) and the
    compiled loop's row (:meth:`compiled_terms`, :meth:`compiled_wrench`: the traced wrench printed
    for numba, its numbers passed as data, t an argument; :mod:`projeq.assembly.loads`), a wrench that
    depends on t too. The potential is 0 unless the subclass states :meth:`potential`.

    >>> import numpy as np
    >>> class Drag(BodyLoad):  # −c |v| v at the body's origin
    ...     def __init__(self, body, c):
    ...         super().__init__(body)
    ...         self.c = float(c)
    ...     def statement(self, R, r, v, omega, t, m):
    ...         return m.vector([*(-self.c * m.sqrt(v[0]**2 + v[1]**2 + v[2]**2) * v), 0.0, 0.0, 0.0])
    >>> from projeq.joints.statement import NUMERIC
    >>> Drag("ball", 0.5).statement(np.eye(3), np.zeros(3), np.array([3.0, 4.0, 0.0]), np.zeros(3), 0.0, NUMERIC).tolist()
    [-7.5, -10.0, -0.0, 0.0, 0.0, 0.0]
    """

    def __init__(self, body: str):
        self.body = body

    def statement(self, R, r, v, omega, t, m):
        """The wrench (f; M_O) on the body, body coordinates, at its pose, twist and t (class docstring)."""
        raise NotImplementedError

    def bind(self, system) -> "BodyLoad":
        self.index = _index(system, self.body, "body")
        self.S = system.subsystems[self.index].S
        return self

    def add_to(self, h, kin, t, q, s_dot) -> None:
        n, twist = self.index, kin.twist[self.index]
        wrench = np.asarray(self.statement(kin.R[n], kin.r[n], twist[:3], twist[3:], t, statement.NUMERIC)).reshape(6)
        h[n] += wrench if self.S is None else self.S @ wrench

    def symbolic_unsupported(self) -> str | None:
        return None

    def symbolic_wrenches(self, links) -> dict:
        link = links[self.index]
        twist = sp.Matrix(link.twist)
        found = self.statement(sp.Matrix(link.R), sp.Matrix(link.r), twist[:3, :], twist[3:, :], sp.Symbol("t"),
                               statement.SYMBOLIC)
        return {self.index: sp.Matrix(found).reshape(6, 1)}

    def compiled_wrench(self):
        """``wrench(R, r, w, t)``, the statement traced with sympy at symbols of R (row by row), r and the
        twist w = (v, ω), the law's numbers as constants (:func:`projeq.joints.statement.parameterized`),
        printed as scalar code that numba compiles (:func:`projeq.symbolic.codegen.numeric_function`).
        Built once per law."""
        if "_printed" not in self.__dict__:
            self._printed = _printed_wrench(self)
        return self._printed

    def compiled_terms(self) -> tuple | None:
        return "stated", (self.index,), np.array(self.compiled_wrench().values, dtype=float)


def _printed_wrench(law):
    """:meth:`BodyLoad.compiled_wrench` of ``law``."""
    R, r, w, t = sp.symbols("R0:9"), sp.symbols("r0:3"), sp.symbols("w0:6"), sp.Symbol("t")

    def trace(tracer):
        return sp.Matrix(tracer.statement(sp.Matrix(3, 3, R), sp.Matrix(r), sp.Matrix(w[:3]), sp.Matrix(w[3:]), t,
                                          statement.SYMBOLIC)).reshape(6, 1)

    wrench, symbols, values = statement.parameterized(law, trace, ("S",))
    return _print_wrench(R, r, w, t, sp.ImmutableMatrix(wrench), symbols)(*values)


@functools.lru_cache(maxsize=64)
def _print_wrench(R, r, w, t, wrench, symbols):
    """``make(*p)`` of a traced wrench, one per form in a process (its numba callback is built once)."""
    codegen = lazy_import("projeq.symbolic.codegen")
    return codegen.numeric_function("wrench", [("R", list(R)), ("r", list(r)), ("w", list(w)), ("t", t)], wrench,
                                    constants=list(symbols))


class JointForce(ForceLaw):
    """A generalized force τ on the minimal velocities ṡ_n of ``joint`` (a motor torque,
    a drive force): a constant or a callable ``(t, q, s_dot) -> τ`` (compiled by numba where it
    can be, :meth:`ForceLaw.compiled_load`: written with numpy and math on t, q and ṡ)."""

    def __init__(self, joint: str, tau):
        self.joint = joint
        self.tau = tau

    def bind(self, system) -> "JointForce":
        self.index = n = _index(system, self.joint, "joint")
        self.parent = system.parent[n]
        self.n_s = system.joints[n].n_s
        self._tau = _load(f"tau of joint {self.joint!r}", self.tau, (self.n_s,))
        return self

    def generalized_force(self, t, q, s_dot) -> NDArray:
        return self._tau(t, q, s_dot)

    def add_to(self, h, kin, t, q, s_dot) -> None:
        n, k = self.index, self.n_s
        F, T = kin.F[n], kin.T_aug[n][:-1, :-1]
        w_n, w_p = [0.0] * F.shape[0], [0.0] * T.shape[1]
        tau = self.generalized_force(t, q, s_dot).tolist()
        joint_wrench(F.tolist(), T.tolist(), tau, [[0.0] * k for _ in range(k)], [0.0] * k, w_n, w_p)
        h[n] += w_n
        h[self.parent] += w_p  # the reaction −T_npᵀ w

    def compiled_terms(self) -> tuple | None:
        tau = self._tau.constant if self._tau.function is None else np.zeros(self.n_s)  # compiled_load's
        return "joint_force", (self.index, self.parent), tau

    def compiled_load(self) -> tuple | None:
        return None if self._tau.function is None else (self._tau.function, 0, self.n_s)

    def symbolic_unsupported(self) -> str | None:
        return _callable("tau", self._tau)

    def symbolic_joint_forces(self, q_joint, s_joint) -> dict:
        return {self.index: sp.Matrix(algebra.exact(self._tau.constant))}


class JointSpring(JointForce):
    """A linear spring-damper on a joint coordinate: τ = −k (q_n − q_ref) − d ṡ_n.

    Only for joints with q̇_n = ṡ_n (revolute, prismatic). Potential ½ k (q_n − q_ref)².
    """

    def __init__(self, joint: str, stiffness: float, damping: float = 0.0, q_ref=0.0):
        super().__init__(joint, None)
        self.stiffness = non_negative("stiffness", stiffness)
        self.damping = non_negative("damping", damping)
        self.q_ref = q_ref

    def bind(self, system) -> "JointSpring":
        self.index = n = _index(system, self.joint, "joint")
        self.parent = system.parent[n]
        joint = system.joints[n]
        if not joint.n_s:
            raise ValueError(f"joint: joint {self.joint!r} ({type(joint).__name__}) has no coordinates of its own; "
                             "a JointSpring on it would act on nothing")
        if not _rates_are_speeds(joint):
            raise ValueError(f"joint: JointSpring needs q̇ = ṡ, which joint {self.joint!r} does not have")
        self.n_s = joint.n_s
        q_ref = finite_array("q_ref", self.q_ref)
        if q_ref.ndim > 1 or q_ref.size not in (1, self.n_s):
            raise ValueError(f"q_ref: joint {self.joint!r} has {self.n_s} coordinate(s); give one number or "
                             f"{self.n_s}, got shape {q_ref.shape}")
        self._q_ref = np.broadcast_to(q_ref.ravel(), (self.n_s,)).copy()
        self._q = system.joint_q_getter(n)
        self._s = system.joint_s_dot_getter(n)
        return self

    def generalized_force(self, t, q, s_dot) -> NDArray:
        tau = [0.0] * self.n_s
        q_n, s_n = self._q(q).tolist(), self._s(s_dot).tolist()
        spring_force(self.stiffness, self.damping, q_n, self._q_ref.tolist(), s_n, tau)
        return np.array(tau)

    def compiled_terms(self) -> tuple | None:
        return "joint_spring", (self.index, self.parent), np.concatenate(([self.stiffness, self.damping], self._q_ref))

    def symbolic_unsupported(self) -> str | None:
        return None

    def symbolic_joint_forces(self, q_joint, s_joint) -> dict:
        q_n, s_n = sp.Matrix(q_joint[self.index]), sp.Matrix(s_joint[self.index])
        return {self.index: -self.stiffness * (q_n - algebra.exact(self._q_ref)) - self.damping * s_n}

    def potential(self, kin, q) -> float:
        dq = self._q(q) - self._q_ref
        return 0.5 * self.stiffness * (dq @ dq)


def _rates_are_speeds(joint) -> bool:
    """Whether q̇ = ṡ (K = E) at the joint's reference q and away from it (q + 0.7, every
    coordinate moved): a planar joint's K = diag(R(θ), 1) is E at θ = 0 only, and −k (q − q_ref)
    on its ṡ would not be the force of the potential ½ k |q − q_ref|²."""
    if joint.n_q != joint.n_s:
        return False
    q_ref = joint.default_q()
    return all(np.allclose(joint.K(joint.normalized(q), 0.0), np.eye(joint.n_q)) for q in (q_ref, q_ref + 0.7))


class SpringDamper(ForceLaw):
    """A linear spring-damper between two points: force k (ℓ − ℓ₀) + d ℓ̇ along the line.

    ``body_a`` / ``body_b`` are subsystem names or ``None`` for the ground; points are in
    the body's coordinates (world coordinates for the ground). Potential ½ k (ℓ − ℓ₀)².
    """

    def __init__(self, body_a, point_a, body_b, point_b, stiffness: float, damping: float = 0.0, length: float = 0.0):
        self.bodies = (body_a, body_b)
        self.points = (finite_array("point_a", point_a, (3,)), finite_array("point_b", point_b, (3,)))
        self.stiffness = non_negative("stiffness", stiffness)
        self.damping = non_negative("damping", damping)
        self.length = non_negative("length", length)

    def bind(self, system) -> "SpringDamper":
        names = ("body_a", "body_b")
        self.index = tuple(-1 if b is None else _index(system, b, p) for b, p in zip(self.bodies, names))
        self.S = tuple(system.subsystems[n].S if n >= 0 else None for n in self.index)
        if self.index[0] == self.index[1]:
            raise ValueError(f"body_b: a spring-damper needs two distinct bodies, not {self.bodies[1]!r} twice")
        return self

    def _poses(self, kin) -> list:
        """R, r, twist and point of end a, then of end b (the ground's: index −1 of ``kin``), as lists."""
        return [x.tolist() for n, point in zip(self.index, self.points)
                for x in (kin.R[n], kin.r[n], kin.twist[n], point)]

    def add_to(self, h, kin, t, q, s_dot) -> None:
        wrenches = ([0.0] * 6, [0.0] * 6)
        if not spring_damper(*self._poses(kin), self.stiffness, self.damping, self.length, *wrenches):
            raise ValueError(f"SpringDamper between {self.bodies}: the two points coincide, no direction")
        for n, S, wrench in zip(self.index, self.S, wrenches):
            if n >= 0:
                h[n] += wrench if S is None else S @ wrench

    def compiled_terms(self) -> tuple | None:
        return "spring_damper", self.index, np.concatenate((*self.points, [self.stiffness, self.damping, self.length]))

    def potential(self, kin, q) -> float:
        ends = self._poses(kin)
        x_a, x_b = (np.array(spring_end(*ends[i : i + 4])[:3]) for i in (0, 4))
        d = x_b - x_a
        return 0.5 * self.stiffness * (np.sqrt(d @ d) - self.length) ** 2

    def symbolic_unsupported(self) -> str | None:
        return None

    def symbolic_wrenches(self, links) -> dict:
        """The tension k (ℓ − ℓ₀) + d ℓ̇ along the line a → b, as in :meth:`add_to`."""
        ends = []
        for n, point in zip(self.index, self.points):
            point = algebra.exact(point)
            if n < 0:
                ends.append((point, sp.zeros(3, 1)))
                continue
            link = links[n]
            v_O, omega = link.twist[:3, :], link.twist[3:, :]
            ends.append((link.r + algebra.mul(link.R, point), algebra.mul(link.R, v_O + algebra.cross(omega, point))))
        (x_a, v_a), (x_b, v_b) = ends
        d = x_b - x_a
        length = sp.sqrt(d.dot(d))
        e = d / length
        tension = self.stiffness * (length - self.length) + self.damping * e.dot(v_b - v_a)
        wrenches = {}
        for n, point, sign in zip(self.index, self.points, (1, -1)):
            if n >= 0:
                f = algebra.mul(links[n].R.T, sign * tension * e)  # pulls a towards b and b towards a
                wrenches[n] = sp.Matrix.vstack(f, algebra.cross(algebra.exact(point), f))
        return wrenches

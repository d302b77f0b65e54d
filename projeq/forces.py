"""Impressed forces beyond gravity: they add to h_n = Q_n − G_n ẏ_n of the subsystems.

A force law is bound to a System by names (``bind``), then, at each evaluation, adds its
wrenches to the subsystems' h_n given the kinematic state (``add_to``) and reports its
potential energy (``potential``). Loads on a body enter as a wrench (f, M_O) about the
body's origin in body coordinates, selected by the body's S. A generalized force τ on a
joint's minimal velocities enters as an equal and opposite pair: h_n += w, h_p −= T_npᵀ w
with F_nᵀ w = τ (w = F_n (F_nᵀF_n)⁻¹ τ), whose projection Σ J_nᵀ h_n is exactly τ on ṡ_n
(B(14)); so the assemblers never special-case joint forces.

Callables receive ``(t, q, s_dot)`` and return the load.

Each law states its symbolic form next to its numeric one (:class:`ForceLaw`):
``symbolic_wrenches`` (body wrenches) or ``symbolic_joint_forces`` (τ on minimal
velocities), which :func:`projeq.symbolic.gauss_form` adds; a law that has none says why
in ``symbolic_unsupported`` (a load given as a callable has values, not expressions).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from numpy.typing import NDArray

from projeq.checks import drop_inherited_twins, finite_array, non_negative
from projeq.symbolic import lazy_import
from projeq.spatial import cross, norm, numeric

sp = lazy_import("sympy")
algebra = lazy_import("projeq.symbolic.algebra")


def _load(name: str, value, shape: tuple) -> Callable:
    """A constant or a callable ``(t, q, s_dot) -> array`` as a checked callable."""
    if callable(value):
        def load(t, q, s_dot):
            out = numeric(value(t, q, s_dot))  # complex in a complex step
            finite_array(name, np.real(out), shape)
            return out
        load.constant = None
        return load
    constant = finite_array(name, value, shape)

    def load(t, q, s_dot):
        return constant

    load.constant = constant  # the value, for the symbolic forms
    return load


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
    :meth:`symbolic_unsupported` (None when it has one). A subclass that restates
    ``add_to``, ``wrench`` or ``generalized_force`` loses the symbolic form it inherits
    unless it restates it too, so an override is never bypassed.
    """

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        drop_inherited_twins(cls, ForceLaw, ("add_to", "wrench", "generalized_force"),
                             ("symbolic_unsupported", "symbolic_wrenches", "symbolic_joint_forces"))

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
        f = self.force(t, q, s_dot)
        f = R.T @ f if self.frame == "world" else f
        return np.concatenate((f, cross(self.point, f)))

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
        tau = self.torque(t, q, s_dot)
        return np.concatenate((np.zeros(3), R.T @ tau if self.frame == "world" else tau))

    def symbolic_unsupported(self) -> str | None:
        return _callable("torque", self.torque)

    def symbolic_wrenches(self, links) -> dict:
        tau = algebra.exact(self.torque.constant)
        tau = algebra.mul(links[self.index].R.T, tau) if self.frame == "world" else tau
        return {self.index: sp.Matrix.vstack(sp.zeros(3, 1), tau)}


class JointForce(ForceLaw):
    """A generalized force τ on the minimal velocities ṡ_n of ``joint`` (a motor torque,
    a drive force): a constant or a callable ``(t, q, s_dot) -> τ``."""

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
        n, F = self.index, kin.F[self.index]
        tau = self.generalized_force(t, q, s_dot)
        w = F @ np.linalg.solve(F.T @ F, tau)  # F_nᵀ w = τ
        h[n] += w
        h[self.parent] -= kin.T_aug[n][:-1, :-1].T @ w  # reaction on p: −T_npᵀ w

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
        if joint.n_q != joint.n_s or not np.allclose(joint.K(joint.default_q(), 0.0), np.eye(joint.n_q)):
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
        return -self.stiffness * (self._q(q) - self._q_ref) - self.damping * self._s(s_dot)

    def symbolic_unsupported(self) -> str | None:
        return None

    def symbolic_joint_forces(self, q_joint, s_joint) -> dict:
        q_n, s_n = sp.Matrix(q_joint[self.index]), sp.Matrix(s_joint[self.index])
        return {self.index: -self.stiffness * (q_n - algebra.exact(self._q_ref)) - self.damping * s_n}

    def potential(self, kin, q) -> float:
        dq = self._q(q) - self._q_ref
        return 0.5 * self.stiffness * (dq @ dq)


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

    def _ends(self, kin):
        """World position and velocity of both attachment points."""
        ends = []
        for n, point in zip(self.index, self.points):
            if n < 0:
                ends.append((point, np.zeros(3)))
                continue
            v_O, omega = kin.twist[n][:3], kin.twist[n][3:]
            R = kin.R[n]
            ends.append((kin.r[n] + R @ point, R @ (v_O + cross(omega, point))))
        return ends

    def add_to(self, h, kin, t, q, s_dot) -> None:
        (x_a, v_a), (x_b, v_b) = self._ends(kin)
        d = x_b - x_a
        length = norm(d)
        if abs(length) < 1e-12:
            raise ValueError(f"SpringDamper between {self.bodies}: the two points coincide, no direction")
        e = d / length
        tension = self.stiffness * (length - self.length) + self.damping * (e @ (v_b - v_a))
        for n, point, S, sign in zip(self.index, self.points, self.S, (1.0, -1.0)):
            if n < 0:
                continue
            f = kin.R[n].T @ (sign * tension * e)  # pulls a towards b and b towards a
            wrench = np.concatenate((f, cross(point, f)))
            h[n] += wrench if S is None else S @ wrench

    def potential(self, kin, q) -> float:
        (x_a, _), (x_b, _) = self._ends(kin)
        return 0.5 * self.stiffness * (norm(x_b - x_a) - self.length) ** 2

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

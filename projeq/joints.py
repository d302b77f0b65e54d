"""How subsystems connect: the kinematic chain ẏ_n = T_np ẏ_p + F_n ṡ_n (THEORY §4).

A joint describes the motion of the child frame n relative to a *joint frame* J fixed in
the parent p (placed at ``r_pn`` with ``orientation`` J → p). Every joint returns, at
(q_n, ṡ_n, t), a :class:`Relative`:

- ``A``: child → joint-frame rotation; ``r``: J → O_n in joint-frame coordinates;
- ``F``: F⁶_n, the relative twist (v, ω) of n per unit ṡ_n, in child coordinates;
- ``w``: the relative twist F⁶ ṡ_n + f⁶(t) (f⁶ ≠ 0 for prescribed, rheonomic motion);
- ``zeta``: Ḟ⁶ ṡ_n + ḟ⁶, the joint's own part of ζ_n.

The chain matrix T_np follows from (A, r) once, in :mod:`projeq.kinematics`, for every
joint alike; positions follow q̇_n = K_n(q) ṡ_n + k_n(q, t).

Letters: ``K`` is q̇ = K ṡ (never a stiffness); ``A`` a rotation; ``t`` time.
"""

from __future__ import annotations

from typing import Callable, NamedTuple, Sequence

import numpy as np
import sympy as sp
from numpy.typing import NDArray

from projeq.checks import finite_array
from projeq.spatial import (
    quaternion_matrix,
    quaternion_rate_matrix,
    skew,
    unit_axis,
    vee,
)

_ZERO6 = np.zeros(6)
_ZERO6.flags.writeable = False


class Relative(NamedTuple):
    """Relative kinematics of a joint at one instant (see the module docstring)."""

    A: NDArray
    r: NDArray
    F: NDArray
    w: NDArray
    zeta: NDArray


class Joint:
    """Base class: placement on the parent and the bookkeeping shared by all joints.

    Parameters
    ----------
    parent : str or None
        Name of the parent subsystem; ``None`` is the inertial ground.
    r_pn : 3-vector
        Origin of the joint frame in parent coordinates (m).
    orientation : 3×3 rotation, optional
        Joint-frame → parent coordinates (default: aligned).
    coupling : dict, optional
        ``{joint_name: ratio}``: the joint has no coordinate of its own; its coordinate is
        Σ ratio · (that joint's coordinate) — gears, pulleys and ropes. Only for one-dof
        joints with q̇ = ṡ. Shared minimal velocities make ∂ẏ/∂ṡ non-triangular, so such
        systems are evaluated by the dense Gauss form (THEORY §4).
    """

    n_q = 0
    n_s = 0
    n_c = 0  # number of velocity constraints whose residual the joint reports

    def __init__(self, parent=None, r_pn=(0.0, 0.0, 0.0), orientation=None, coupling=None):
        if parent is not None and not isinstance(parent, str):
            raise ValueError(f"parent: expected a subsystem name or None, got {parent!r}")
        self.parent = parent
        self.r_pn = finite_array("r_pn", r_pn, (3,))
        self.orientation = _rotation_matrix("orientation", orientation)
        self.coupling = _coupling(coupling, self)

    def relative(self, q_n: NDArray, s_dot_n: NDArray, t: float) -> Relative:
        """Relative kinematics (A, r, F⁶, w, ζ) at (q_n, ṡ_n, t)."""
        raise NotImplementedError

    def K(self, q_n: NDArray, t: float) -> NDArray:
        """K_n(q) of q̇_n = K_n ṡ_n + k_n (identity for q̇ = ṡ)."""
        return np.eye(self.n_q, self.n_s)

    def q_dot(self, q_n: NDArray, s_dot_n: NDArray, t: float) -> NDArray:
        """q̇_n = K_n(q) ṡ_n + k_n(q, t)."""
        return self.K(q_n, t) @ s_dot_n

    def default_q(self) -> NDArray:
        """Coordinates of the reference configuration (zero unless a joint says otherwise)."""
        return np.zeros(self.n_q)

    def constraint_residual(self, q_n: NDArray, q_dot_n: NDArray, t: float) -> NDArray:
        """Residuals of the velocity constraints the minimal velocities are meant to
        satisfy, evaluated on (q, q̇) (none for the built-in joints)."""
        return np.zeros(0)

    def normalized(self, q_n: NDArray) -> NDArray:
        """q_n projected back onto its manifold (unit quaternions); identity otherwise."""
        return q_n

    def __repr__(self) -> str:
        return f"{type(self).__name__}(parent={self.parent!r})"


def _rotation_matrix(name: str, value) -> NDArray:
    if value is None:
        return np.eye(3)
    A = finite_array(name, value, (3, 3))
    if np.abs(A.T @ A - np.eye(3)).max() > 1e-9 or np.linalg.det(A) < 0:
        raise ValueError(f"{name}: not a proper rotation matrix (AᵀA ≠ E or det < 0):\n{A}")
    return A


def _coupling(coupling, joint) -> dict:
    if not coupling:
        return {}
    if not isinstance(coupling, dict):
        raise ValueError(f"coupling: expected {{joint_name: ratio}}, got {coupling!r}")
    return {name: float(finite_array(f"coupling[{name!r}]", ratio, ())) for name, ratio in coupling.items()}


class _OneAxis(Joint):
    """Shared part of the one-dof joints along or about a unit axis e (joint-frame coordinates)."""

    n_q = 1
    n_s = 1

    def __init__(self, parent=None, axis="z", r_pn=(0.0, 0.0, 0.0), orientation=None, coupling=None):
        super().__init__(parent, r_pn, orientation, coupling)
        self.axis = unit_axis(axis, "axis")


class Revolute(_OneAxis):
    """Rotation θ about the unit axis e through O_n: F⁶ = [0; e] (THEORY §4).

    θ is positive by the right-hand rule about e; q = ṡ-integral = (θ,).
    """

    def __init__(self, parent=None, axis="z", r_pn=(0.0, 0.0, 0.0), orientation=None, coupling=None):
        super().__init__(parent, axis, r_pn, orientation, coupling)
        self._E = skew(self.axis)
        self._E2 = self._E @ self._E
        self._F = np.concatenate((np.zeros(3), self.axis))[:, None]

    def relative(self, q_n, s_dot_n, t):
        A = np.eye(3) + np.sin(q_n[0]) * self._E + (1.0 - np.cos(q_n[0])) * self._E2
        return Relative(A, _ZERO6[:3], self._F, self._F[:, 0] * s_dot_n[0], _ZERO6)


class Prismatic(_OneAxis):
    """Translation x along the unit axis e: F⁶ = [e; 0], r = e x (THEORY §4)."""

    def __init__(self, parent=None, axis="z", r_pn=(0.0, 0.0, 0.0), orientation=None, coupling=None):
        super().__init__(parent, axis, r_pn, orientation, coupling)
        self._F = np.concatenate((self.axis, np.zeros(3)))[:, None]

    def relative(self, q_n, s_dot_n, t):
        return Relative(np.eye(3), self.axis * q_n[0], self._F, self._F[:, 0] * s_dot_n[0], _ZERO6)


class Fixed(Joint):
    """A rigid connection: no coordinates; the child is the joint frame."""

    _F = np.zeros((6, 0))

    def relative(self, q_n, s_dot_n, t):
        return Relative(np.eye(3), _ZERO6[:3], self._F, _ZERO6, _ZERO6)


class Planar(Joint):
    """Three dof in a plane of the joint frame: q = (a, b, θ), ṡ = (v_a, v_b, ω).

    (a, b) locate O_n along the plane's first and second axis, θ turns about its normal.
    The minimal velocities are the relative velocity of O_n and the spin in *child*
    coordinates, so F⁶ is constant and K(q) rotates (v_a, v_b) into the joint frame —
    Bremer's car (B(11)) is this joint with the lateral velocity v_b = 0 removed.
    """

    n_q = 3
    n_s = 3
    _AXES = {"xy": (0, 1, 2), "yz": (1, 2, 0), "zx": (2, 0, 1), "xz": (0, 2, 1)}

    def __init__(self, parent=None, plane="xy", r_pn=(0.0, 0.0, 0.0), orientation=None):
        super().__init__(parent, r_pn, orientation)
        if plane not in self._AXES:
            raise ValueError(f"plane: unknown plane {plane!r}; use one of {sorted(self._AXES)}")
        self.plane = plane
        a, b, n = (np.eye(3)[i] for i in self._AXES[plane])
        self._P = np.array([a, b])
        self.normal = n
        self._E = skew(n)
        self._E2 = self._E @ self._E
        self._F = np.zeros((6, 3))
        self._F[:3, 0], self._F[:3, 1], self._F[3:, 2] = a, b, n

    def _A(self, theta):
        return np.eye(3) + np.sin(theta) * self._E + (1.0 - np.cos(theta)) * self._E2

    def relative(self, q_n, s_dot_n, t):
        r = self._P.T @ q_n[:2]
        return Relative(self._A(q_n[2]), r, self._F, self._F @ s_dot_n, _ZERO6)

    def K(self, q_n, t):
        K = np.zeros((3, 3))
        K[:2, :2] = self._P @ self._A(q_n[2]) @ self._P.T
        K[2, 2] = 1.0
        return K


class Free(Joint):
    """Six dof: q = (r, quaternion (w, x, y, z)), ṡ = (v, ω) of the child in child coordinates.

    F⁶ = E₆; ṙ = A v and q̇_quat = ½ quat ⊗ (0, ω) (no Euler-angle singularity). The
    quaternion is normalised wherever the pose is evaluated and in simulation output.
    """

    n_q = 7
    n_s = 6
    _F = np.eye(6)

    def relative(self, q_n, s_dot_n, t):
        A = quaternion_matrix(q_n[3:] / np.linalg.norm(q_n[3:]))
        return Relative(A, q_n[:3], self._F, s_dot_n, _ZERO6)

    def K(self, q_n, t):
        quat = q_n[3:] / np.linalg.norm(q_n[3:])
        K = np.zeros((7, 6))
        K[:3, :3] = quaternion_matrix(quat)
        K[3:, 3:] = quaternion_rate_matrix(quat)
        return K

    def default_q(self):
        return np.array([0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])

    def normalized(self, q_n):
        out = np.array(q_n, dtype=float)
        out[3:] /= np.linalg.norm(out[3:])
        return out


class Prescribed(Joint):
    """A one-dof joint whose coordinate is a given function of time (rheonomic).

    ẏ_n = T_np ẏ_p + f⁶(t) with f⁶ = F⁶ θ̇(t), and ζ_n gains F⁶ θ̈(t) (THEORY §4). The
    joint adds no coordinate and no minimal velocity.

    Parameters
    ----------
    joint : Revolute or Prismatic
        The joint whose coordinate θ is prescribed (its parent and placement are used).
    motion : sympy expression in ``t`` or callable
        θ(t) as an expression in the symbol ``t`` (θ̇, θ̈ by differentiation), or a callable
        ``t -> (θ, θ̇, θ̈)``.
    """

    def __init__(self, joint: Joint, motion):
        if not isinstance(joint, _OneAxis) or joint.coupling:
            raise ValueError("joint: Prescribed needs an uncoupled Revolute or Prismatic joint")
        super().__init__(joint.parent, joint.r_pn, joint.orientation)
        self.joint = joint
        self.motion = motion if callable(motion) else _time_function(motion)

    def relative(self, q_n, s_dot_n, t):
        theta, theta_dot, theta_ddot = self.motion(t)
        inner = self.joint.relative(np.array([theta]), np.array([theta_dot]), t)
        zeta = inner.zeta + inner.F[:, 0] * theta_ddot
        return Relative(inner.A, inner.r, Fixed._F, inner.w, zeta)


def _time_function(expr) -> Callable:
    t = sp.Symbol("t")
    expr = sp.sympify(expr)
    extra = expr.free_symbols - {t}
    if extra:
        raise ValueError(f"motion: depends on {sorted(map(str, extra))}; only t is allowed")
    f = sp.lambdify(t, [expr, expr.diff(t), expr.diff(t, 2)], modules="numpy")
    return lambda time: tuple(float(v) for v in f(time))


class UserJoint(Joint):
    """A joint defined by its pose and minimal velocities: the door for non-holonomic ṡ.

    The child's pose relative to the joint frame is (A(q, t), r(q, t)); its relative twist
    (v, ω) in child coordinates is F⁶(q, t) ṡ + f⁶(q, t); positions follow
    q̇ = K(q, t) ṡ + k(q, t). The minimal velocities ṡ may be quasi-velocities, and a
    velocity constraint goes in *before* the derivation by leaving its direction out of F
    (Bremer's car: ṡ = (v_x, ω_z), B(11)). Ḟ ṡ + ḟ is obtained by differentiation along
    q̇ (symbolically, or by complex-step for callables), and the pose is checked against
    F and K at construction.

    Build with :meth:`from_sympy` or :meth:`from_functions`.
    """

    def __init__(self, parent, n_q, n_s, relative, K, q_dot, q0=None, r_pn=(0, 0, 0), orientation=None,
                 constraints=None, n_c=0):
        super().__init__(parent, r_pn, orientation)
        self.n_q, self.n_s, self.n_c = n_q, n_s, n_c
        self._relative, self._K, self._q_dot = relative, K, q_dot
        self._constraints = constraints
        self._q0 = np.zeros(n_q) if q0 is None else finite_array("q0", q0, (n_q,))

    def relative(self, q_n, s_dot_n, t):
        return self._relative(q_n, s_dot_n, t)

    def K(self, q_n, t):
        return self._K(q_n, t)

    def q_dot(self, q_n, s_dot_n, t):
        return self._q_dot(q_n, s_dot_n, t)

    def default_q(self):
        return self._q0.copy()

    def constraint_residual(self, q_n, q_dot_n, t):
        if self._constraints is None:
            return np.zeros(0)
        return np.asarray(self._constraints(q_n, q_dot_n, t), dtype=float).ravel()

    @classmethod
    def from_sympy(
        cls,
        q: Sequence[sp.Symbol],
        s: Sequence[sp.Symbol],
        A,
        r,
        F,
        K,
        *,
        f=None,
        k=None,
        t: sp.Symbol | None = None,
        parameters: dict | None = None,
        constraints=None,
        q_dot: Sequence[sp.Symbol] | None = None,
        parent=None,
        q0=None,
        r_pn=(0.0, 0.0, 0.0),
        orientation=None,
    ) -> "UserJoint":
        """A user joint from sympy expressions in the coordinates ``q``, the minimal
        velocities ``s`` (ṡ), time ``t`` and ``parameters`` ({symbol: value}).

        ``A`` (3×3) and ``r`` (3) give the pose, ``F`` (6×n_s) and ``f`` (6) the relative
        twist F ṡ + f in child coordinates, ``K`` (n_q×n_s) and ``k`` (n_q) give q̇.
        Ḟ ṡ + ḟ = (∂F/∂q q̇ + ∂F/∂t) ṡ + ∂f/∂q q̇ + ∂f/∂t is derived and compiled once.
        ``constraints`` lists the original velocity constraints (expressions in q, the
        symbols ``q_dot`` for q̇, and t) whose residuals every Result reports.
        """
        from projeq.symbolic_joint import compile_user_joint

        return compile_user_joint(
            cls, q, s, A, r, F, K, f=f, k=k, t=t, parameters=parameters or {},
            parent=parent, q0=q0, r_pn=r_pn, orientation=orientation,
            constraints=constraints, q_dot=q_dot,
        )

    @classmethod
    def from_functions(
        cls,
        n_q: int,
        n_s: int,
        pose: Callable,
        F: Callable,
        K: Callable,
        *,
        f: Callable | None = None,
        k: Callable | None = None,
        constraints: Callable | None = None,
        n_c: int = 0,
        parent=None,
        q0=None,
        r_pn=(0.0, 0.0, 0.0),
        orientation=None,
    ) -> "UserJoint":
        """A user joint from callables ``pose(q, t) -> (A, r)``, ``F(q, t)``, ``K(q, t)``
        (and optionally ``f(q, t)``, ``k(q, t)``).

        Ḟ ṡ + ḟ is taken by complex-step differentiation along (q̇, 1), exact to
        round-off, so the callables must accept complex arguments (numpy ufuncs do).
        ``constraints(q, q_dot, t)`` returns the ``n_c`` residuals of the original velocity
        constraints, reported along every simulated trajectory.
        """
        from projeq.symbolic_joint import wrap_user_functions

        return wrap_user_functions(
            cls, n_q, n_s, pose, F, K, f=f, k=k, parent=parent, q0=q0, r_pn=r_pn,
            orientation=orientation, constraints=constraints, n_c=n_c,
        )


def pose_twist_mismatch(joint: Joint, q_n: NDArray, s_dot_n: NDArray, t: float, h: float = 1e-7) -> float:
    """Largest difference between F⁶ ṡ + f⁶ and the relative twist obtained by
    differentiating the pose (A, r) along q̇ = K ṡ + k (central differences, step h).

    Used to validate user joints; for the built-in joints it is a test of their K.
    """
    q_dot = joint.q_dot(q_n, s_dot_n, t)
    ahead = joint.relative(joint.normalized(q_n + h * q_dot), s_dot_n, t + h)
    behind = joint.relative(joint.normalized(q_n - h * q_dot), s_dot_n, t - h)
    now = joint.relative(q_n, s_dot_n, t)
    A_dot = (ahead.A - behind.A) / (2 * h)
    r_dot = (ahead.r - behind.r) / (2 * h)
    twist = np.concatenate((now.A.T @ r_dot, vee(now.A.T @ A_dot)))
    return float(np.abs(twist - now.w).max())

"""Rigid subsystems: the Gauss-form terms of docs/theory.md §3, written once.

ẏ = (v_O, ω) in the body-fixed frame with origin O; ``r_c`` is O → mass centre and
``I_c`` the inertia tensor about the mass centre, both in body coordinates.

    M = [[m E, −m r̃_c], [m r̃_c, I_O]],    I_O = I_c − m r̃_c r̃_c
    G ẏ = [m ω̃ v_c ; m r̃_c ω̃ v_c + ω̃ I_c ω],   v_c = v_O − r̃_c ω
    Q = [f ; r̃_c f]   (gravity f = m g at the mass centre; other loads are added by the System)

The planar body and the point mass are the same formulas: a planar body selects the
in-plane rows (``S``), a point mass has I_c = 0.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.checks import finite_array, inertia_tensor, positive
from projeq.spatial import cross, skew
from projeq.subsystems.base import Subsystem

_PLANES = {"xy": (0, 1, 5), "yz": (1, 2, 3), "zx": (2, 0, 4), "xz": (0, 2, 4)}
_ZERO3, _ZERO3x3 = np.zeros(3), np.zeros((3, 3))
_ZERO3.flags.writeable = _ZERO3x3.flags.writeable = False


def rigid_mass_matrix(m: float, r_c: NDArray, I_c: NDArray) -> NDArray:
    """M = [[m E, −m r̃_c], [m r̃_c, I_c − m r̃_c r̃_c]] (docs/theory.md §3)."""
    rc = skew(r_c)
    M = np.zeros((6, 6))
    M[:3, :3] = m * np.eye(3)
    M[:3, 3:] = -m * rc
    M[3:, :3] = m * rc
    M[3:, 3:] = I_c - m * rc @ rc
    return M


def gravity_potential(m, r_c: NDArray, R: NDArray, r: NDArray, gravity: NDArray):
    """V = −Σ m g · (r + R r_c): the gravity potential of one rigid body (m, r_c in its frame, at the
    pose R, r), of bodies stacked along the first axis (m (n,), r_c (n, 3), R (n, 3, 3), r (n, 3)),
    or one V per row of such stacks (R (k, n, 3, 3), r (k, n, 3): V (k,))."""
    heights = (r + (R @ r_c[..., None])[..., 0]) @ gravity
    return -np.sum(m * heights, axis=-1) if np.ndim(heights) else -m * heights


def rigid_h(m, r_c: NDArray, I_c: NDArray, twist: NDArray, g_body: NDArray) -> NDArray:
    """h = Q − G ẏ of a rigid body with gravity g (body coordinates), docs/theory.md §3.

    With the momentum p = m v_c: h = [m g − ω̃ p ; r̃_c (m g − ω̃ p) − ω̃ I_c ω].
    Works on one body or row-wise on stacks: m (...), r_c (..., 3), I_c (..., 3, 3),
    twist (..., 6), g_body (..., 3).
    """
    m = np.asarray(m)[..., None]
    v, omega = twist[..., :3], twist[..., 3:]
    p_c = m * (v + cross(omega, r_c))
    force = m * g_body - cross(omega, p_c)
    L_c = (I_c @ omega[..., None])[..., 0]
    return np.concatenate((force, cross(r_c, force) - cross(omega, L_c)), axis=-1)


class RigidGroup:
    """Subsystems with rigid-body terms (``rigid_inertia``) and the same S evaluated
    together: :func:`rigid_h` on stacks.

    ``M[k]`` and the rows of ``h(...)`` belong to ``bodies[k]``; equal to calling each
    body's ``gauss_terms`` (tests/subsystems/test_rigid.py), several times faster.
    """

    def __init__(self, bodies):
        self.m, self.r_c, self.I_c = (np.array(part) for part in zip(*(b.rigid_inertia for b in bodies)))
        self.M = [b.gauss_terms(np.zeros(b.n_y), np.eye(3), np.zeros(3))[0] for b in bodies]
        self.S = bodies[0].S

    def h(self, y_dot: NDArray, R: NDArray, gravity: NDArray) -> NDArray:
        """h_n of every body: rows of y_dot (N, n_y) with rotations R (N, 3, 3)."""
        twist = y_dot if self.S is None else y_dot @ self.S
        g_body = gravity @ R  # rows Rᵀ g
        h6 = rigid_h(self.m, self.r_c, self.I_c, twist, g_body)
        return h6 if self.S is None else h6 @ self.S.T


class RigidBody(Subsystem):
    """A spatial rigid body: the subsystem of docs/theory.md §3 with ẏ = (v_O, ω).

    Parameters
    ----------
    m : float
        Mass in kg (> 0).
    r_c : 3-vector
        Body origin O (where its joint attaches) → mass centre, body coordinates, m.
    I_c : 3×3 array
        Inertia tensor about the mass centre in body coordinates, kg m², symmetric
        positive definite with principal moments obeying the triangle inequality; or with
        one principal moment zero (a slender rod, as sympy/PyDy models have it): then no
        joint may turn the body about that axis (:attr:`slender_axis`), checked when the
        System is built.

    Attributes
    ----------
    slender_axis : ndarray or None
        The unit axis (body coordinates) of a zero principal moment of I_c, else None.

    Examples
    --------
    >>> import numpy as np, projeq as pq
    >>> body = pq.RigidBody(m=2.0, r_c=(0, 0, -0.5), I_c=np.diag([0.1, 0.1, 0.02]))
    >>> M, h = body.gauss_terms(np.zeros(6), np.eye(3), np.array([0, 0, -9.81]))
    >>> float(h[2])     # weight m g along −z
    -19.62
    """

    n_y = 6

    def __init__(self, m: float, r_c=(0.0, 0.0, 0.0), I_c=None):
        self.m = positive("m (mass)", m)
        self.r_c = finite_array("r_c", r_c, (3,))
        self.I_c = self._check_inertia(np.eye(3) * 0.0 if I_c is None else I_c)
        self.slender_axis = slender_axis(self.I_c)
        self.M6 = rigid_mass_matrix(self.m, self.r_c, self.I_c)
        self.M6.flags.writeable = False

    @staticmethod
    def _check_inertia(I_c) -> NDArray:
        I_c = inertia_tensor("I_c", I_c, allow_zero=True)  # semi-definite: a slender rod
        if not np.any(I_c):
            raise ValueError("I_c: inertia tensor is not positive definite (all zero); a particle is a PointMass")
        return I_c

    @property
    def rigid_inertia(self) -> tuple:
        """(m, r_c, I_c): :meth:`gauss_terms` are docs/theory.md §3's of these (a subclass that
        overrides ``gauss_terms`` has ``rigid_inertia = None``, :class:`Subsystem`)."""
        return self.m, self.r_c, self.I_c

    def gauss_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e=None):
        """(M_n, h_n) of docs/theory.md §3; ``R`` body → inertial, ``gravity`` inertial (a rigid
        body has no internal coordinates q_e)."""
        return self.M6, rigid_h(self.m, self.r_c, self.I_c, y_dot, R.T @ gravity)

    def kinetic_energy(self, y_dot: NDArray, q_e=None) -> float:
        """½ ẏᵀ M ẏ."""
        return 0.5 * (y_dot @ self.M6 @ y_dot)

    def potential_energy(self, R: NDArray, r: NDArray, gravity: NDArray, q_e=None) -> float:
        """−m g · r_c(inertial) (:func:`gravity_potential`)."""
        return gravity_potential(self.m, self.r_c, R, r, gravity)

    def __repr__(self) -> str:
        return f"{type(self).__name__}(m={self.m}, r_c={self.r_c.tolist()})"


def slender_axis(I_c: NDArray) -> NDArray | None:
    """The unit principal axis of a single zero principal moment of I_c (a slender rod's
    axis), or None (none zero, or all: a point mass)."""
    moments, axes = np.linalg.eigh(I_c)
    zero = moments <= 1e-12 * max(np.abs(moments).max(), 1e-300)
    return axes[:, 0] if zero.sum() == 1 else None


class PointMass(RigidBody):
    """A particle of mass ``m`` at ``r_c`` from the frame origin: a rigid body with I_c = 0.

    Its reference frame still turns with its joint, so a pendulum bob is a ``PointMass``
    on a ``Revolute`` with ``r_c`` the rod vector.
    """

    def __init__(self, m: float, r_c=(0.0, 0.0, 0.0)):
        super().__init__(m, r_c, np.zeros((3, 3)))

    @staticmethod
    def _check_inertia(I_c) -> NDArray:
        return inertia_tensor("I_c", I_c, allow_zero=True)


class PlanarBody(RigidBody):
    """A rigid body moving in a plane: the spatial body restricted by a selection S.

    ẏ = S (v_O, ω) holds the two in-plane velocity components and the spin about the
    plane's normal; M = S M⁶ Sᵀ and h = S h⁶(Sᵀ ẏ) are the spatial formulas, so the planar
    body equals the spatial one restricted to the plane (tests/subsystems/test_rigid.py).

    Parameters
    ----------
    m, r_c : as for :class:`RigidBody` (``r_c`` a 3-vector in body coordinates).
    I_c : float or 3×3 array
        Moment of inertia about the normal through the mass centre, or a full tensor.
    plane : ``"xy"`` (normal z), ``"yz"`` (normal x) or ``"zx"`` / ``"xz"`` (normal y).
    """

    n_y = 3
    rigid_inertia = RigidBody.rigid_inertia  # its terms are the rigid ones, selected by S

    def __init__(self, m: float, r_c=(0.0, 0.0, 0.0), I_c=0.0, plane: str = "xy"):
        if plane not in _PLANES:
            raise ValueError(f"plane: unknown plane {plane!r}; use one of {sorted(_PLANES)}")
        self.plane = plane
        self.rows = np.array(_PLANES[plane])
        if np.ndim(I_c) == 0:  # only the moment about the normal enters the planar terms
            I_c = np.eye(3) * positive("I_c (moment about the plane normal)", I_c)
        super().__init__(m, r_c, I_c)
        self.S = np.eye(6)[self.rows]
        self.M = self.M6[np.ix_(self.rows, self.rows)]

    def gauss_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e=None):
        """(S M⁶ Sᵀ, S h⁶(Sᵀ ẏ)): the spatial terms restricted to the plane."""
        return self.M, rigid_h(self.m, self.r_c, self.I_c, self.S.T @ y_dot, R.T @ gravity)[self.rows]

    def kinetic_energy(self, y_dot: NDArray, q_e=None) -> float:
        """½ ẏᵀ M ẏ."""
        return 0.5 * (y_dot @ self.M @ y_dot)


class Frame(Subsystem):
    """A massless frame: a place to chain joints (a universal joint as two revolutes).

    M_n = 0 and h_n = 0 (the rigid-body terms of zero mass and inertia); the system stays
    regular as long as every joint moves some mass further out (else the evaluators raise
    :class:`projeq.SingularMassError`).
    """

    n_y = 6
    rigid_inertia = (0.0, _ZERO3, _ZERO3x3)

    def gauss_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e=None):
        """(0, 0): no mass, no load."""
        return np.zeros((6, 6)), np.zeros(6)

    def kinetic_energy(self, y_dot: NDArray, q_e=None) -> float:
        return 0.0

    def potential_energy(self, R: NDArray, r: NDArray, gravity: NDArray, q_e=None) -> float:
        return 0.0

    def __repr__(self) -> str:
        return "Frame()"

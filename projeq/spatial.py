"""Spatial kinematics: spin matrices, rotations, quaternions and rigid chain matrices.

Pure functions on numpy arrays, in Bremer's notation (docs/theory.md §1, §4):

- ``skew(a)`` is the spin matrix ã with ã b = a × b;
- ``A_np`` rotates coordinates of frame p into frame n; ``R`` (no subscript) is a
  rotation whose columns are a body's axes in inertial coordinates (body → inertial);
- a *twist* is the 6-vector (v_O, ω) of a frame's origin velocity and angular velocity,
  both in that frame's own coordinates; ``T_np`` maps the twist of p to the part of the
  twist of n that p's motion causes (B(15), docs/theory.md §4).

This is the one numeric home of these formulas. Every function is complex-safe: complex
input gives the complex result of the same formula (no float-only buffers), so complex-step
differentiation, Im f(x + iε ẋ)/ε = ḟ to round-off, works through them (a beam port's Ḟ,
the Ḟ of user joints from callables). The compiled order-n kernel keeps scalar twins of
the rotation, the chain matrix and the rigid-body h (:mod:`projeq.assembly.kernels`),
tested equal to these.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray


def numeric(value) -> NDArray:
    """``value`` as a float array, or a complex one if it is complex (a complex step passes)."""
    array = np.asarray(value)
    return array if np.iscomplexobj(array) else array.astype(float)


def norm(v) -> NDArray:
    """The Euclidean length √(v · v) of the last axis, analytic in complex arithmetic (a complex
    step passes; ``np.linalg.norm`` takes moduli)."""
    v = np.asarray(v)
    return np.sqrt(np.sum(v * v, axis=-1))


_AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}


def skew(a) -> NDArray:
    """Spin matrix ã of a 3-vector, so that ``skew(a) @ b == a × b``."""
    return np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])


def cross(a, b) -> NDArray:
    """a × b for 3-vectors, or row-wise for stacks of shape (..., 3).

    A plain formula: for 3-vectors ten times faster than ``np.cross``; stacks are written
    into one preallocated array.
    """
    if a.ndim == 1 and b.ndim == 1:
        return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
    out = np.empty(np.broadcast_shapes(a.shape, b.shape), dtype=np.result_type(a, b, float))
    out[..., 0] = a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1]
    out[..., 1] = a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2]
    out[..., 2] = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return out


def unit_axis(axis, name: str = "axis") -> NDArray:
    """A unit 3-vector from ``"x" | "y" | "z"`` (optionally signed, ``"-z"``) or a vector.

    Raises ``ValueError`` naming ``name`` for a zero, non-finite or mis-shaped axis.
    """
    if isinstance(axis, str):
        sign, key = (-1.0, axis[1:]) if axis.startswith("-") else (1.0, axis)
        if key not in _AXES:
            raise ValueError(f"{name}: unknown axis {axis!r}; use 'x', 'y', 'z' or a 3-vector")
        return sign * np.array(_AXES[key])
    e = np.asarray(axis, dtype=float)
    if e.shape != (3,):
        raise ValueError(f"{name}: expected a 3-vector, got shape {e.shape}")
    if not np.all(np.isfinite(e)):
        raise ValueError(f"{name}: axis has non-finite entries {e}")
    norm = np.linalg.norm(e)
    if norm < 1e-12:
        raise ValueError(f"{name}: zero axis {e} has no direction")
    return e / norm


def axis_spin(e) -> tuple[NDArray, NDArray]:
    """(ẽ, ẽ²) of a fixed unit axis e, formed once for :func:`rodrigues`."""
    E = skew(e)
    return E, E @ E


def rodrigues(spin: tuple[NDArray, NDArray], angle) -> NDArray:
    """Rodrigues' rotation R = E + sin φ ẽ + (1 − cos φ) ẽ² by the angle φ about the unit
    axis e whose ``spin = (ẽ, ẽ²)`` (:func:`axis_spin`): maps rotated-frame coordinates
    into the original frame (right-hand rule about e)."""
    E, E2 = spin
    return np.eye(3) + np.sin(angle) * E + (1.0 - np.cos(angle)) * E2


def rotation(e: NDArray, angle) -> NDArray:
    """Rotation by ``angle`` about the unit axis ``e``: :func:`rodrigues` with (ẽ, ẽ²) of e."""
    return rodrigues(axis_spin(e), angle)


def rotation_x(angle) -> NDArray:
    """Rotation by ``angle`` about the x-axis, R_x(φ) = rotation(e_x, φ)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_y(angle) -> NDArray:
    """Rotation by ``angle`` about the y-axis, R_y(φ) = rotation(e_y, φ)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rotation_z(angle) -> NDArray:
    """Rotation by ``angle`` about the z-axis, R_z(φ) = rotation(e_z, φ)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def quaternion_matrix(quat: NDArray) -> NDArray:
    """Rotation matrix of a unit quaternion (w, x, y, z), body → reference coordinates."""
    w, x, y, z = quat
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def quaternion_rate_matrix(quat: NDArray) -> NDArray:
    """The 4×3 matrix Γ with q̇ = Γ ω for ω in body coordinates (q̇ = ½ q ⊗ (0, ω))."""
    w, x, y, z = quat
    return 0.5 * np.array([[-x, -y, -z], [w, -z, y], [z, w, -x], [-y, x, w]])


def chain_matrix(A_np: NDArray, r_pn: NDArray) -> NDArray:
    """Rigid T_np = [[A_np, −A_np r̃_pn], [0, A_np]] (docs/theory.md §4), or a stack of them for
    stacks A_np (..., 3, 3) and r_pn (..., 3).

    ``r_pn`` is O_p → O_n in p-coordinates; ẏ_n = T_np ẏ_p is the twist of a frame n
    rigidly attached to p.
    """
    T = np.zeros(A_np.shape[:-2] + (6, 6), dtype=np.result_type(A_np, r_pn, float))
    T[..., :3, :3] = A_np
    T[..., 3:, 3:] = A_np
    T[..., :3, 3:] = -A_np @ skew_stack(r_pn)
    return T


def skew_stack(a: NDArray) -> NDArray:
    """Spin matrices of a stack of 3-vectors (..., 3) → (..., 3, 3)."""
    S = np.zeros(a.shape[:-1] + (3, 3), dtype=np.result_type(a, float))
    S[..., 0, 1], S[..., 0, 2], S[..., 1, 2] = -a[..., 2], a[..., 1], -a[..., 0]
    S[..., 1, 0], S[..., 2, 0], S[..., 2, 1] = a[..., 2], -a[..., 1], a[..., 0]
    return S


def cross_motion(u: NDArray, w: NDArray) -> NDArray:
    """Motion cross product u × w = (u_ω × w_v + u_v × w_ω, u_ω × w_ω) of two twists
    (row-wise for stacks of shape (..., 6)).

    With u = T_np ẏ_p and w the joint's relative twist, it is the part Ṫ_np ẏ_p of
    ζ_n that stems from the joint's rotation and translation (docs/theory.md §4).
    """
    u_v, u_w, w_v, w_w = u[..., :3], u[..., 3:], w[..., :3], w[..., 3:]
    return np.concatenate((cross(u_w, w_v) + cross(u_v, w_w), cross(u_w, w_w)), axis=-1)


def vee(W: NDArray) -> NDArray:
    """The 3-vector a of a spin matrix W = ã (its skew part, for nearly skew input)."""
    return 0.5 * np.array([W[2, 1] - W[1, 2], W[0, 2] - W[2, 0], W[1, 0] - W[0, 1]])

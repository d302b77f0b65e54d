"""Rolling without slipping on a plane: a disk (wheel) and a sphere, as non-holonomic joints
(docs/theory.md §2, §4, §7).

The plane is the x–y plane of the joint frame (normal z, pointing to the side of the body); the
child frame's origin is the body's centre, at the height R above the contact point C. Rolling
without slipping makes C's velocity zero, v = ω × R n (n: the plane's normal; the contact
constraints are not integrable). Following Bremer (2009) §2 and conclusions, the constraint goes
in *before* the equations are formed: the minimal velocities are ṡ = ω, the body's angular
velocity in child coordinates, and the twist per unit ṡ is F⁶ = [−R ñ_C; E₃] (ñ_C: the spin
matrix of n in child coordinates), so that v = F_v ω = ω × R n_C holds for every ṡ. The
coordinates follow from q̇ = K(q) ṡ, K not integrable. The plane may move (a turntable: the joint's
parent turning at a prescribed rate); ω and v are then relative to the parent.

Each joint reports the two contact constraints it satisfies (:meth:`RollingDisk.constraint_residual`),
so every simulated Result carries their residual.
"""

from __future__ import annotations

import numpy as np

from projeq.checks import positive
from projeq.joints.base import Joint
from projeq.joints.statement import Stated
from projeq.spatial import norm, numeric, quaternion_matrix


def _contact_twist(m, R, n):
    """F⁶ = [−R ñ; E₃] of a body of radius R rolling on a plane whose normal is n (child coordinates):
    v = ω × R n."""
    x, y, z = (R * entry for entry in n)
    return m.matrix([[0.0, z, -y], [-z, 0.0, x], [y, -x, 0.0],
                     [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


class _Rolling(Joint):
    """A body of radius R rolling without slip on the parent's x–y plane (the two contact-point
    velocity rows in F, q̇ = K(q) ṡ): what the rolling joints share."""

    n_c = 2

    def __init__(self, parent=None, radius=1.0, r_pn=(0.0, 0.0, 0.0), orientation=None):
        super().__init__(parent, r_pn, orientation)
        self.radius = positive("radius", radius)


class RollingDisk(_Rolling):
    """A thin disk (a wheel) of radius R rolling without slipping on the joint frame's x–y plane.

    Coordinates as Barhorst §3.2, eqs. (88)–(97) (the disk of :func:`projeq.scenes.rolling_disk`):
    q = (ψ, φ, θ, x, y): heading ψ about the normal z, tilt φ about the heading frame's x axis,
    roll θ about the disk's axis, and (x, y) the contact point; the child frame is
    A = R_z(ψ) R_x(φ) R_y(θ), its y axis the disk's axis, its origin the disk's centre,
    r = (x, y, 0) + R b₃ (b₃ = R_z(ψ) R_x(φ) e_z, the contact point → centre direction).
    ṡ = ω in child coordinates; F⁶ = [−R b̃₃; E₃] with b₃ = R_y(θ)ᵀ e_z in child coordinates, and
    q̇ = K(q) ω with the Euler-angle rates of eq. (95) and ẋ = R cos ψ θ̇, ẏ = R sin ψ θ̇ (eq. 97).

    The Euler angles are singular at φ = ±π/2, the disk flat on the plane (sec φ in K), where the
    rolling contact ends as well.

    Parameters
    ----------
    radius : float
        R, the disk's radius (m), positive.
    """

    n_q, n_s = 5, 3

    def statement(self, q, t, m):
        R = self.radius
        heading, tilt, roll = q[0], q[1], q[2]
        tilted = m.rotation([0.0, 0.0, 1.0], heading) @ m.rotation([1.0, 0.0, 0.0], tilt)
        c1, s1, c2, c3, s3 = m.cos(heading), m.sin(heading), m.cos(tilt), m.cos(roll), m.sin(roll)
        t2 = m.tan(tilt)
        angles = [[-s3 / c2, 0.0, c3 / c2], [c3, 0.0, s3], [s3 * t2, 1.0, -c3 * t2]]  # eq. (95)
        rolled = angles[2]  # θ̇ per unit ω
        K = m.matrix(angles + [[R * c1 * e for e in rolled], [R * s1 * e for e in rolled]])  # eq. (97)
        return Stated(A=tilted @ m.rotation([0.0, 1.0, 0.0], roll),
                      r=m.vector([q[3], q[4], 0.0]) + R * (tilted @ m.vector([0.0, 0.0, 1.0])),
                      F=_contact_twist(m, R, (-s3, 0.0, c3)), K=K)

    def constraint_residual(self, q_n, q_dot_n, t):
        """The contact point at rest: (ẋ − R cos ψ θ̇, ẏ − R sin ψ θ̇) (m/s)."""
        R, heading, roll_rate = self.radius, q_n[0], q_dot_n[2]
        return np.array([q_dot_n[3] - R * np.cos(heading) * roll_rate, q_dot_n[4] - R * np.sin(heading) * roll_rate])

    def coordinates(self):
        return (("heading", "rad"), ("tilt", "rad"), ("roll", "rad"), ("x", "m"), ("y", "m"))

    def velocities(self):  # ω of the disk in its own (child) coordinates
        return tuple((f"omega_{a}", "rad/s") for a in "xyz")


class RollingSphere(_Rolling):
    """A sphere (a ball) of radius R rolling without slipping on the joint frame's x–y plane.

    q = (x, y, w, q_x, q_y, q_z): the centre's (x, y), at the height R, and the unit quaternion of
    the ball's orientation (the quaternion is divided by its length wherever it is read, as in
    :class:`projeq.Spherical`); ṡ = ω in child (ball) coordinates. F⁶ = [−R ñ_C; E₃] with
    n_C = Aᵀ e_z, and q̇ = K(q) ω: (ẋ, ẏ) = R ((A ω)_y, −(A ω)_x) (ω × R e_z in the plane's
    coordinates) and the quaternion's q̇ = ½ q ⊗ (0, ω).

    Parameters
    ----------
    radius : float
        R, the sphere's radius (m), positive.
    """

    n_q, n_s = 6, 3

    def statement(self, q, t, m):
        R = self.radius
        length = m.sqrt(q[2] ** 2 + q[3] ** 2 + q[4] ** 2 + q[5] ** 2)
        w, x, y, z = (q[i] / length for i in range(2, 6))
        A = m.quaternion_matrix([w, x, y, z])
        rate = [[-x, -y, -z], [w, -z, y], [z, w, -x], [-y, x, w]]  # 2 Γ(q): quaternion_rate_matrix
        K = [[R * A[1, j] for j in range(3)], [-R * A[0, j] for j in range(3)]] + \
            [[entry / 2 for entry in row] for row in rate]
        return Stated(A=A, r=m.vector([q[0], q[1], R]), F=_contact_twist(m, R, [A[2, j] for j in range(3)]),
                      K=m.matrix(K))

    def constraint_residual(self, q_n, q_dot_n, t):
        """The contact point at rest: (ẋ, ẏ) − R ((A ω)_y, −(A ω)_x) (m/s), with ω = 4 Γ(q)ᵀ q̇ the
        inverse of q̇ = Γ(q) ω (Γᵀ Γ = E/4 for a unit quaternion)."""
        quat = q_n[2:] / norm(q_n[2:])
        w, x, y, z = quat
        omega = 2.0 * np.array([[-x, w, z, -y], [-y, -z, w, x], [-z, y, -x, w]]) @ q_dot_n[2:]
        spin = quaternion_matrix(quat) @ omega
        return np.array([q_dot_n[0] - self.radius * spin[1], q_dot_n[1] + self.radius * spin[0]])

    def coordinates(self):
        return (("x", "m"), ("y", "m")) + tuple((f"quat_{a}", "") for a in "wxyz")

    def velocities(self):  # ω of the ball in its own (child) coordinates
        return tuple((f"omega_{a}", "rad/s") for a in "xyz")

    def default_q(self):
        return np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])

    def normalized(self, q_n):
        """The quaternion divided by its length √(qᵀq) (analytic: a complex step passes)."""
        out = numeric(np.array(q_n))
        out[2:] /= norm(out[2:])
        return out

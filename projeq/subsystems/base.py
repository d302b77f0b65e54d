"""The subsystem interface: one term of the sum in B(14).

A subsystem n has describing velocities ẏ_n and contributes M_n ÿ_n + G_n ẏ_n − Q_n to
the Projection Equation. The assemblers only ever call the members below, so a new kind
of subsystem (an elastic beam, a user-defined one) plugs in without changing them.

Letters in this module: ``M`` is the subsystem mass matrix (never a torque), ``h`` is
h_n = Q_n − G_n ẏ_n.
"""

from __future__ import annotations

from typing import Protocol

from numpy.typing import NDArray


class Subsystem(Protocol):
    """Something that moves: the Gauss-form terms of one subsystem (B(13)–(14)).

    Attributes
    ----------
    n_y : int
        Number of describing velocities ẏ_n.
    S : ndarray of shape (n_y, 6), or None
        Selection of ẏ_n from the twist (v_O, ω) of the subsystem's reference frame R_n,
        ẏ_n = S · twist + [0; ṡ_e] (``None`` means ẏ_n *is* the twist). Joints act through
        it: F_n = [S F⁶, [0; E]], T_np = S T⁶_np Sₚᵀ (THEORY §4). Planar bodies select
        three rows; a subsystem with internal coordinates has zero rows for them.
    n_e : int, optional (default 0)
        Internal coordinates q_e (elastic coordinates of a beam, an absorber's travel),
        owned by the subsystem, with minimal velocities ṡ_e = q̇_e: the last n_e entries
        of ẏ_n. They follow the joint's coordinates in q and ṡ.
    """

    n_y: int
    S: NDArray | None

    def gauss_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray) -> tuple[NDArray, NDArray]:
        """Return (M_n, h_n), h_n = Q_n − G_n ẏ_n with gravity included in Q_n.

        ``R`` rotates the reference frame's coordinates into inertial ones; ``gravity`` is
        the gravitational acceleration in inertial coordinates; ``q_e`` the internal
        coordinates (empty for rigid bodies).
        """
        ...

    def kinetic_energy(self, y_dot: NDArray, q_e: NDArray) -> float:
        """½ ẏ_nᵀ M_n ẏ_n."""
        ...

    def potential_energy(self, R: NDArray, r: NDArray, gravity: NDArray, q_e: NDArray) -> float:
        """Potential of the subsystem (gravity, internal springs) with frame pose (R, r)."""
        ...

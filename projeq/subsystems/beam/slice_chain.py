"""An independent model of the beam spun about its own axis: a chain of rigid slices.

The beam of B(16)–(23) (H. Bremer, "Problems in fast moving non-holonomic elastic
systems") is cut into ``n_slices`` rigid slices of length Δx = L/N, each with its mass
ρA Δx at the centre line and its rotary inertia Δx ρI diag(2, 1, 1) (circular section).
Successive slices are joined by bending joints with springs EI/Δx and no twist: either
two revolute joints (about y, then z — a Cardan joint — or z, then y) or the rotation
that turns one slice's axis into the next one's by the shortest way (discrete parallel
transport). The root slice is joined the same way to the hub, which turns by the
prescribed α(t) about x. As N → ∞ every such chain tends to the beam without torsional
strain (κ_x = 0): the twist a joint adds is of second order in its (small) angles.

So that the chain can be compared with a Ritz model term by term, its joint angles are
not free: the slice axes follow the centre line (1, v′, w′) of the Ritz field
v = Φᵀ a_v, w = Φᵀ a_w with the clamped polynomials (x/L)^(k+1)
(``RitzBeam(family="polynomial")``). Its kinetic energy T(a, ȧ, α̇) is evaluated from the
rotation matrices of the slices (no small-angle formula; slice angular velocities by
complex-step differentiation of the matrices), its Lagrange equations are linearised
about a = 0 by exact derivatives (the complex step through 𝕄(a), whose own derivatives
then take the complex step inside a sixth-order stencil:
:func:`projeq.analysis.differentiation.derivative_along`, ``second_derivative_along``;
≈ 1e-15 relative, where differences left 1.4e-7 in K_c), giving the matrices of
:class:`projeq.symbolic.spinning_beam.RitzModel`:

    T = ½ uᵀ 𝕄(a) u, u = (ȧ, α̇):  M = 𝕄_aa(0),  C = ∂𝕄_aα/∂a (0),  G = C − Cᵀ,
    K_c = ½ ∂²𝕄_αα/∂a² (0),  K = Σ_joints (EI/Δx) ΔΦ′ ΔΦ′ᵀ (linear joint springs).

Discretisation error: O(Δx²) in M, G, K_c, C with the shortest-way joints, O(Δx) with
revolute pairs, O(Δx) in K (``benchmarks/spinning_beam_chain.py`` prints the numbers); the slices' own
ρA Δx³/12 about y and z is left out (it vanishes as Δx → 0).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import derivative_along, exact_jacobian, second_derivative_along
from projeq.checks import count, positive
from projeq.spatial import numeric, rotation_y, rotation_z, skew, vee
from projeq.subsystems.beam import shapes

JOINTS = ("shortest", "yz", "zy")
_E_X = np.array([1.0, 0.0, 0.0])
# step of the stencil around the complex step in ∂²𝕄_αα/∂a² (unit directions): 𝕄_αα holds
# 1/(1 + v′² + w′²) with |Φ′| up to n + 1, whose high derivatives are large; measured against
# the closed form at 20 slices: 8e-11 at 4e-3, 2e-14 at 1e-3, 7e-16 at 5e-4, 4e-16 at 2.5e-4
HESSIAN_STEP = 5e-4


def _shortest_rotation(u: NDArray, v: NDArray) -> NDArray:
    """The rotation turning unit vector u into v about u × v (no component about u or v)."""
    k = skew(np.cross(u, v))
    return np.eye(3) + k + k @ k / (1.0 + u @ v)


def _revolute_pair(d: NDArray, joint: str) -> NDArray:
    """Two revolute joints turning e_x into the unit vector d: about y then z (``"yz"``),
    or about z then y (``"zy"``); complex-safe."""
    if joint == "yz":
        return rotation_y(np.arctan(-d[2] / d[0])) @ rotation_z(np.arcsin(d[1]))
    return rotation_z(np.arctan(d[1] / d[0])) @ rotation_y(np.arcsin(-d[2]))


class SliceChain:
    """The chain of ``n_slices`` rigid slices following a Ritz field with ``n`` clamped
    polynomials per bending plane (coordinates a = (a_v, a_w)); see the module docstring."""

    def __init__(self, n_slices: int, n: int = 2, length: float = 1.0, rho_A: float = 1.0, rho_I: float = 0.01,
                 EI: float = 1.0, joint: str = "shortest"):
        if joint not in JOINTS:
            raise ValueError(f"joint: expected one of {JOINTS}, got {joint!r}")
        self.n_slices, self.n = count("n_slices", n_slices), count("n", n)
        self.length = positive("length", length)
        self.rho_A, self.rho_I, self.EI = positive("rho_A", rho_A), positive("rho_I", rho_I), positive("EI", EI)
        self.joint = joint
        dx = self.length / self.n_slices
        self.x = (np.arange(self.n_slices) + 0.5) * dx
        self.mass = rho_A * dx
        self.inertia = dx * rho_I * np.array([2.0, 1.0, 1.0])
        Phi, Phi_x = shapes.polynomial(self.n, self.length)(self.x)[:2]
        self.Phi, self.Phi_x = Phi, Phi_x
        # joint springs: the root joint (hub to slice 0, Δx/2) and the joints between slices
        rotation_jumps = np.diff(np.hstack((np.zeros((self.n, 1)), Phi_x)), axis=1)
        spans = np.r_[dx / 2, np.full(self.n_slices - 1, dx)]
        K_plane = (rotation_jumps * (EI / spans)) @ rotation_jumps.T
        self.K = np.kron(np.eye(2), K_plane)

    def _frames(self, a: NDArray) -> NDArray:
        """Slice frames B_i (slice → R coordinates) for the field a (real or complex), (N, 3, 3)."""
        tangents = np.stack([np.ones(self.n_slices, dtype=a.dtype), a[: self.n] @ self.Phi_x, a[self.n:] @ self.Phi_x], 1)
        tangents = tangents / np.sqrt((tangents**2).sum(axis=1))[:, None]
        B, previous, frames = np.eye(3, dtype=a.dtype), _E_X.astype(a.dtype), []
        for t in tangents:
            if self.joint == "shortest":
                B = _shortest_rotation(previous, t) @ B
            else:
                B = B @ _revolute_pair(B.T @ t, self.joint)
            frames.append(B)
            previous = t
        return np.array(frames)

    def inertia_matrix(self, a: NDArray) -> NDArray:
        """𝕄(a) of T = ½ uᵀ 𝕄 u with u = (ȧ, α̇): translation of the slice centres in the
        frame spinning with the hub, rotation of the slices from their matrices; complex-safe
        (a may carry a complex step)."""
        a = numeric(np.asarray(a))
        m = 2 * self.n
        frames = self._frames(a)
        # ∂ω_i/∂ȧ_k = vee(B_iᵀ ∂B_i/∂a_k) by complex step, ∂ω_i/∂α̇ = B_iᵀ e_x
        turned = [derivative_along(self._frames, a, e) for e in np.eye(m)]
        M = np.zeros((m + 1, m + 1), dtype=a.dtype)
        v = a[: self.n] @ self.Phi
        w = a[self.n:] @ self.Phi
        for i, B in enumerate(frames):
            J_omega = np.column_stack([vee(B.T @ turned[k][i]) for k in range(m)] + [B.T @ _E_X])
            J_r = np.zeros((3, m + 1), dtype=a.dtype)
            J_r[1, : self.n], J_r[2, self.n: m] = self.Phi[:, i], self.Phi[:, i]
            J_r[:, m] = np.cross(_E_X, [self.x[i], v[i], w[i]])
            M += self.mass * J_r.T @ J_r + J_omega.T @ (self.inertia[:, None] * J_omega)
        return M

    def spin_inertia(self, a: NDArray) -> float:
        """𝕄_αα(a) = Σ (m |e_x × r_i|² + (B_iᵀe_x)ᵀ I (B_iᵀe_x)): the chain's inertia about x
        (complex-safe)."""
        a = numeric(np.asarray(a))
        axes = np.array([B.T @ _E_X for B in self._frames(a)])
        distance2 = (a[: self.n] @ self.Phi) ** 2 + (a[self.n:] @ self.Phi) ** 2
        return self.mass * distance2.sum() + (axes**2 * self.inertia).sum()

    def linear_model(self):
        """The linearised Lagrange equations M ä + α̇ G ȧ + (K − α̇² K_c + α̈ C) a = 0 as a
        :class:`projeq.symbolic.spinning_beam.RitzModel` (see the module docstring)."""
        from projeq.symbolic.spinning_beam import RitzModel

        m, zero = 2 * self.n, np.zeros(2 * self.n)
        E = np.eye(m)
        M0 = self.inertia_matrix(zero)
        C = exact_jacobian(lambda a: self.inertia_matrix(a)[:m, m], zero)
        hessian = np.array([[second_derivative_along(self.spin_inertia, zero, ei, ej, HESSIAN_STEP) for ej in E]
                            for ei in E])
        return RitzModel(M=M0[:m, :m], G=C - C.T, K=self.K, K_c=hessian / 2, C=C)


def extrapolated_model(n_slices: int, **parameters):
    """Richardson extrapolation of the shortest-way chain (a ``RitzModel``).

    M, G, K_c and C converge as Δx² and are extrapolated from ``n_slices`` and 2 ``n_slices``;
    K converges as Δx + O(Δx²) (the rigid half slice at the tip has no spring: the joints
    miss its curvature energy) and is extrapolated twice, from N, 2N and 4N slices (K is
    cheap). Its error: compare the motions of ``extrapolated_model(N)`` and
    ``extrapolated_model(2N)`` (``benchmarks/spinning_beam_chain.py``)."""
    from projeq.symbolic.spinning_beam import RitzModel

    def richardson(fine, coarse, p):
        return (2**p * fine - coarse) / (2**p - 1)

    coarse = SliceChain(n_slices, joint="shortest", **parameters).linear_model()
    fine = SliceChain(2 * n_slices, joint="shortest", **parameters).linear_model()
    K1, K2, K4 = (SliceChain(k * n_slices, joint="shortest", **parameters).K for k in (1, 2, 4))
    model = RitzModel(*(richardson(f, c, 2) for f, c in zip(fine, coarse)))
    model = model._replace(K=richardson(richardson(K4, K2, 1), richardson(K2, K1, 1), 2))
    return model

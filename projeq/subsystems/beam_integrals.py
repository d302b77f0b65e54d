"""Precomputed shape integrals of a RitzBeam: M_n and h_n of B(25) for small deformations
without quadrature per call (THEORY §10, "a speed/accuracy knob").

The slice Jacobian J(x, q_e) = [E, −r̃(x), Φ_r(x)] is a polynomial in q_e (affine plus the
quadratic u₂), so J = J₀(x) + Σ_k q_k J₁ₖ(x) + O(q²) with J₁ₖ the exact central difference
of step 1. The slice acceleration not proportional to ÿ is

    c(x) = a + ω̃ω̃ r(x) + 2 ω̃ Φ_r(x) q̇_e − (q̇_vᵀH_v q̇_v + q̇_wᵀH_w q̇_w) e_x,  a = ω̃ v_R − g_R,

linear in the station fields r, Φ_r and H. With q_e and q̇_e of order ε (rigid motion of
order one) the integrals ∫J₀ᵀJ₀ dm, ∫J₁ₖᵀJ₀ dm, ∫J dm, ∫J_aᵀ r_b dm, ∫J₀_aᵀ Φ_r,b dm and
the stiffening integrals ∫J₀,xᵀ H dm are computed once, and M_n, h_n follow to first order
in ε (errors O(ε²); exact at q_e = 0 for any ẏ). The geometric stiffness is kept: it comes
from ∫J₁ᵀ ω̃ω̃ (x e_x) dm = −(ω_y² + ω_z²) ∫ x H dm q (THEORY §10, N = ρAΩ²(L² − x²)/2).
Rotary inertia and the stiffness stay with the beam (shared with the quadrature mode).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.spatial import cross, skew


class ShapeIntegrals:
    """The shape integrals of ``beam`` (a RitzBeam), by its quadrature, once."""

    def __init__(self, beam):
        m = beam.mass_weights
        zero = np.zeros(beam.n_e)
        r0, Phi0 = beam._slices(zero)
        J0 = beam._jacobian(r0, Phi0)
        J1 = np.array([self._linear_part(beam, unit) for unit in np.eye(beam.n_e)])
        n_y, n_e = beam.n_y, beam.n_e
        self.M0 = np.einsum("sai,saj,s->ij", J0, J0, m)
        M1 = np.einsum("ksai,saj,s->kij", J1, J0, m)
        self.M1 = (M1 + M1.transpose(0, 2, 1)).reshape(n_e, n_y * n_y)
        # ∫J dm (zero and first order), flattened for matrix products
        self.J_int = np.einsum("sai,s->ai", J0, m), np.einsum("ksai,s->kai", J1, m).reshape(n_e, 3 * n_y)
        # ∫J_aᵀ r_b dm, indices (ab, i)
        J_r1 = np.einsum("ksai,sb,s->kabi", J1, r0, m) + np.einsum("sai,sbk,s->kabi", J0, Phi0, m)
        self.J_r = np.einsum("sai,sb,s->abi", J0, r0, m).reshape(9, n_y), J_r1.reshape(n_e, 9 * n_y)
        self.J_Phi = np.einsum("sai,sbk,s->abik", J0, Phi0, m).reshape(9, n_y * n_e)  # ∫J₀_aᵀ Φ_r,b dm
        self.J_H = {key: np.einsum("si,sjk,s->ijk", J0[:, 0, :], beam.H[key], m) for key in ("v", "w")}
        self.beam = beam

    @staticmethod
    def _linear_part(beam, unit: NDArray) -> NDArray:
        """∂J/∂q_k at q = 0: central difference of step 1 (exact, J is quadratic in q)."""
        ahead, behind = beam._slices(unit), beam._slices(-unit)
        return 0.5 * (beam._jacobian(*ahead) - beam._jacobian(*behind))

    def terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray) -> tuple[NDArray, NDArray]:
        """(M_n, h_n) of the slices' translation to first order in (q_e, q̇_e)."""
        beam = self.beam
        v_R, omega, q_e_dot = y_dot[:3], y_dot[3:6], y_dot[6:]
        W = skew(omega)
        a = cross(omega, v_R) - R.T @ gravity
        n_y, n_e = beam.n_y, beam.n_e
        M = self.M0 + (q_e @ self.M1).reshape(n_y, n_y)
        h = -a @ (self.J_int[0] + (q_e @ self.J_int[1]).reshape(3, n_y))
        h -= (W @ W).ravel() @ (self.J_r[0] + (q_e @ self.J_r[1]).reshape(9, n_y))
        h -= 2.0 * ((W.ravel() @ self.J_Phi).reshape(n_y, n_e) @ q_e_dot)
        if beam.stiffening:
            for key, cols in (("v", beam.v_cols), ("w", beam.w_cols)):
                qd = q_e_dot[beam._local(cols)]
                h += self.J_H[key] @ qd @ qd
        return M, h

"""How a RitzBeam integrates the slices' translation terms of B(25), chosen once in its
constructor (``integration=``): :class:`Quadrature` sums them at the Gauss stations at every
call; :class:`PrecomputedIntegrals` assembles them from moments of the shape functions
computed once, exact for the beam's model (docs/theory.md §10, "a speed/accuracy knob").

Both are built with the beam, ``integration(beam)``, and answer ``terms(y_dot, R,
gravity, q_e)`` (M_n, h_n of the translation) and ``elastic_rows(...)`` (their last n_e
rows). Rotary inertia and the stiffness stay with the beam (shared by both).

**Quadrature.** With J(x) = [E, −r̃(x), Φ_r(x)] and the acceleration not proportional to ÿ,
c(x) = J̇ ẏ + ω̃ v_c − g_R = ω̃ ṙ + ω̃ v_c − (q̇_vᵀH_v q̇_v + q̇_wᵀH_w q̇_w) e_x − g_R,

    M_n = Σ_k m_k J(x_k)ᵀ J(x_k),   h_n = −Σ_k m_k J(x_k)ᵀ c(x_k)

over the stations x_k with masses m_k = w_k ρA(x_k).

**Precomputed integrals.** The slice position is a polynomial of degree two in the elastic coordinates,

    r(x, q) = R(x) z(q),   z = (1, q, q_v ⊗ q_v, q_w ⊗ q_w),

with the columns of R: x e_x, the Ritz functions Ψ(x) = Φ_r(x, 0), and −½ H_ij(x) e_x for
the products q_i q_j of the second-order axial field u₂ = −½ (q_vᵀH_v q_v + q_wᵀH_w q_w).
Then Φ_r = ∂r/∂q = R Z with Z = ∂z/∂q, ṙ = R Z q̇, the part of r̈ not proportional to q̈
is R Ż q̇ (the stiffening term −(q̇ᵀH q̇) e_x), and every integral of B(25) is bilinear in
the station fields, so with the moments

    G_ab = ∫ R_aᵀ R_b dm  (rows a, b of R; n_z × n_z),   R̄ = ∫ R dm,   m = ∫ dm,

computed once by the beam's quadrature, J = [E, −r̃, Φ_r] and the acceleration
c = a + ω̃ω̃ r + 2 ω̃ ṙ + R Ż q̇ (a = ω̃ v_R − g_R) give

    ∫ r dm = R̄ z,   ∫ r_a r_b dm = zᵀ G_ab z,   ∫ r_a Φ_r,b dm = zᵀ G_ab Z,
    ∫ Φ_rᵀ Φ_r dm = Zᵀ (Σ_a G_aa) Z,   ∫ Φ_r,aᵀ ṙ_b dm = Zᵀ G_ab Z q̇,

and M_n = ∫ Jᵀ J dm, h_n = −∫ Jᵀ c dm follow from them without approximation: equal to
the quadrature mode to round-off, for any deformation (tests/subsystems/test_beam_integrals.py).
The cost per call is O(n_z²) with n_z = 1 + n_e + n_v² + n_w², independent of the number
of stations.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.spatial import cross, skew, vee


class Quadrature:
    """The translation terms of ``beam`` (a RitzBeam) by its Gauss quadrature at every call
    (module docstring); the default."""

    def __init__(self, beam):
        self.beam = beam
        self._v, self._w = (slice(cols.start - 6, cols.stop - 6) for cols in (beam.v_cols, beam.w_cols))

    def terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray) -> tuple[NDArray, NDArray]:
        """(M_n, h_n) of the slices' translation, B(25): Σ m_k Jᵀ J and −Σ m_k Jᵀ c."""
        beam = self.beam
        r, Phi_r = beam.slices(q_e)
        J = beam.jacobian(r, Phi_r)
        v_R, omega, q_e_dot = y_dot[:3], y_dot[3:6], y_dot[6:]
        r_dot = Phi_r @ q_e_dot
        v_c = v_R + cross(omega, r) + r_dot
        c = cross(omega, r_dot) + cross(omega, v_c) - R.T @ gravity  # J̇ẏ + ω̃ v_c − g
        if beam.stiffening:
            qd_v, qd_w = q_e_dot[self._v], q_e_dot[self._w]
            c[:, 0] -= (beam.H["v"] @ qd_v) @ qd_v + (beam.H["w"] @ qd_w) @ qd_w  # d/dt(∂u₂/∂q) q̇
        J_flat = (J * np.sqrt(beam.mass_weights)[:, None, None]).reshape(-1, beam.n_y)
        M = J_flat.T @ J_flat
        h = -J.reshape(-1, beam.n_y).T @ (c * beam.mass_weights[:, None]).ravel()
        return M, h

    def elastic_rows(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray) -> tuple[NDArray, NDArray]:
        """The last n_e rows of :meth:`terms` (by quadrature they cost as much as all rows)."""
        M, h = self.terms(y_dot, R, gravity, q_e)
        return M[6:], h[6:]


class PrecomputedIntegrals:
    """The translation terms of ``beam`` (a RitzBeam) from its moments G_ab, R̄, m, computed
    once by its quadrature (module docstring)."""

    def __init__(self, beam):
        self.beam = beam
        n_e = beam.n_e
        # bending planes carrying u₂: positions in q_e and their H(x) at the stations
        self.planes = [
            (np.arange(cols.start - 6, cols.stop - 6), beam.H[key])
            for key, cols in (("v", beam.v_cols), ("w", beam.w_cols))
            if beam.stiffening and cols.stop > cols.start
        ]
        quadratic = [-0.5 * H.reshape(len(beam.x), -1) for _, H in self.planes]
        self.n_z = 1 + n_e + sum(block.shape[1] for block in quadratic)
        R = np.zeros((len(beam.x), 3, self.n_z))
        R[:, 0, 0] = beam.x
        R[:, :, 1 : 1 + n_e] = beam.slices(np.zeros(n_e))[1]  # Ψ(x) = Φ_r(x, 0)
        if quadratic:
            R[:, 0, 1 + n_e :] = np.hstack(quadratic)
        m = beam.mass_weights
        self.mass = float(m.sum())
        self.R_bar = np.einsum("sak,s->ak", R, m)
        self.G = np.einsum("sak,sbl,s->abkl", R, R, m)
        self.G_trace = np.einsum("aakl->kl", self.G)
        self._G_rows = self.G.reshape(9 * self.n_z, self.n_z)  # for one matrix–vector product
        # the products q_i q_j in z (row-major within each plane), and ∂(q_i q_j)/∂q_l =
        # δ_il q_j + q_i δ_jl as a constant tensor D with Z_quadratic = D q
        pairs = [(i, j) for cols, _ in self.planes for i in cols for j in cols]
        self._i, self._j = (np.array([p[k] for p in pairs], dtype=int) for k in (0, 1))
        E = np.eye(n_e)
        self._D = E[self._i][:, :, None] * E[self._j][:, None, :] + E[self._j][:, :, None] * E[self._i][:, None, :]
        self._Z_linear = np.vstack((np.zeros((1, n_e)), E))

    def monomials(self, q_e: NDArray, q_e_dot: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """z(q), Z = ∂z/∂q and Ż q̇ (whose only non-zero entries are 2 q̇_i q̇_j)."""
        z = np.concatenate(((1.0,), q_e, q_e[self._i] * q_e[self._j]))
        Z = np.vstack((self._Z_linear, self._D @ q_e))
        z_dd = np.concatenate((np.zeros(1 + len(q_e)), 2.0 * q_e_dot[self._i] * q_e_dot[self._j]))
        return z, Z, z_dd

    def _moments(self, q_e: NDArray, q_e_dot: NDArray, omega: NDArray, a: NDArray) -> dict:
        """The integrals shared by all rows: ∫ r dm, ∫ Φ_r dm, ∫ R_aᵀ r_b dm, Y_ab = ∫ r_a Φ_r,b dm,
        and the elastic rows M_e = ∫ Φ_rᵀ J dm, −h_e = ∫ Φ_rᵀ c dm (c of the module docstring)."""
        z, Z, z_dd = self.monomials(q_e, q_e_dot)
        n_z, n_e = self.n_z, len(q_e)
        W = skew(omega)
        WW = W @ W
        Gz = (self._G_rows @ z).reshape(3, 3, n_z)  # Gz[a, b] = ∫ R_aᵀ r_b dm
        Y = np.swapaxes(Gz @ Z, 0, 1)  # Y[a, b] = ∫ r_a Φ_r,b dm
        r_bar, Phi_bar = self.R_bar @ z, self.R_bar @ Z
        M_e = np.empty((n_e, 6 + n_e), dtype=np.result_type(Z, Y))  # complex in a complex step
        M_e[:, :3] = Phi_bar.T
        M_e[:, 3:6] = -2.0 * vee(Y).T  # (∫ r̃ Φ_r dm)ᵀ: −2 vee(C) = Σ_bc ε_abc C_bc, C = ∫ r xᵀ dm
        M_e[:, 6:] = Z.T @ self.G_trace @ Z
        Phi_c = (  # ∫ Φ_rᵀ c dm
            Phi_bar.T @ a
            + np.einsum("ab,bai->i", WW, Y)
            + 2.0 * Z.T @ (W.ravel() @ (self._G_rows @ (Z @ q_e_dot)).reshape(9, n_z))
            + Z.T @ (self.G_trace @ z_dd)
        )
        return {"z": z, "z_dd": z_dd, "W": W, "WW": WW, "Gz": Gz, "Y": Y, "r_bar": r_bar, "Phi_bar": Phi_bar,
                "M_e": M_e, "h_e": -Phi_c}

    def elastic_rows(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray) -> tuple[NDArray, NDArray]:
        """The last n_e rows of (M_n, h_n) of the slices' translation: all a beam on a
        prescribed hub needs (:mod:`projeq.assembly.beam_fast`)."""
        omega = y_dot[3:6]
        moments = self._moments(q_e, y_dot[6:], omega, cross(omega, y_dot[:3]) - R.T @ gravity)
        return moments["M_e"], moments["h_e"]

    def terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray) -> tuple[NDArray, NDArray]:
        """(M_n, h_n) of the slices' translation, B(25), from the moments (module docstring)."""
        v_R, omega, q_e_dot = y_dot[:3], y_dot[3:6], y_dot[6:]
        a = cross(omega, v_R) - R.T @ gravity
        k = self._moments(q_e, q_e_dot, omega, a)
        W, WW, Gz, Y, r_bar, Phi_bar = k["W"], k["WW"], k["Gz"], k["Y"], k["r_bar"], k["Phi_bar"]
        S = Gz @ k["z"]  # ∫ r rᵀ dm
        M = np.empty((6 + len(q_e), 6 + len(q_e)), dtype=np.result_type(S, Y, k["M_e"]))
        M[:3, :3] = self.mass * np.eye(3)
        M[:3, 3:6] = -skew(r_bar)
        M[3:6, :3] = skew(r_bar)
        M[3:6, 3:6] = (S[0, 0] + S[1, 1] + S[2, 2]) * np.eye(3) - S
        M[6:] = k["M_e"]
        M[:6, 6:] = k["M_e"][:, :6].T
        c_int = self.mass * a + WW @ r_bar + 2.0 * W @ (Phi_bar @ q_e_dot) + self.R_bar @ k["z_dd"]  # ∫ c dm
        r_c = np.outer(r_bar, a) + S @ WW.T + 2.0 * (Y @ q_e_dot) @ W.T + (Gz @ k["z_dd"]).T  # ∫ r cᵀ dm
        return M, np.concatenate((-c_int, 2.0 * vee(r_c), k["h_e"]))

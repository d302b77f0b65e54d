"""An Euler–Bernoulli beam by a direct Ritz approach (B(19)–(25), THEORY §10).

The beam hangs in a floating reference frame R (its root, axis x) with describing
velocities ẏ = (v_R, ω_R, q̇_e). A slice at x sits at r(x) = (x + u + u₂, v, w) with
u = Φ_uᵀ q_u, v = Φ_vᵀ q_v, w = Φ_wᵀ q_w and, when ``stiffening`` is on, the second-order
axial displacement u₂(x) = −½ ∫₀ˣ (v′² + w′²) dξ = −½ (q_vᵀ H_v(x) q_v + q_wᵀ H_w(x) q_w),
H(x) = ∫₀ˣ Φ′Φ′ᵀ dξ. Its velocity is v_c(x) = J(x) ẏ with J = [E, −r̃(x), Φ_r(x, q_e)], and
the Projection Equation B(19)–(25) for the slices gives

    M_n = ∫ Jᵀ J dm,   h_n = −∫ Jᵀ (ω̃ ṙ + ω̃ v_c − (q̇_vᵀH_v q̇_v + q̇_wᵀH_w q̇_w) e_x − g_R) dm − K_e q_e

(the bracket is J̇ ẏ + ω̃ v_c − g, the acceleration not proportional to ÿ), plus the rotary
inertia of the slices (Rayleigh) with ω_c = ω + Φ_θᵀ q̇_e, Φ_θ = (0, −Φ_w′, Φ_v′). Because
u₂ is part of the kinematics, the projection of the slices' axial inertia loads on
∂u₂/∂q gives the geometric stiffness ∫ N(x) Φ′Φ′ᵀ dx with N(x) = ∫ₓᴸ f_x: dynamic
stiffening from spin, angular and frame acceleration and gravity alike, and the model
stays conservative (tests/subsystems/test_beam.py checks energy). Integrals by
Gauss–Legendre quadrature at stations fixed at construction.

Letters: ``K_e`` is the stiffness matrix (``K`` is kept for q̇ = K ṡ).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.checks import non_negative, positive
from projeq.joints import Relative
from projeq.spatial import cross, skew_stack
from projeq.subsystems import shapes


def _per_length(name: str, value, x: NDArray, allow_zero: bool = False) -> NDArray:
    """A per-length property (constant or function of x) at the stations, checked."""
    values = np.asarray(value(x) if callable(value) else np.full_like(x, float(value)), dtype=float)
    if values.shape != x.shape or not np.all(np.isfinite(values)):
        raise ValueError(f"{name}: must give a finite value at each station x")
    if np.any(values < 0) or (not allow_zero and np.any(values <= 0)):
        raise ValueError(f"{name}: must be positive along the beam, got min {values.min():.3g}")
    return values


def _family(name: str, family, table: dict, n: int, L: float):
    if n == 0:
        return None
    if callable(family):
        return family(n, L)
    if family not in table:
        raise ValueError(f"{name}: unknown Ritz family {family!r}; use one of {sorted(table)} or a callable")
    return table[family](n, L)


class RitzBeam:
    """A beam subsystem: Euler–Bernoulli bending in two planes, optional axial deformation
    and rotary inertia, dynamic stiffening, stiffness-proportional damping.

    Parameters
    ----------
    length : float
        L in m; the beam runs along the reference frame's x axis from its origin.
    rho_A : float or callable
        Mass per length ρA (kg/m), constant or a function of x.
    EI_z, EI_y : float or callable
        Bending stiffness for v (x–y plane) and w (x–z plane), N m²; EI_y defaults to EI_z.
    EA : float or callable, optional
        Axial stiffness (N), needed when ``n_u > 0``.
    rho_I : (float, float), optional
        Rotary inertia per length (ρI_y, ρI_z) in kg m; polar ρ(I_y + I_z). None: none.
    n_v, n_w, n_u : int
        Number of Ritz functions for v, w and u (the accuracy knob).
    family : "polynomial", "clamped_free" or a callable ``(n, L) -> shapes``
        Bending family (clamped root); the axial family is chosen alike.
    quadrature_order : int, optional
        Gauss points along the beam (default 2·max(n) + 6).
    stiffening : bool
        Include u₂ (dynamic stiffening); default True.
    damping : float
        β of the stiffness-proportional damping force −β K_e q̇_e (s).
    """

    def __init__(
        self,
        length: float,
        rho_A,
        EI_z,
        EI_y=None,
        EA=None,
        rho_I=None,
        n_v: int = 4,
        n_w: int = 4,
        n_u: int = 0,
        family="polynomial",
        quadrature_order: int | None = None,
        stiffening: bool = True,
        damping: float = 0.0,
    ):
        self.length = L = positive("length", length)
        for name, n in (("n_v", n_v), ("n_w", n_w), ("n_u", n_u)):
            if int(n) != n or n < 0:
                raise ValueError(f"{name}: number of Ritz functions must be a non-negative integer, got {n!r}")
        self.n_u, self.n_v, self.n_w = int(n_u), int(n_v), int(n_w)
        self.n_e = self.n_u + self.n_v + self.n_w
        if self.n_e == 0:
            raise ValueError("n_v, n_w, n_u: a beam needs at least one Ritz function")
        if self.n_u and EA is None:
            raise ValueError("EA: axial deformation (n_u > 0) needs the axial stiffness EA")
        self.n_y = 6 + self.n_e
        self.S = np.vstack((np.eye(6), np.zeros((self.n_e, 6))))
        self.stiffening = bool(stiffening)
        self.damping = non_negative("damping", damping)
        self.order = order = int(quadrature_order or 2 * max(self.n_u, self.n_v, self.n_w) + 6)
        if order < 1:
            raise ValueError(f"quadrature_order: must be at least 1, got {quadrature_order}")
        t, w = np.polynomial.legendre.leggauss(order)
        self.x = x = 0.5 * L * (t + 1.0)
        self.weights = 0.5 * L * w
        self.mass_weights = self.weights * _per_length("rho_A", rho_A, x)
        self._shapes(family, L)
        self._EI = {"z": EI_z, "y": EI_y if EI_y is not None else EI_z}
        self._stiffness(EI_z, self._EI["y"], EA)
        self._rotary(rho_I)
        self._check_independent()
        self._ports: dict = {}  # station data of joints attached to the beam, by station
        self._warned = False  # the unstiffened-spin warning is given once per beam
        self.first_frequency = self._first_frequency()

    # -- precomputation ------------------------------------------------------------------
    def _shapes(self, family, L) -> None:
        """The families, their clamped-root check, and Φ, Φ′, Φ″, H at the stations."""
        self.u_cols = slice(6, 6 + self.n_u)
        self.v_cols = slice(6 + self.n_u, 6 + self.n_u + self.n_v)
        self.w_cols = slice(6 + self.n_u + self.n_v, self.n_y)
        self.families = {}
        for key, n, table, conditions in (
            ("u", self.n_u, shapes.AXIAL, (0,)),
            ("v", self.n_v, shapes.BENDING, (0, 1)),
            ("w", self.n_w, shapes.BENDING, (0, 1)),
        ):
            self.families[key] = fam = _family("family", family, table, n, L)
            if fam is None:
                continue
            at_root = fam(np.zeros(1))
            for derivative in conditions:
                bad = np.flatnonzero(np.abs(at_root[derivative][:, 0]) > 1e-12)
                if bad.size:
                    what = "Φ(0)" if derivative == 0 else "Φ′(0)"
                    raise ValueError(
                        f"family: Ritz functions {bad.tolist()} for {key} violate the clamped root ({what} ≠ 0)"
                    )
        self.Phi, self.H = self.station_data(self.x)

    def station_data(self, x: NDArray) -> tuple[dict, dict]:
        """Φ, Φ′, Φ″ of u, v, w at stations x, and H(x) = ∫₀ˣ Φ′Φ′ᵀ dξ of v and w
        (by Gauss quadrature of the beam's order on [0, x])."""
        sizes = {"u": self.n_u, "v": self.n_v, "w": self.n_w}
        Phi = {
            key: tuple(np.asarray(p, dtype=float) for p in fam(x)) if fam else tuple(np.zeros((0, len(x))) for _ in range(3))
            for key, fam in self.families.items()
        }
        t, w = np.polynomial.legendre.leggauss(self.order)
        xi = 0.5 * x[:, None] * (t[None, :] + 1.0)  # quadrature points in [0, x]
        H = {}
        for key in ("v", "w"):
            n, fam = sizes[key], self.families[key]
            if fam is None:
                H[key] = np.zeros((len(x), 0, 0))
                continue
            d1 = np.asarray(fam(xi.ravel())[1]).reshape(n, len(x), len(t))
            H[key] = np.einsum("igk,jgk,gk->gij", d1, d1, 0.5 * x[:, None] * w[None, :])
        return Phi, H

    def _stiffness(self, EI_z, EI_y, EA) -> None:
        """K_e = ∫ (EA Φ_u′Φ_u′ᵀ + EI_z Φ_v″Φ_v″ᵀ + EI_y Φ_w″Φ_w″ᵀ) dx (block diagonal)."""
        self.K_e = np.zeros((self.n_e, self.n_e))
        blocks = (("u", 1, EA, "EA", self.u_cols), ("v", 2, EI_z, "EI_z", self.v_cols), ("w", 2, EI_y, "EI_y", self.w_cols))
        for key, derivative, stiffness, name, cols in blocks:
            if cols.stop == cols.start:
                continue
            D = self.Phi[key][derivative]
            k = self.weights * _per_length(name, stiffness, self.x)
            sl = slice(cols.start - 6, cols.stop - 6)
            self.K_e[sl, sl] = (D * k) @ D.T

    def _rotary(self, rho_I) -> None:
        """Rotary inertia per station diag(ρ(I_y + I_z), ρI_y, ρI_z) and J_ω(x) = [0, E, Φ_θ]."""
        if rho_I is None:
            self.rotary = None
            return
        rho_I = np.broadcast_to(np.asarray(rho_I, dtype=float), (2,))
        I_y, I_z = (positive(f"rho_I[{i}]", v) for i, v in enumerate(rho_I))
        self.rotary = self.weights[:, None] * np.array([I_y + I_z, I_y, I_z])[None, :]
        J = np.zeros((len(self.x), 3, self.n_y))
        J[:, :, 3:6] = np.eye(3)
        J[:, 1, self.w_cols] = -self.Phi["w"][1].T  # rotation about y: −w′
        J[:, 2, self.v_cols] = self.Phi["v"][1].T  # rotation about z: +v′
        self.J_omega = J

    def _check_independent(self) -> None:
        gram = np.zeros((self.n_e, self.n_e))
        for key, cols in (("u", self.u_cols), ("v", self.v_cols), ("w", self.w_cols)):
            P, sl = self.Phi[key][0], slice(cols.start - 6, cols.stop - 6)
            gram[sl, sl] = (P * self.weights) @ P.T
        eigenvalues, vectors = np.linalg.eigh(gram)
        if eigenvalues[0] <= 1e-14 * eigenvalues[-1]:  # numerically singular (monomials up to x¹³ pass)
            involved = np.flatnonzero(np.abs(vectors[:, 0]) > 1e-3).tolist()
            raise ValueError(
                f"family: the Ritz functions {involved} are linearly dependent to machine precision "
                "(singular mass matrix); for many functions use family='clamped_free'"
            )

    def _first_frequency(self) -> float:
        """Lowest bending frequency of the clamped beam at rest (rad/s), from M_ee and K_e."""
        from scipy.linalg import eigh

        M, _ = self.gauss_terms(np.zeros(self.n_y), np.eye(3), np.zeros(3), np.zeros(self.n_e))
        return float(np.sqrt(max(eigh(self.K_e, M[6:, 6:], eigvals_only=True)[0], 0.0)))

    def _warn_unstiffened_spin(self, omega: NDArray) -> None:
        """Without stiffening a spin about an axis across the beam faster than its first
        bending frequency makes the model unstable (ω_lag² = ω₁² − Ω² < 0): allowed, but
        said once."""
        spin = float(np.hypot(omega[1], omega[2]))
        if spin > self.first_frequency:
            import warnings

            self._warned = True
            warnings.warn(
                f"RitzBeam without stiffening spins at {spin:.3g} rad/s, above its first bending "
                f"frequency {self.first_frequency:.3g} rad/s: the unstiffened model is unstable there "
                "(use stiffening=True)",
                RuntimeWarning,
                stacklevel=2,
            )

    # -- slice kinematics ------------------------------------------------------------------
    def _slices(self, q_e: NDArray, x: NDArray | None = None, data=None):
        """r(x) and Φ_r(x, q_e) at the quadrature stations (or at ``x`` with its
        ``station_data``)."""
        x, (Phi, H) = (self.x, (self.Phi, self.H)) if x is None else (x, data)
        e = lambda cols: slice(cols.start - 6, cols.stop - 6)  # noqa: E731  (columns within q_e)
        q_u, q_v, q_w = q_e[e(self.u_cols)], q_e[e(self.v_cols)], q_e[e(self.w_cols)]
        dtype = np.result_type(q_e, float)  # complex for the complex-step derivative of ports
        r = np.zeros((len(x), 3), dtype=dtype)
        r[:, 0] = x + q_u @ Phi["u"][0]
        r[:, 1] = q_v @ Phi["v"][0]
        r[:, 2] = q_w @ Phi["w"][0]
        Phi_r = np.zeros((len(x), 3, self.n_e), dtype=dtype)
        Phi_r[:, 0, e(self.u_cols)] = Phi["u"][0].T
        Phi_r[:, 1, e(self.v_cols)] = Phi["v"][0].T
        Phi_r[:, 2, e(self.w_cols)] = Phi["w"][0].T
        if self.stiffening:
            Hq_v, Hq_w = H["v"] @ q_v, H["w"] @ q_w
            r[:, 0] -= 0.5 * (Hq_v @ q_v + Hq_w @ q_w)  # u₂
            Phi_r[:, 0, e(self.v_cols)] = -Hq_v  # ∂u₂/∂q_v
            Phi_r[:, 0, e(self.w_cols)] = -Hq_w
        return r, Phi_r

    def _jacobian(self, r: NDArray, Phi_r: NDArray) -> NDArray:
        """J(x) = [E, −r̃(x), Φ_r(x)], stacked over the stations."""
        J = np.empty((len(r), 3, self.n_y))
        J[:, :, :3] = np.eye(3)
        J[:, :, 3:6] = -skew_stack(r)
        J[:, :, 6:] = Phi_r
        return J

    # -- the subsystem interface -------------------------------------------------------------
    def gauss_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray):
        """(M_n, h_n) of B(25) by quadrature (see the module docstring)."""
        r, Phi_r = self._slices(q_e)
        J = self._jacobian(r, Phi_r)
        v_R, omega, q_e_dot = y_dot[:3], y_dot[3:6], y_dot[6:]
        if not (self.stiffening or self._warned) and hasattr(self, "first_frequency"):
            self._warn_unstiffened_spin(omega)
        r_dot = Phi_r @ q_e_dot
        v_c = v_R + cross(omega, r) + r_dot
        c = cross(omega, r_dot) + cross(omega, v_c) - R.T @ gravity  # J̇ẏ + ω̃ v_c − g
        if self.stiffening:
            qd_v, qd_w = q_e_dot[self.v_cols.start - 6 : self.v_cols.stop - 6], q_e_dot[self.w_cols.start - 6 : self.w_cols.stop - 6]
            c[:, 0] -= (self.H["v"] @ qd_v) @ qd_v + (self.H["w"] @ qd_w) @ qd_w  # d/dt(∂u₂/∂q) q̇
        J_flat = (J * np.sqrt(self.mass_weights)[:, None, None]).reshape(-1, self.n_y)
        M = J_flat.T @ J_flat
        h = -J.reshape(-1, self.n_y).T @ (c * self.mass_weights[:, None]).ravel()
        if self.rotary is not None:
            Jw = self.J_omega
            Jw_flat = (Jw * np.sqrt(self.rotary)[:, :, None]).reshape(-1, self.n_y)
            M += Jw_flat.T @ Jw_flat
            omega_c = Jw @ y_dot
            h -= Jw.reshape(-1, self.n_y).T @ cross(omega, self.rotary * omega_c).ravel()
        h[6:] -= self.K_e @ (q_e + self.damping * q_e_dot)
        return M, h

    def kinetic_energy(self, y_dot: NDArray, q_e: NDArray) -> float:
        """½ ẏᵀ M ẏ (exact for the slice kinematics)."""
        M, _ = self.gauss_terms(y_dot, np.eye(3), np.zeros(3), q_e)
        return 0.5 * float(y_dot @ M @ y_dot)

    def potential_energy(self, R: NDArray, r: NDArray, gravity: NDArray, q_e: NDArray) -> float:
        """Gravity −∫ g·r_slice dm plus the strain energy ½ q_eᵀ K_e q_e."""
        r_x, _ = self._slices(q_e)
        return float(-self.mass_weights @ (r_x @ R.T + r) @ gravity + 0.5 * q_e @ self.K_e @ q_e)

    def port(self, point: NDArray, q_e: NDArray, q_e_dot: NDArray) -> Relative:
        """Kinematics of a frame attached at ``point`` of the undeformed beam (station
        x = point[0], cross-section offset c = (0, point[1], point[2])), relative to the
        beam's reference frame, as a joint would give them (THEORY §10, last line):

        pose A = R_z(v′) R_y(−w′) (Bremer's Cardan sequence, B(17)), r = r(x) + A c;
        relative twist F q̇_e in port coordinates with F = [[Aᵀ Φ_r − c̃ Φ_ω], [Φ_ω]],
        Φ_ω q̇_e = v̇′ (−sin(−w′), 0, cos(−w′)) − ẇ′ e_y; and Ḟ q̇_e by complex step.
        """
        x = float(point[0])
        if not 0.0 <= x <= self.length:
            raise ValueError(f"r_pn: a joint on a beam must sit at a station 0 ≤ x ≤ {self.length}, got x = {x}")
        offset = np.array([0.0, point[1], point[2]])
        data = self._port_data(x)
        A, r, F = self._port_terms(q_e, data, offset)
        step = 1e-30
        F_dot = np.imag(self._port_terms(q_e + 1j * step * q_e_dot, data, offset)[2]) / step
        return Relative(A, r, F, F @ q_e_dot, F_dot @ q_e_dot)

    def _port_data(self, x: float):
        """Station data at x, kept per station (ports sit at fixed stations)."""
        if x not in self._ports:
            self._ports[x] = (np.array([x]), self.station_data(np.array([x])))
        return self._ports[x]

    def _port_terms(self, q_e, data, offset):
        """(A, r, F) of a port; complex-safe, for the complex-step Ḟ."""
        x, (Phi, H) = data
        r_x, Phi_r = self._slices(q_e, x, (Phi, H))
        e = lambda cols: slice(cols.start - 6, cols.stop - 6)  # noqa: E731
        a = Phi["v"][1][:, 0] @ q_e[e(self.v_cols)]  # v′
        b = -(Phi["w"][1][:, 0] @ q_e[e(self.w_cols)])  # −w′
        ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
        R_z = np.array([[ca, -sa, 0 * ca], [sa, ca, 0 * ca], [0 * ca, 0 * ca, 1 + 0 * ca]])
        R_y = np.array([[cb, 0 * cb, sb], [0 * cb, 1 + 0 * cb, 0 * cb], [-sb, 0 * cb, cb]])
        A = R_z @ R_y
        Phi_omega = np.zeros((3, self.n_e), dtype=A.dtype)
        Phi_omega[0, e(self.v_cols)] = -sb * Phi["v"][1][:, 0]
        Phi_omega[2, e(self.v_cols)] = cb * Phi["v"][1][:, 0]
        Phi_omega[1, e(self.w_cols)] = -Phi["w"][1][:, 0]
        C = np.array([[0, -offset[2], offset[1]], [offset[2], 0, -offset[0]], [-offset[1], offset[0], 0]])
        F = np.vstack((A.T @ Phi_r[0] - C @ Phi_omega, Phi_omega))
        return A, r_x[0] + A @ offset, F

    def displacement(self, q_e, x) -> NDArray:
        """(u + u₂, v, w) at stations x in the beam's reference frame: for one q_e a
        (len(x), 3) array, for a trajectory of q_e (rows) a (n_t, len(x), 3) array."""
        x = np.atleast_1d(np.asarray(x, dtype=float))
        if np.any(x < 0) or np.any(x > self.length):
            raise ValueError(f"x: stations must lie on the beam, 0 ≤ x ≤ {self.length}")
        data = self.station_data(x)
        q_e = np.asarray(q_e, dtype=float)
        rows = [self._slices(q, x, data)[0] - np.outer(x, (1.0, 0.0, 0.0)) for q in np.atleast_2d(q_e)]
        return np.array(rows) if q_e.ndim == 2 else rows[0]

    def centre_line(self, q_e: NDArray, y_dot: NDArray, stations: int = 21) -> tuple[NDArray, NDArray]:
        """Positions r(x) and velocities J(x) ẏ of ``stations`` equally spaced points of the
        centre line, in the beam's reference frame (for drawing and export)."""
        x = np.linspace(0.0, self.length, int(stations))
        r, Phi_r = self._slices(q_e, x, self.station_data(x))
        return r, self._jacobian(r, Phi_r) @ y_dot

    def _coordinates(self, result) -> NDArray:
        """This beam's q_e along a trajectory (rows), found in ``result.system``."""
        system = getattr(result, "system", None)
        if system is None:
            raise ValueError("result: has no system (loaded from a file?); probe a Result from simulate()")
        places = [n for n, sub in enumerate(system.subsystems) if sub is self]
        if len(places) != 1:
            raise ValueError(f"result: this beam appears {len(places)} times in the system; probe it by q_e")
        return result.q[:, system.e_q_slice[places[0]]]

    def deflection(self, result, x: float) -> NDArray:
        """(u, v, w) at station x in the beam's reference frame along a simulated
        trajectory: one row per time point (u includes the foreshortening u₂)."""
        return self.displacement(self._coordinates(result), [x])[:, 0, :]

    def slope(self, result, x: float) -> NDArray:
        """(v′, w′) at station x, one row per time point."""
        return self._derivative(result, x, 1)

    def bending_moment(self, result, x: float) -> NDArray:
        """Bending moments (EI_z v″, EI_y w″) at station x (N m), one row per time point."""
        curvature = self._derivative(result, x, 2)
        return curvature * np.array([self._EI_at(x, "z"), self._EI_at(x, "y")])

    def _derivative(self, result, x: float, order: int) -> NDArray:
        q_e = self._coordinates(result)
        Phi, _ = self.station_data(np.array([float(x)]))
        v = q_e[:, self.v_cols.start - 6 : self.v_cols.stop - 6] @ Phi["v"][order][:, 0]
        w = q_e[:, self.w_cols.start - 6 : self.w_cols.stop - 6] @ Phi["w"][order][:, 0]
        return np.column_stack((v, w))

    def _EI_at(self, x: float, axis: str) -> float:
        EI = self._EI[axis]
        return float(EI(np.array([x]))[0]) if callable(EI) else float(EI)

    def __repr__(self) -> str:
        return f"RitzBeam(L={self.length}, n_u={self.n_u}, n_v={self.n_v}, n_w={self.n_w}, stiffening={self.stiffening})"

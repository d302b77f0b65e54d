"""An Euler–Bernoulli beam by a direct Ritz approach (B(19)–(25), docs/theory.md §10).

The beam hangs in a floating reference frame R (its root, axis x) with describing
velocities ẏ = (v_R, ω_R, q̇_e). A slice at x sits at r(x) = (x + u + u₂, v, w) with
u = Φ_uᵀ q_u, v = Φ_vᵀ q_v, w = Φ_wᵀ q_w and, when ``stiffening`` is on, the second-order
axial displacement u₂(x) = −½ ∫₀ˣ (v′² + w′²) dξ = −½ (q_vᵀ H_v(x) q_v + q_wᵀ H_w(x) q_w),
H(x) = ∫₀ˣ Φ′Φ′ᵀ dξ. Its velocity is v_c(x) = J(x) ẏ with J = [E, −r̃(x), Φ_r(x, q_e)], and
the Projection Equation B(19)–(25) for the slices gives

    M_n = ∫ Jᵀ J dm,   h_n = −∫ Jᵀ (ω̃ ṙ + ω̃ v_c − (q̇_vᵀH_v q̇_v + q̇_wᵀH_w q̇_w) e_x − g_R) dm − K_e q_e

(the bracket is J̇ ẏ + ω̃ v_c − g, the acceleration not proportional to ÿ), plus the rotary
inertia of the slices (Rayleigh) with ω_c = (E − θ̃) ω + (E − ½θ̃) θ̇ in the slice's frame,
rotation vector θ = Φ_θᵀ q_e + τ e_x, Φ_θ = (Φ_β, −Φ_w′, Φ_v′) (torsion β, docs/theory.md §10) and
the geometric twist τ = q_vᵀ T(x) q_w of a beam without torsional strain (second order; it
carries the spin-up torque's coupling, docs/theory.md). Because
u₂ is part of the kinematics, the projection of the slices' axial inertia loads on
∂u₂/∂q gives the geometric stiffness ∫ N(x) Φ′Φ′ᵀ dx with N(x) = ∫ₓᴸ f_x: dynamic
stiffening from spin, angular and frame acceleration and gravity alike, and the model
stays conservative (tests/subsystems/test_beam.py checks energy). Integrals at
Gauss–Legendre stations fixed at construction, summed per call or from moments computed
once (the ``integration`` strategy, :mod:`projeq.subsystems.beam.integrals`).

Letters: ``K_e`` is the stiffness matrix (``K`` is kept for q̇ = K ṡ).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import derivative_along
from projeq.checks import count, finite_array, flag, non_negative, positive
from projeq.joints import Relative
from projeq.spatial import cross, rotation_x, rotation_y, rotation_z, skew, skew_stack
from projeq.subsystems.beam import shapes
from projeq.subsystems.beam.checks import beam_memory, family_shapes, per_length
from projeq.subsystems.beam.integrals import PrecomputedIntegrals, Quadrature
from projeq.subsystems.base import Subsystem
from projeq.subsystems.beam.probes import BeamProbes


def _warn_unused(name: str, stiffness, count_name: str, n: int, deformation: str) -> None:
    """A UserWarning that ``name``, given, has no effect: its deformation has no Ritz functions
    (n = 0). A warning, not an error: the counts are the accuracy knob, and a convergence
    study keeps the material data while it turns a deformation off."""
    if stiffness is not None and n == 0:
        warnings.warn(f"{name}: given but unused, since {count_name} = 0 (no {deformation} Ritz functions); "
                      f"give {count_name} > 0 for {deformation} deformation, or leave {name} out",
                      UserWarning, stacklevel=3)


class RitzBeam(BeamProbes, Subsystem):
    """A beam subsystem: Euler–Bernoulli bending in two planes, optional axial and torsional
    deformation and rotary inertia, dynamic stiffening, stiffness-proportional damping.

    Parameters
    ----------
    length : float
        L in m; the beam runs along the reference frame's x axis from its origin.
    rho_A : float or callable
        Mass per length ρA (kg/m), constant or a function of x.
    EI_z, EI_y : float or callable
        Bending stiffness for v (x–y plane) and w (x–z plane), N m²; EI_y defaults to EI_z.
    EA : float or callable, optional
        Axial stiffness (N), needed when ``n_u > 0``; given with ``n_u = 0`` it has no effect
        and a UserWarning says so.
    rho_I : (float, float), optional
        Rotary inertia per length (ρI_y, ρI_z) in kg m; polar ρ(I_y + I_z). None: none.
    n_v, n_w, n_u, n_beta : int
        Number of Ritz functions for v, w, u and the torsion angle β (the accuracy knob).
    GI_t : float or callable, optional
        Torsional stiffness (N m²), needed when ``n_beta > 0``; given with ``n_beta = 0`` it
        has no effect and a UserWarning says so.
    rho_I_p : float, optional
        Polar mass moment per length ρI_p (kg m) of the torsion, needed when ``n_beta > 0``
        unless ``rho_I`` gives it as ρ(I_y + I_z). With ``n_beta = 0`` it still acts: it is the
        slices' inertia about the beam's axis (ρI_p L in the rigid beam's spin about x).
    family : "polynomial", "clamped_free", "pinned_free" or a callable ``(n, L) -> shapes``
        Bending family; the axial and torsional families are chosen alike ("polynomial" or
        "clamped_free": the fixed–free bar's sines; "pinned_free" uses the latter; a
        callable serves all deformations). A callable's output is checked by
        :func:`projeq.subsystems.beam.checks.family_shapes`.
    support : "clamped" or "pinned"
        Geometric boundary conditions the bending functions must meet at the root:
        Φ(0) = Φ′(0) = 0 (clamped) or Φ(0) = 0 (pinned: the joint carries the rigid
        rotation about the pin). A family violating them is refused.
    quadrature_order : int, optional
        Gauss points along the beam (default 2·max(n) + 6).
    stiffening : bool
        Include u₂ (dynamic stiffening); default True.
    damping : float
        β of the stiffness-proportional damping force −β K_e q̇_e (s).
    integration : Quadrature or PrecomputedIntegrals, optional
        How the slices' translation terms of B(25) are integrated, chosen here once
        (:mod:`projeq.subsystems.beam.integrals`): by quadrature at every call
        (:class:`~projeq.subsystems.beam.integrals.Quadrature`, the default) or from moments
        of the shape functions computed once
        (:class:`~projeq.subsystems.beam.integrals.PrecomputedIntegrals`: exact for this
        model at any deformation). Any class ``integration(beam)`` answering ``terms`` and
        ``elastic_rows`` as these do.
    precomputed_integrals : bool
        Shorthand for ``integration=PrecomputedIntegrals``; default False.

    Attributes
    ----------
    integrals : Quadrature or PrecomputedIntegrals
        The integration strategy built for this beam.
    K_e : ndarray
        Stiffness matrix of the elastic coordinates.
    first_frequency : float
        Lowest bending frequency at rest (rad/s).
    x : ndarray
        The quadrature stations (m).
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
        n_beta: int = 0,
        GI_t=None,
        rho_I_p=None,
        family="polynomial",
        support: str = "clamped",
        quadrature_order: int | None = None,
        stiffening: bool = True,
        damping: float = 0.0,
        precomputed_integrals: bool = False,
        integration=None,
    ):
        self.length = L = positive("length", length)
        for name, n in (("n_v", n_v), ("n_w", n_w), ("n_u", n_u), ("n_beta", n_beta)):
            if isinstance(n, bool) or not isinstance(n, (int, np.integer, float)) or int(n) != n or n < 0:
                raise ValueError(f"{name}: number of Ritz functions must be a non-negative integer, got {n!r}")
        self.n_u, self.n_v, self.n_w, self.n_beta = int(n_u), int(n_v), int(n_w), int(n_beta)
        self.n_e = self.n_u + self.n_v + self.n_w + self.n_beta
        if self.n_e == 0:
            raise ValueError("n_v, n_w, n_u, n_beta: a beam needs at least one Ritz function")
        beam_memory(6 + self.n_e)
        if self.n_u and EA is None:
            raise ValueError("EA: axial deformation (n_u > 0) needs the axial stiffness EA")
        if self.n_beta and GI_t is None:
            raise ValueError("GI_t: torsion (n_beta > 0) needs the torsional stiffness GI_t")
        if self.n_beta and rho_I_p is None and rho_I is None:
            raise ValueError("rho_I_p: torsion (n_beta > 0) needs the polar mass moment per length ρI_p")
        _warn_unused("EA", EA, "n_u", self.n_u, "axial")
        _warn_unused("GI_t", GI_t, "n_beta", self.n_beta, "torsional")
        if support not in ("clamped", "pinned"):
            raise ValueError(f"support: must be 'clamped' or 'pinned', got {support!r}")
        self.support = support
        self.n_y = 6 + self.n_e
        self.S = np.vstack((np.eye(6), np.zeros((self.n_e, 6))))
        self.stiffening = flag("stiffening", stiffening)
        self.damping = non_negative("damping", damping)
        default_order = 2 * max(self.n_u, self.n_v, self.n_w, self.n_beta) + 6
        order = default_order if quadrature_order is None else quadrature_order
        self.order = order = count("quadrature_order", order)
        n_max = max(self.n_u, self.n_v, self.n_w, self.n_beta)
        if order < n_max + 2:  # Gauss with p points is exact up to degree 2p − 1
            raise ValueError(
                f"quadrature_order: {order} Gauss points integrate polynomials up to degree {2 * order - 1} "
                f"exactly, but the products of {n_max} Ritz functions reach degree {2 * n_max + 2}; give at "
                f"least {n_max + 2} (default {default_order})"
            )
        t, w = np.polynomial.legendre.leggauss(order)
        self.x = x = 0.5 * L * (t + 1.0)
        self.weights = 0.5 * L * w
        self.mass_weights = self.weights * per_length("rho_A", rho_A, x)
        self._shapes(family, L)
        self._EI = {"z": EI_z, "y": EI_y if EI_y is not None else EI_z}
        self._stiffness(EI_z, self._EI["y"], EA, GI_t)
        self._rotary(rho_I, rho_I_p)
        self._check_independent()
        self.integrals = _integration(integration, flag("precomputed_integrals", precomputed_integrals))(self)
        bending = np.r_[self.v_cols, self.w_cols] - 6
        M_b = self._mass_at_rest()[np.ix_(bending, bending)]
        self.first_frequency = first_bending_frequency(self.K_e[np.ix_(bending, bending)], M_b)

    # -- precomputation ------------------------------------------------------------------
    def _shapes(self, family, L) -> None:
        """The families, their root check (support), and Φ, Φ′, Φ″, H at the stations."""
        ends = np.cumsum([6, self.n_u, self.n_v, self.n_w, self.n_beta])
        self.u_cols, self.v_cols, self.w_cols, self.beta_cols = (slice(a, b) for a, b in zip(ends[:-1], ends[1:]))
        bending = (0, 1) if self.support == "clamped" else (0,)
        axial_family = "clamped_free" if family == "pinned_free" else family
        self.families = {}
        for key, n, fam_name, table, conditions in (
            ("u", self.n_u, axial_family, shapes.AXIAL, (0,)),
            ("v", self.n_v, family, shapes.BENDING, bending),
            ("w", self.n_w, family, shapes.BENDING, bending),
            ("beta", self.n_beta, axial_family, shapes.AXIAL, (0,)),
        ):
            self.families[key] = fam = family_shapes(fam_name, table, n, L, key)
            if fam is None:
                continue
            at_root = fam(np.zeros(1))
            for derivative in conditions:
                bad = np.flatnonzero(np.abs(at_root[derivative][:, 0]) > 1e-12)
                if bad.size:
                    what = "Φ(0)" if derivative == 0 else "Φ′(0)"
                    raise ValueError(
                        f"family: Ritz functions {bad.tolist()} for {key} violate the geometric boundary "
                        f"condition of the {self.support} root ({what} ≠ 0)"
                    )
        self.Phi, self.H = self.station_data(self.x)
        self._field = self.slice_field()

    def station_data(self, x: NDArray) -> tuple[dict, dict]:
        """Φ, Φ′, Φ″ of u, v, w at stations x, and H(x) = ∫₀ˣ Φ′Φ′ᵀ dξ of v and w
        (by Gauss quadrature of the beam's order on [0, x])."""
        sizes = {"u": self.n_u, "v": self.n_v, "w": self.n_w}
        Phi = {
            key: tuple(np.asarray(p, dtype=float) for p in fam(x)) if fam else tuple(np.zeros((0, len(x))) for _ in range(4))
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

    def _stiffness(self, EI_z, EI_y, EA, GI_t) -> None:
        """K_e = ∫ (EA Φ_u′Φ_u′ᵀ + EI_z Φ_v″Φ_v″ᵀ + EI_y Φ_w″Φ_w″ᵀ + GI_t Φ_β′Φ_β′ᵀ) dx
        (block diagonal, docs/theory.md §10)."""
        self.K_e = np.zeros((self.n_e, self.n_e))
        blocks = (
            ("u", 1, EA, "EA", self.u_cols),
            ("v", 2, EI_z, "EI_z", self.v_cols),
            ("w", 2, EI_y, "EI_y", self.w_cols),
            ("beta", 1, GI_t, "GI_t", self.beta_cols),
        )
        for key, derivative, stiffness, name, cols in blocks:
            if cols.stop == cols.start:
                continue
            D = self.Phi[key][derivative]
            k = self.weights * per_length(name, stiffness, self.x)
            sl = slice(cols.start - 6, cols.stop - 6)
            self.K_e[sl, sl] = (D * k) @ D.T

    def _rotary(self, rho_I, rho_I_p) -> None:
        """Rotary inertia per station diag(ρI_p, ρI_y, ρI_z) (ρI_p = ρ(I_y + I_z) unless
        given) and the slices' rotation field (:meth:`rotation_field`)."""
        self.rotary = None
        if rho_I is not None or rho_I_p is not None:
            I_y, I_z = 0.0, 0.0
            if rho_I is not None:
                rho_I = finite_array("rho_I", rho_I)
                if rho_I.size not in (1, 2):
                    raise ValueError(f"rho_I: expected ρI or (ρI_y, ρI_z), got {rho_I.size} values")
                rho_I = np.broadcast_to(rho_I.ravel(), (2,))
                I_y, I_z = (positive(f"rho_I[{i}]", v) for i, v in enumerate(rho_I))
            I_p = I_y + I_z if rho_I_p is None else positive("rho_I_p", rho_I_p)
            self.rotary = self.weights[:, None] * np.array([I_p, I_y, I_z])[None, :]
        Phi_theta = np.zeros((len(self.x), 3, self.n_e))
        e = self._local
        Phi_theta[:, 0, e(self.beta_cols)] = self.Phi["beta"][0].T  # twist about x: β
        Phi_theta[:, 1, e(self.w_cols)] = -self.Phi["w"][1].T  # rotation about y: −w′
        Phi_theta[:, 2, e(self.v_cols)] = self.Phi["v"][1].T  # rotation about z: +v′
        T = np.zeros((len(self.x), self.n_e, self.n_e))
        if self.rotary is not None:
            T[:, e(self.v_cols), e(self.w_cols)] = self._geometric_twist(self.x)
        self._rotation = (np.zeros((len(self.x), 3)) if self.rotary is None else self.rotary, Phi_theta, T)

    def rotation_field(self) -> tuple[NDArray, NDArray, NDArray]:
        """The slices' rotation at the quadrature stations as constants (I, Φ_θ, T): the rotary
        inertia I_k = Δx_k (ρI_p, ρI_y, ρI_z) (zero without rotary inertia) and the rotation
        vector θ(q_e) = Φ_θ q_e + (q_eᵀ T q_e) e_x of each slice relative to R, with
        Φ_θ = (Φ_β, −Φ_w′, Φ_v′) (torsion, then the bending slopes, docs/theory.md §10) and T
        the geometric twist τ = q_vᵀ T(x) q_w (:meth:`_geometric_twist`) in q_e's positions.
        :meth:`_slice_rotation` evaluates it, and so does the compiled kernel
        (:func:`projeq.assembly.kernels.rotary_body`)."""
        return self._rotation

    def _geometric_twist(self, x: NDArray) -> NDArray:
        """T(x) = ½ ∫₀ˣ (Φ_v′Φ_w″ᵀ − Φ_v″Φ_w′ᵀ) dξ at stations x: the slices of a beam without
        torsional strain (κ_x = 0) turn about x by τ(x) = q_vᵀ T(x) q_w relative to R, the
        rotation vector's x component that κ_x = τ′ − ½(θ × θ′)_x = 0 asks for, θ = (τ, −w′, v′)
        (docs/theory.md, "The spinning beam's rotary inertia")."""
        n_v, n_w = self.n_v, self.n_w
        if not (n_v and n_w):
            return np.zeros((len(x), n_v, n_w))
        t, w = np.polynomial.legendre.leggauss(self.order)
        xi = (0.5 * x[:, None] * (t[None, :] + 1.0)).ravel()  # quadrature points in [0, x]
        dv = [np.asarray(d).reshape(n_v, len(x), len(t)) for d in self.families["v"](xi)[1:3]]
        dw = [np.asarray(d).reshape(n_w, len(x), len(t)) for d in self.families["w"](xi)[1:3]]
        weights = 0.25 * x[:, None] * w[None, :]  # ½ of the quadrature weights on [0, x]
        return np.einsum("igk,jgk,gk->gij", dv[0], dw[1], weights) - np.einsum("igk,jgk,gk->gij", dv[1], dw[0], weights)

    def _check_independent(self) -> None:
        gram = np.zeros((self.n_e, self.n_e))
        for key, cols in (("u", self.u_cols), ("v", self.v_cols), ("w", self.w_cols), ("beta", self.beta_cols)):
            P, sl = self.Phi[key][0], slice(cols.start - 6, cols.stop - 6)
            gram[sl, sl] = (P * self.weights) @ P.T
        eigenvalues, vectors = np.linalg.eigh(gram)
        if eigenvalues[0] <= 1e-14 * eigenvalues[-1]:  # numerically singular (polynomials: n ≤ 9 pass, n = 10 not)
            involved = [self._name(k) for k in np.flatnonzero(np.abs(vectors[:, 0]) > 1e-3)]
            raise ValueError(
                f"family: the Ritz functions {involved} are linearly dependent to machine precision "
                "(singular mass matrix); for many functions use family='clamped_free'"
            )

    def _name(self, k: int) -> str:
        """Name of elastic coordinate k: the deformation and the function's index in it."""
        for key, cols in (("u", self.u_cols), ("v", self.v_cols), ("w", self.w_cols), ("beta", self.beta_cols)):
            if cols.start - 6 <= k < cols.stop - 6:
                return f"{key}[{k - cols.start + 6}]"
        raise IndexError(k)

    def _mass_at_rest(self) -> NDArray:
        """M_ee of the undeformed beam: Σ_k m_k Ψ_kᵀ Ψ_k + Σ_k Φ_θ,kᵀ I_k Φ_θ,k over the stations
        (translation with Ψ = Φ_r(x, 0), and the slices' rotary inertia)."""
        Psi = self.slices(np.zeros(self.n_e))[1]
        M = np.einsum("k,kai,kaj->ij", self.mass_weights, Psi, Psi)
        if self.rotary is not None:
            I, Phi_theta, _ = self._rotation
            M += np.einsum("ka,kai,kaj->ij", I, Phi_theta, Phi_theta)
        return M

    def coordinates(self) -> tuple:
        """The Ritz amplitudes in the order of q_e: axial u[i], bending v[i] and w[i] (m, the
        shape functions are dimensionless) and torsion beta[i] (rad)."""
        groups = (("u", self.n_u, "m"), ("v", self.n_v, "m"), ("w", self.n_w, "m"), ("beta", self.n_beta, "rad"))
        return tuple((f"{name}[{i}]", unit) for name, n, unit in groups for i in range(n))

    # -- slice kinematics ------------------------------------------------------------------
    def slice_field(self, x: NDArray | None = None, data=None) -> tuple[NDArray, NDArray, NDArray]:
        """The slice kinematics at the quadrature stations (or at ``x`` with its
        ``station_data``) as constants: r(x, q_e) = r₀(x) + Ψ(x) q_e − ½ (q_eᵀ Q(x) q_e) e_x
        with r₀ = x e_x, Ψ = Φ_r(x, 0) (rows u, v, w of the Ritz functions) and
        Q = blockdiag(H_v, H_w) when ``stiffening`` (u₂, module docstring), else 0.
        Returns (r₀, Ψ, Q), stacked over the stations; :meth:`slices` evaluates it, and so
        does the compiled kernel (:mod:`projeq.assembly.kernels`)."""
        x, (Phi, H) = (self.x, (self.Phi, self.H)) if x is None else (x, data)
        e = self._local  # columns of ẏ → positions within q_e
        r0 = np.zeros((len(x), 3))
        r0[:, 0] = x
        Psi = np.zeros((len(x), 3, self.n_e))
        Psi[:, 0, e(self.u_cols)] = Phi["u"][0].T
        Psi[:, 1, e(self.v_cols)] = Phi["v"][0].T
        Psi[:, 2, e(self.w_cols)] = Phi["w"][0].T
        Q = np.zeros((len(x), self.n_e, self.n_e))
        if self.stiffening:
            Q[:, e(self.v_cols), e(self.v_cols)] = H["v"]
            Q[:, e(self.w_cols), e(self.w_cols)] = H["w"]
        return r0, Psi, Q

    def slices(self, q_e: NDArray, field: tuple | None = None):
        """r(x) and Φ_r(x, q_e) = ∂r/∂q_e = Ψ − e_x (Q q_e)ᵀ at the quadrature stations (or
        at those of ``field``, another :meth:`slice_field`, formed once by the caller):
        the slice field evaluated at q_e."""
        r0, Psi, Q = self._field if field is None else field
        Qq = Q @ q_e  # complex for the complex-step derivative of ports
        r = r0 + Psi @ q_e
        r[:, 0] -= 0.5 * (Qq @ q_e)  # u₂
        Phi_r = Psi.astype(Qq.dtype)
        Phi_r[:, 0, :] -= Qq  # ∂u₂/∂q_e
        return r, Phi_r

    def jacobian(self, r: NDArray, Phi_r: NDArray) -> NDArray:
        """J(x) = [E, −r̃(x), Φ_r(x)], stacked over the stations."""
        J = np.empty((len(r), 3, self.n_y), dtype=np.result_type(r, Phi_r))
        J[:, :, :3] = np.eye(3)
        J[:, :, 3:6] = -skew_stack(r)
        J[:, :, 6:] = Phi_r
        return J

    # -- the subsystem interface -------------------------------------------------------------
    def gauss_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray):
        """(M_n, h_n) of B(25): the translation by the beam's integration strategy, the
        rotary inertia of the slices and the restoring forces (module docstring)."""
        omega, q_e_dot = y_dot[3:6], y_dot[6:]
        self.check_spin(omega)
        M, h = self.integrals.terms(y_dot, R, gravity, q_e)
        if self.rotary is not None:
            Jw, omega_c, c_w = self._slice_rotation(omega, q_e, q_e_dot, y_dot)
            Jw_flat = (Jw * np.sqrt(self.rotary)[:, :, None]).reshape(-1, self.n_y)
            M += Jw_flat.T @ Jw_flat
            h -= Jw.reshape(-1, self.n_y).T @ (self.rotary * c_w + cross(omega_c, self.rotary * omega_c)).ravel()
        h[6:] -= self._restoring_force(q_e, q_e_dot)
        return M, h

    def elastic_terms(self, y_dot: NDArray, R: NDArray, gravity: NDArray, q_e: NDArray):
        """The last n_e rows (M_e, h_e) of :meth:`gauss_terms`: all a beam on a prescribed
        hub needs (:mod:`projeq.assembly.beam_fast`); without rotary inertia only these rows
        are asked of the integration strategy (precomputed integrals form only them)."""
        if self.rotary is not None:
            M, h = self.gauss_terms(y_dot, R, gravity, q_e)
            return M[6:], h[6:]
        self.check_spin(y_dot[3:6])
        M_e, h_e = self.integrals.elastic_rows(y_dot, R, gravity, q_e)
        return M_e, h_e - self._restoring_force(q_e, y_dot[6:])

    def check_spin(self, omega: NDArray) -> None:
        """Without stiffening a spin about an axis across the beam faster than its first
        bending frequency makes the model unstable (ω_lag² = ω₁² − Ω² < 0): allowed, but
        said by a RuntimeWarning whose text is fixed per beam, so that Python's warning
        filters show it once (the default action: once per text and place)."""
        if not self.stiffening and np.hypot(*np.real(omega[1:])) > self.first_frequency:
            warnings.warn(
                f"RitzBeam without stiffening spins about an axis across the beam faster than its first "
                f"bending frequency {self.first_frequency:.3g} rad/s: the unstiffened model is unstable "
                "there (use stiffening=True)",
                RuntimeWarning,
            )

    def _restoring_force(self, q_e: NDArray, q_e_dot: NDArray) -> NDArray:
        """K_e (q_e + d q̇_e): elastic and stiffness-proportional damping forces."""
        return self.K_e @ (q_e + self.damping * q_e_dot)

    def _slice_rotation(self, omega, q_e, q_e_dot, y_dot):
        """Angular velocity of the slices in their own (slightly turned) frames to second
        order, ω_c = (E − θ̃) ω + (E − ½θ̃) θ̇ with the rotation vector θ = Φ_θ q_e + τ e_x of the
        slice relative to R (:meth:`rotation_field`; τ = q_eᵀ T q_e the geometric twist of a
        beam without torsional strain, :meth:`_geometric_twist`): its Jacobian
        J_ω(x, q_e) = [0, E − θ̃, (E − ½θ̃) ∂θ/∂q_e] with ∂θ/∂q_e = Φ_θ + e_x ((T + Tᵀ) q_e)ᵀ,
        ω_c, and J̇_ω ẏ = ω̃ θ̇ + (E − ½θ̃) e_x 2 q̇_eᵀ T q̇_e (the rotary terms of the Rayleigh
        beam; with Euler's ω̃_c I ω_c the power is exactly d/dt ½ ω_cᵀ I ω_c). The second-order
        parts carry the ρI_p α̈ coupling of a beam spun about its axis (docs/theory.md, "The
        spinning beam's rotary inertia")."""
        _, Phi_theta, T = self._rotation
        dtype = np.result_type(Phi_theta, q_e, q_e_dot)  # complex in a complex step
        T_q, q_T = T @ q_e, q_e @ T
        theta = (Phi_theta @ q_e).astype(dtype)
        theta[:, 0] += T_q @ q_e  # τ
        d_theta = Phi_theta.astype(dtype)  # ∂θ/∂q_e
        d_theta[:, 0, :] += T_q + q_T
        theta_skew = skew_stack(theta)
        theta_dot = d_theta @ q_e_dot
        twist_acceleration = 2.0 * ((T @ q_e_dot) @ q_e_dot)
        J = np.zeros((len(theta), 3, self.n_y), dtype)
        J[:, :, 3:6] = np.eye(3) - theta_skew
        J[:, :, 6:] = d_theta - 0.5 * theta_skew @ d_theta
        c_w = cross(omega, theta_dot)
        c_w[:, 0] += twist_acceleration
        c_w -= 0.5 * np.cross(theta, twist_acceleration[:, None] * np.array([1.0, 0.0, 0.0]))
        return J, J @ y_dot, c_w

    def kinetic_energy(self, y_dot: NDArray, q_e: NDArray) -> float:
        """½ ẏᵀ M ẏ (exact for the slice kinematics)."""
        M, _ = self.gauss_terms(y_dot, np.eye(3), np.zeros(3), q_e)
        return 0.5 * (y_dot @ M @ y_dot)

    def potential_energy(self, R: NDArray, r: NDArray, gravity: NDArray, q_e: NDArray) -> float:
        """Gravity −∫ g·r_slice dm (at the slices' positions only under gravity) plus the strain
        energy ½ q_eᵀ K_e q_e."""
        strain = 0.5 * q_e @ self.K_e @ q_e
        if not np.any(gravity):
            return strain
        r_x, _ = self.slices(q_e)
        return -self.mass_weights @ (r_x @ R.T + r) @ gravity + strain

    def port(self, point: NDArray, q_e: NDArray, q_e_dot: NDArray) -> Relative:
        """Kinematics of a frame attached at ``point`` of the undeformed beam (station
        x = point[0], cross-section offset c = (0, point[1], point[2])), relative to the
        beam's reference frame, as a joint would give them (docs/theory.md §10, last line):

        pose A = R_z(v′) R_y(−w′) R_x(β) (Bremer's Cardan sequence, B(17)), r = r(x) + A c;
        relative twist F q̇_e in port coordinates with F = [[Aᵀ Φ_r − c̃ Φ_ω], [Φ_ω]],
        Φ_ω q̇_e = R_xᵀ(v̇′ (−sin(−w′), 0, cos(−w′)) − ẇ′ e_y) + β̇ e_x; Ḟ q̇_e by complex step.
        """
        return self.port_at(point).relative(q_e, q_e_dot)

    def port_at(self, point: NDArray) -> BeamPort:
        """The frame attached at ``point`` with its station data computed once: its
        ``relative(q_e, q_e_dot)`` is :meth:`port` (for evaluators that keep it)."""
        x = float(point[0])
        if not 0.0 <= x <= self.length:
            raise ValueError(f"r_pn: a joint on a beam must sit at a station 0 ≤ x ≤ {self.length}, got x = {x}")
        station = np.array([x])
        data = (station, self.station_data(station))
        e = self._local
        angles = np.zeros((3, self.n_e))  # ∂v′/∂q_e, ∂(−w′)/∂q_e and ∂β/∂q_e at the station
        angles[0, e(self.v_cols)] = data[1][0]["v"][1][:, 0]
        angles[1, e(self.w_cols)] = -data[1][0]["w"][1][:, 0]
        angles[2, e(self.beta_cols)] = data[1][0]["beta"][0][:, 0]
        r0, Psi, Q = self.slice_field(*data)
        return BeamPort(self, data, np.array([0.0, point[1], point[2]]), (r0[0], Psi[0], Q[0], angles))

    def _port_terms(self, q_e, port):
        """(A, r, F) of ``port`` (a :class:`BeamPort`) from its field; complex-safe, for the
        complex-step Ḟ."""
        offset, angles = port.offset, port.field[3]
        r_x, Phi_r = self.slices(q_e, tuple(constants[None] for constants in port.field[:3]))  # at the one station
        a, b, beta = angles @ q_e  # v′, −w′, β
        R_x = rotation_x(beta)
        A = rotation_z(a) @ rotation_y(b) @ R_x
        Phi_omega = R_x.T @ np.array([-np.sin(b) * angles[0], angles[1], np.cos(b) * angles[0]])
        Phi_omega[0] += angles[2]
        F = np.vstack((A.T @ Phi_r[0] - skew(offset) @ Phi_omega, Phi_omega))
        return A, r_x[0] + A @ offset, F

    def __repr__(self) -> str:
        counts = f"n_u={self.n_u}, n_v={self.n_v}, n_w={self.n_w}, n_beta={self.n_beta}"
        return f"RitzBeam(L={self.length}, {counts}, support={self.support!r}, stiffening={self.stiffening})"


@dataclass(frozen=True)
class BeamPort:
    """A frame attached to a RitzBeam at a station x with cross-section offset c, and the
    beam's station data there (built once by :meth:`RitzBeam.port_at`)."""

    beam: RitzBeam
    data: tuple  # (x as a 1-array, station_data(x))
    offset: NDArray  # c = (0, y, z)
    field: tuple  # (r₀, Ψ, Q) of RitzBeam.slice_field at x, and the angles' rows ∂(v′, −w′, β)/∂q_e

    def relative(self, q_e: NDArray, q_e_dot: NDArray) -> Relative:
        """Pose, F q̇_e and Ḟ q̇_e relative to the beam's frame (:meth:`RitzBeam.port`);
        Ḟ q̇_e by complex step."""
        A, r, F = self.beam._port_terms(q_e, self)
        F_dot = derivative_along(lambda q: self.beam._port_terms(q, self)[2], q_e, q_e_dot)
        return Relative(A, r, F, F @ q_e_dot, F_dot @ q_e_dot)

    def position(self, q_e: NDArray) -> NDArray:
        """The frame's origin r(x) + A c in the beam's frame at q_e (real or complex)."""
        return self.beam._port_terms(q_e, self)[1]


def first_bending_frequency(K_b: NDArray, M_b: NDArray) -> float:
    """Lowest bending frequency (rad/s) of a beam at rest on its support: ω₁ = √λ₁ with λ₁
    the smallest eigenvalue of K_b φ = λ M_b φ, the bending blocks of the stiffness and mass
    matrices; ∞ without bending functions.

    >>> round(first_bending_frequency(np.diag([0.25, 9.0]), np.eye(2)), 12)  # a soft beam: below 1 rad/s
    0.5
    """
    if K_b.size == 0:
        return np.inf
    from scipy.linalg import eigh

    return float(np.sqrt(max(eigh(K_b, M_b, eigvals_only=True)[0], 0.0)))


def _integration(integration, precomputed_integrals: bool):
    """The integration strategy from ``integration`` or its shorthand ``precomputed_integrals``."""
    if integration is None:
        return PrecomputedIntegrals if precomputed_integrals else Quadrature
    if not callable(integration):
        raise ValueError(
            f"integration: expected Quadrature, PrecomputedIntegrals or a class integration(beam), got {integration!r}"
        )
    if precomputed_integrals and integration is not PrecomputedIntegrals:
        raise ValueError(
            f"precomputed_integrals, integration: precomputed_integrals=True is integration=PrecomputedIntegrals, "
            f"but integration={integration!r} was given"
        )
    return integration

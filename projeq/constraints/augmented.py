"""Closed loops through singular positions and with redundant constraints: the augmented
Lagrangian formulation (docs/theory.md, the table of formulations).

Coordinate partitioning (:mod:`.partitioned`) needs a regular block A_dep of the constraint
matrix A_s; it cannot exist where the constraints become dependent — a mechanism whose links
come into line (the N-four-bar of the IFToMM benchmark A02 when its bars are horizontal, where
its mobility jumps from 1 to N + 1) or an overconstrained one whose rows are dependent
everywhere (Bricard's mechanism, Grübler count 0, mobility 1). :class:`AugmentedSystem` keeps
all the tree's velocities ṡ_tree as its state and the constraint forces A_sᵀ λ in the
Projection Equation, M s̈ + b = A_sᵀ λ, with the accelerations from the constraints at
acceleration level, stabilised (Baumgarte 1972, with ω and ζ):

    A_s s̈ = r,   r = −γ − 2 ζ ω (A_s ṡ − b_s) − ω² [Φ; 0]

solved by the augmented Lagrangian iteration of Bayo, García de Jalón & Serna (1988) and
Bayo & Ledesma (1996, "Augmented Lagrangian and mass-orthogonal projection methods for
constrained multibody dynamics", Nonlinear Dynamics 9, 113–130, eqs. (7)–(9)):

    (M + α A_sᵀ A_s) s̈_{k+1} = −b + A_sᵀ λ*_k + α A_sᵀ r,   λ*_{k+1} = λ*_k + α (r − A_s s̈_{k+1}),

from λ*_0 = 0. With M = L Lᵀ and the mass-weighted A_s L⁻ᵀ = U Σ Vᵀ, k iterations move z = Lᵀ s̈
from the free motion z_free = −L⁻¹ b by Σ_i v_i f_i (u_iᵀ (r − A_s L⁻ᵀ z_free)) / σ_i with the filter
f_i = 1 − (1 + α σ_i²)^(−k) (α in units of 1/σ_max²): this closed form is what is evaluated. It is
Gauss's principle of least constraint for every direction the constraints hold (α σ_i² ≫ 1:
f_i = 1 to round-off) and lets go smoothly of the directions that vanish at a singular position
(σ_i → 0, f_i → 0), where the partitioned form divides by zero. Redundant rows (σ_i below
RANK_TOLERANCE σ_max) do not act; their multipliers are the minimum-norm solution of
A_sᵀ λ = M s̈ + b (the λ orthogonal to
every combination of rows that cancels): λ = Σ_i u_i f_i (u_iᵀ r̃) / σ_i², r̃ = r − A_s L⁻ᵀ z_free.
The rank of A_s and the mobility are computed at every evaluation (:meth:`AugmentedSystem.rank`,
:meth:`AugmentedSystem.mobility`); nothing stops the run at a singular position.

Measured against :class:`~projeq.constraints.partitioned.TangentSystem` (``benchmarks/iftomm.py``, double
four-bar to 10 s): both run through the singular positions; here the released directions drift
while they are released and the stabilisation pulls them back, so that point B0 is off the
parallelogram motion by 6.6e-6 at rtol 1e-9 (TangentSystem: 7.6e-6) with 1.2 times the
evaluations, but at rtol 1e-10 the motion leaves the parallelogram branch at a crossing (B0 off
by 9.4 m, the energy by 35 J, 3 times the evaluations; TangentSystem: 4.2e-7 m, 8e-8 J): the
branch is held only by the stabilisation, not by construction.

Drift: q is projected onto Φ = 0 wherever :func:`projeq.simulate` normalises it (segment ends,
outputs), as by the partitioned form; the velocities are held by the stabilisation.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.checks import positive
from projeq.constraints.partitioned import RANK_TOLERANCE, ConstrainedSystem

PENALTY = 1e8  # α σ_max²: Bayo & Ledesma's 1e7–1e9 (times the mass scale) in mass-weighted units
ITERATIONS = 3  # augmented Lagrangian iterations: a direction with α σ² = 1e4 holds to 1e-12


class AugmentedSystem(ConstrainedSystem):
    """A tree System with constraint equations, all tree velocities as its state, and the
    constraint forces from the augmented Lagrangian (module docstring).

    Takes the arguments of :class:`~projeq.constraints.partitioned.ConstrainedSystem` (``phi``,
    ``A``, ``b``, ``q0``, ``project_q0``, ``correction``) except the partition, and:

    Parameters
    ----------
    s_dot0 : array (tree.n_s), optional
        Initial tree velocities (default zero), projected onto A_s ṡ = b_s (mass-orthogonally,
        Bayo & Ledesma 1996, eq. (16)).
    omega, zeta : float
        Baumgarte's stabilisation: natural frequency ω (rad/s) and damping ratio ζ of the
        constraint violation.
    penalty : float
        α σ_max² (dimensionless), the augmented Lagrangian penalty.
    iterations : int
        Augmented Lagrangian iterations per evaluation.

    Examples
    --------
    The pendulum of ConstrainedSystem's example, its constraint written twice (a redundant row):

    >>> import numpy as np, projeq as pq
    >>> tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
    ...     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")},
    ...     gravity=(0, 0, -9.81))
    >>> circle = lambda q, t: [np.hypot(q[0], q[1]) - 1.0, 2 * (np.hypot(q[0], q[1]) - 1.0)]
    >>> pendulum = AugmentedSystem(tree, phi=circle, q0=[0.6, -0.8])
    >>> pendulum.n_s, pendulum.rank(pendulum.q0), pendulum.mobility(pendulum.q0)
    (2, 1, 1)
    >>> r = pq.simulate(pendulum, 0.2, n_points=5, n_segments=2)
    >>> bool(np.abs(r.constraint_residual).max() < 1e-10)
    True
    """

    def __init__(self, system, phi=None, A=None, b=None, q0=None, s_dot0=None, project_q0: bool = False,
                 correction: str = "projection", omega: float = 10.0, zeta: float = 1.0,
                 penalty: float = PENALTY, iterations: int = ITERATIONS):
        self.omega, self.zeta = positive("omega", omega), positive("zeta", zeta)
        self.penalty = positive("penalty", penalty)
        if int(iterations) != iterations or iterations < 1:
            raise ValueError(f"iterations: expected a positive integer, got {iterations!r}")
        self.iterations = int(iterations)
        super().__init__(system, phi=phi, A=A, b=b, q0=q0, project_q0=project_q0, correction=correction)
        if s_dot0 is not None:
            self.s_dot0 = self.project_velocities(self.q0, self.check_state(self.q0, s_dot0)[1])

    def _choose_velocities(self, q0, independent, repivot) -> None:
        """All tree velocities are the state: no partition, no re-pivoting."""
        self.independent, self.dependent = np.arange(self.tree.n_s), np.zeros(0, dtype=int)
        self.n_s, self.repivot, self.limit = self.tree.n_s, False, np.inf

    @property
    def partition(self) -> None:
        """None: the state holds every tree velocity."""
        return None

    def check_configuration(self, q: NDArray, t: float = 0.0) -> None:
        """The tree's coordinate singularities only: the constraints may be dependent."""
        self.tree.check_configuration(q, t)

    def events(self) -> tuple:
        """None: the formulation runs through singular positions."""
        return ()

    def with_independent(self, independent, repivot: bool | None = None):
        raise ValueError("independent: an AugmentedSystem has no partition (its state holds every tree "
                         "velocity); build a ConstrainedSystem to choose independent velocities")

    def F(self, q: NDArray, t: float = 0.0, constraint_matrix=None) -> tuple[NDArray, NDArray]:
        """(E, 0): the state is ṡ_tree itself."""
        return np.eye(self.n_s), np.zeros(self.n_s)

    def gauss_form(self, q, s_dot, t: float = 0.0):
        raise ValueError("system: an AugmentedSystem has no Gauss form in minimal velocities (its "
                         "velocities are constrained by multipliers); use a TangentSystem")

    def project_velocities(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> NDArray:
        """ṡ moved onto A_s ṡ = b_s mass-orthogonally: ṡ − M⁻¹ A_sᵀ (A_s M⁻¹ A_sᵀ)⁺ (A_s ṡ − b_s),
        in the mass-weighted singular directions (Bayo & Ledesma 1996, eq. (16))."""
        A_s, b_s = self.constraint_matrix(q, t)
        L = np.linalg.cholesky(self.tree_gauss_form(q, np.zeros(self.n_s), t)[0])
        z, _ = _least_constraint(A_s, L, L.T @ s_dot, b_s, self.penalty, self.iterations)
        return np.linalg.solve(L.T, z)

    def accelerations_tree(self, q: NDArray, s_dot: NDArray, t: float = 0.0,
                           method: str | None = None) -> tuple[NDArray, NDArray]:
        """(s̈_tree, λ) by the augmented Lagrangian (module docstring): M s̈ + b = A_sᵀ λ with
        A_s s̈ = r held in every direction the constraints act, λ the minimum-norm multipliers;
        ``method``: the tree evaluator giving b (as for ConstrainedSystem)."""
        C, c = self.velocity_constraints(q, t)
        K, k = self.tree.K(q, t), self.tree.q_dot(q, np.zeros(self.n_s), t)
        A_s, b_s = C @ K, c - C @ k
        M, b = self.tree_gauss_form(q, s_dot, t, method)
        L = np.linalg.cholesky(M)
        z_free = -np.linalg.solve(L, b)
        z, lam = _least_constraint(A_s, L, z_free, self.target(q, s_dot, t, A_s, b_s, C), self.penalty,
                                   self.iterations)
        return np.linalg.solve(L.T, z), lam

    def target(self, q, s_dot, t, A_s, b_s, C) -> NDArray:
        """r = −γ − 2 ζ ω (A_s ṡ − b_s) − ω² [Φ; 0]: the stabilised A_s s̈ (Baumgarte 1972)."""
        position = np.concatenate((self.phi(q, t), np.zeros(self.m_p)))
        return -self.gamma(q, s_dot, t, C) - 2 * self.zeta * self.omega * (A_s @ s_dot - b_s) \
            - self.omega**2 * position

    def __repr__(self) -> str:
        return f"AugmentedSystem(n_q={self.n_q}, n_s={self.n_s}, {self.m_h} holonomic, {self.m_p} Pfaffian)"


def _least_constraint(A_s, L, z_free, r, penalty, iterations) -> tuple[NDArray, NDArray]:
    """(z, λ): z = Lᵀ s̈ after ``iterations`` augmented Lagrangian steps from z_free towards
    A_s L⁻ᵀ z = r, and the minimum-norm multipliers (module docstring)."""
    if not A_s.size:
        return z_free, np.zeros(A_s.shape[0])
    U, sigma, Vt = np.linalg.svd(np.linalg.solve(L, A_s.T).T, full_matrices=False)  # A_s L⁻ᵀ
    scaled = penalty * (sigma / sigma[0]) ** 2 if sigma[0] > 0 else np.zeros_like(sigma)
    f = -np.expm1(-iterations * np.log1p(scaled))  # 1 − (1 + α σ²)^(−k)
    held = sigma > RANK_TOLERANCE * sigma[0]  # a redundant row's direction (σ = 0 to round-off) does not act
    gain = np.where(held, f / np.where(held, sigma, 1.0), 0.0)
    residual = U.T @ r - sigma * (Vt @ z_free)  # r − A_s L⁻ᵀ z_free in the directions u_i
    lam = U @ (np.where(held, gain / np.where(held, sigma, 1.0), 0.0) * residual)
    return z_free + Vt.T @ (gain * residual), lam

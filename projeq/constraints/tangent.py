"""Closed loops through singular positions and with redundant constraints: minimal velocities
in the tangent space of the constraints, by a rank-revealing factorisation (docs/theory.md, the
table of formulations).

Coordinate partitioning (:mod:`.partitioned`) writes ṡ_tree = F ṡ + f with F = [E; −A_dep⁻¹ A_ind]:
it needs the block A_dep of the constraint matrix A_s regular. That block cannot be regular where
the constraints become dependent — a mechanism whose links come into line (the N-four-bar of the
IFToMM benchmark A02 with its bars horizontal, where its mobility jumps from 1 to N + 1) — nor
anywhere for an overconstrained mechanism (Bricard's, Grübler count 0, mobility 1). Yet the
motion's tangent is regular there: F is the null space of A_s scaled to the independent velocities.
:class:`TangentSystem` takes it from the singular value decomposition A_s = U Σ Vᵀ at every
evaluation:

    N = the columns of V of the n_s smallest singular values,   F = N N_ind⁻¹,

with n_s = n_s,tree − rank A_s at q0 (the mobility, redundant rows counted out) and the
independent velocities those whose rows N_ind are best conditioned (column-pivoted QR of Nᵀ).
Particular solutions come from the pseudo-inverse A_s⁺ (singular values below RANK_TOLERANCE σ_max
dropped): f = f₀ − F f₀[independent] with f₀ = A_s⁺ b_s, and likewise f̄ from A_s s̈_tree = −γ, so
that the Projection Equation Fᵀ (M (F s̈ + f̄) + b) = 0 is that of :mod:`.partitioned`, and the
multipliers λ of M s̈_tree + b = A_sᵀ λ are the minimum-norm solution (least squares): a redundant
row's share of a constraint force is not determined by rigid bodies, and the minimum-norm λ gives
none of it to the combination of rows that cancels.

Near a singular position the null space of A_s is separated from the vanishing singular values by
their size (∝ the distance from the singular position), so that F, and with it the motion's branch,
stays continuous through it: the velocity never leaves the mechanism's one-dimensional tangent
(the branch is kept by construction; an acceleration-level formulation has to hold it by its
stabilisation). Integrator stages, though, lie off the manifold (by the step's curvature error,
~1e-4..1e-3 at rtol 1e-9), and within that distance of a singular position the null vector is no
longer the smallest: a stage would take a direction that has come free there. So N is continued
along the branch, as the tangent of a path is continued in numerical continuation (Allgower &
Georg, "Introduction to Numerical Continuation Methods", 1990, §2.1): where the n_s smallest
singular values are separated from the others (the next one above ``separation`` σ_max, 1e-2
by default, far above the stages' distance from the manifold) N is theirs and is kept as the
branch's tangent; where more singular values fall below (a singular position within ~1e-2 of
the state), N is that kept tangent projected onto the right singular vectors of all of them
and orthonormalised. On the branch the tangent lies in that near-null space, so the projection
returns it (to the square of the stage's distance from the manifold); the plain smallest
singular vectors would be off by O(1) there (tests/constraints/test_iftomm.py). Measured on the
double four-bar of IFToMM A02 to 10 s (``benchmarks/iftomm.py``): point B0 within 7.6e-6 of
the parallelogram motion at rtol 1e-9 and 4.2e-7 at rtol 1e-10, against 4.3e-5 and 1.3e-5 without
the continuation (``separation=0``, which has also met step failures and energy jumps at later
crossings, depending on tolerance). The null space is taken at the state moved onto the manifold
by one Gauss–Newton step (:meth:`NullSpaceForm._motion_tangent`), not at the integrator's stage,
which lies off it by δ (~1e-11 at rtol 1e-11): the stage's own null vector turns by ~δ/σ_next,
which near a singular position and through f̄ = A_s⁺(−γ) put errors of up to 5e-5 into s̈, so that
the double four-bar's error over 10 s stopped falling with rtol (2.8e-7 at 1e-10, 8.6e-7 at
1e-11); from the manifold it falls 5–12× per decade from rtol 1e-6 to 1e-11 (1.2e-3 … 2.2e-8,
``benchmarks/iftomm.py``, the tolerances table). On the constraint manifold the rank of A_s can only drop below its value at a
regular q0 (at singular positions), never rise, so the n_s directions always exist (q0 must be a
regular configuration: its rank fixes n_s). Where the independent velocities stop describing the
motion (a crank at a dead centre, N_ind singular) the independent set is re-chosen as in :mod:`.partitioned`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.constraints.compiled import OWN_RULE, compiled_tangent, uncompiled
from projeq.system import Model
from projeq.constraints.matrices import (
    REPIVOT_CONDITION, independent_indices, minimum_norm_solution, numerical_rank, pivoted_columns,
)


# singular values of A_s below this fraction of the largest do not act in the particular solutions:
# the errors of the differences (~1e-11) divided by σ stay below ~1e-5 (m/s² per m/s²)
ACTING = 1e-6
# singular values of A_s below this fraction of the largest count as near-null: within this distance
# (relative) of a singular position, N continues the branch's tangent (TangentSystem._branch); far
# above the distance of integrator stages from the constraint manifold (~1e-4 at rtol 1e-9)
SEPARATION = 1e-2


class NullSpaceForm(Model):
    """The null-space form of a :class:`~projeq.constraints.partitioned.ConstrainedSystem`
    (module docstring): F spans the null space of the constraints, so that the model runs
    through singular positions and takes redundant constraints as they are. Mixed into
    :class:`~projeq.constraints.partitioned.TangentSystem`, the class a ConstrainedSystem
    becomes where it takes this form (a Model, so that an object can change between the two)."""

    _latest = (None, None)  # (key of (q, t), (C, c)) of the latest velocity_constraints call
    _svd = (None, None)  # (key of A_s, its SVD) of the latest decomposition
    _tangent = None  # N where the null space was last separated: the branch's tangent (_branch)

    def _choose_velocities(self, q0, independent, repivot) -> None:
        A_s = self.constraint_matrix(q0)[0]
        self.n_s = self.tree.n_s - numerical_rank(A_s)
        if independent is None:
            chosen = pivoted_columns(self._null_space(A_s).T, self.n_s)
        else:
            chosen = independent_indices(independent, self.n_s, self.tree.n_s, "the mobility at q0")
        self.independent, self.dependent = chosen, np.setdiff1d(np.arange(self.tree.n_s), chosen)
        self.repivot = independent is None if repivot is None else bool(repivot)
        self.check_configuration(q0, 0.0)
        self.limit = max(REPIVOT_CONDITION, 10 * self.condition(q0))

    def velocity_constraints(self, q: NDArray, t: float = 0.0) -> tuple[NDArray, NDArray]:
        """(C, c) of ConstrainedSystem, kept for the latest (q, t): the integrator asks for q̇ and
        s̈ at the same state, and both need them."""
        key = (np.asarray(q).tobytes(), np.asarray(q).dtype.str, complex(t))  # a complex step is another point
        if self._latest[0] != key:
            self._latest = (key, super().velocity_constraints(q, t))
        return self._latest[1]

    def _null_space(self, A_s: NDArray) -> NDArray:
        """N (n_s,tree × n_s) of A_s on the motion's branch (:meth:`_branch`), from the SVD of
        Re A_s; for A_s carrying a complex step, :func:`_null_space_step` of it."""
        if not A_s.size:
            return np.eye(self.tree.n_s)
        _, sigma, Vt = self._decomposition(np.real(A_s))
        N = self._branch(sigma, Vt)
        return _null_space_step(A_s, N, self.tree.n_s - self.n_s) if np.iscomplexobj(A_s) else N

    def _decomposition(self, A_s: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """The SVD (U, σ, Vᵀ) of a real A_s, kept for the latest A_s: F, f and f̄ of one state share it."""
        key = A_s.tobytes()
        if self._svd[0] != key:
            self._svd = (key, np.linalg.svd(A_s))
        return self._svd[1]

    def _branch(self, sigma: NDArray, Vt: NDArray) -> NDArray:
        """N from the SVD A_s = U Σ Vᵀ, continued along the motion (module docstring): the right
        singular vectors of the n_s smallest singular values where they are separated from the
        others (the next above ``separation`` σ_max; N is kept as the branch's tangent), else the
        tangent kept last, projected onto the k ≥ n_s right singular vectors below ``separation`` σ_max
        (the near-null space of a singular position) and orthonormalised."""
        n = self.tree.n_s
        sigma = np.concatenate((sigma, np.zeros(n - len(sigma))))  # σ of the columns beyond the rows: 0
        near = max(self.n_s, int(np.count_nonzero(sigma < self.separation * sigma[0])))
        if near == self.n_s or self._tangent is None:
            self._tangent = Vt[n - self.n_s:].T
            return self._tangent
        V_near = Vt[n - near:].T
        return np.linalg.qr(V_near @ (V_near.T @ self._tangent))[0]

    def _scaled(self, N: NDArray) -> NDArray:
        """F = N N_ind⁻¹ (F[independent] = E)."""
        F = np.linalg.solve(N[self.independent].T, N.T).T
        F[self.independent] = np.eye(self.n_s)
        return F

    def condition(self, q: NDArray, t: float = 0.0) -> float:
        """κ = 1/σ_min(N_ind) ≥ 1, ‖F‖₂ ≤ κ: how badly the independent velocities describe the motion
        (1 without any: a fully driven mechanism has no free motion to describe)."""
        if not self.n_s:
            return 1.0
        sigma = np.linalg.svd(self._null_space(self.constraint_matrix(q, t)[0])[self.independent],
                              compute_uv=False)
        return float(1.0 / sigma[-1]) if sigma[-1] > 0 else np.inf

    def check_configuration(self, q: NDArray, t: float = 0.0) -> None:
        """ValueError if the independent velocities cannot describe the motion at q (N_ind singular)."""
        if not self.condition(q, t) < 1e8:
            raise ValueError(
                f"independent: the velocities {self.independent.tolist()} cannot describe the motion at "
                f"q = {np.round(q, 6).tolist()}, t = {t:.6g} (they stand still while the mechanism moves); "
                "choose others (default: pivoted QR picks them at q0)"
            )

    def after_event(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> tuple:
        """Re-chosen independent velocities where N_ind degenerates (pivoted QR of N at q)."""
        if not self.repivot:
            self.check_configuration(q, t)
        chosen = pivoted_columns(self._null_space(self.constraint_matrix(q, t)[0]).T, self.n_s)
        new = self._in_partition(chosen, q, t)
        new.s_dot0 = self._tree_velocities_now(q, s_dot, t)[new.independent]
        return new, new.s_dot0.copy()

    def with_independent(self, independent, repivot: bool | None = None) -> "NullSpaceForm":
        """This system with the tree velocities ``independent`` as its minimal velocities."""
        new = self._in_partition(np.sort(np.asarray(independent)), self.q0)
        new.check_configuration(self.q0)
        new.s_dot0 = self.tree_velocities(self.q0, self.s_dot0)[new.independent]
        new.repivot = self.repivot if repivot is None else bool(repivot)
        return new

    def singular_positions(self):
        """An event for :func:`projeq.simulate` (``events=[system.singular_positions()]``, not
        terminal) that fires where ρ = σ_r / σ_max — the smallest of the r singular values of A_s
        that act at q0 (r its rank there), relative to the largest — has a minimum along the
        motion: its rate dρ/dt (:func:`ratio_rate`, exact: Ȧ_s by the complex step along
        (q̇, 1) through the constraint matrix) rises through zero. At a singular position ρ drops
        to zero with a kink, where the root is found. Pass the Result to :meth:`rank_changes` for
        the rank and mobility at the positions found."""
        acting = self.tree.n_s - self.n_s

        def constraint_matrix(x):
            return self.constraint_matrix(x[:-1], x[-1])[0]

        def singular_position(t, q, s_dot):
            x, v = np.append(q, t), np.append(self.q_dot(q, s_dot, t), 1.0)
            return ratio_rate(self.constraint_matrix(q, t)[0], self._d1(constraint_matrix, x, v), acting)

        singular_position.terminal, singular_position.direction = False, 1
        return singular_position

    def rank_changes(self, result, event: int = 0) -> tuple:
        """((t, rank, mobility), ...) where the event ``event`` of ``result`` (the index of
        :meth:`singular_positions` among the run's events) fired with the rank of A_s below its
        rank at q0: the singular positions the run passed, with the degrees of freedom there.
        (``result.rank`` and ``result.mobility`` hold them at every output time; the event finds
        the singular positions between the outputs.)"""
        rank0 = self.rank(self.q0)
        found = ((float(t), self.rank(q, t), self.mobility(q, t))
                 for t, q in zip(result.t_events[event], result.q_events[event]))
        return tuple(row for row in found if row[1] < rank0)

    def _compiled_rule(self):
        """The compiled kernel of the tangent space (:func:`projeq.constraints.compiled.tangent`),
        None (after one warning) for a subclass that forms F by its own rule."""
        if type(self).F is not NullSpaceForm.F or type(self).particular is not NullSpaceForm.particular:
            return uncompiled(self, OWN_RULE)
        return compiled_tangent(self, ACTING)

    def F(self, q: NDArray, t: float = 0.0, constraint_matrix=None) -> tuple[NDArray, NDArray]:
        """(F, f) of ṡ_tree = F ṡ + f: F = N N_ind⁻¹ with N the motion's tangent at q
        (:meth:`_motion_tangent`), f the particular solution of A_s f = b_s with f[independent] = 0
        (module docstring)."""
        A_s, b_s = self.constraint_matrix(q, t) if constraint_matrix is None else constraint_matrix
        self._tangent_of = (A_s, self._motion_tangent(q, t, A_s))
        return self._scaled(self._tangent_of[1]), self.particular(A_s, b_s)

    _tangent_of = (None, None)  # (A_s, N) of the latest F: particular's f̄ at the same state takes its N

    def _motion_tangent(self, q: NDArray, t: float, A_s: NDArray) -> NDArray:
        """N (:meth:`_null_space`) of the constraint matrix at q* = q − A_s⁺ [Φ(q); 0], the state moved
        onto the constraint manifold by one Gauss–Newton step (K = E; else along Φ_q⁺ and normalised),
        not of A_s at q itself: an integrator's stage lies off the manifold by δ (~1e-11 at rtol 1e-11),
        and the null vector of A_s there turns by ~δ/σ_next from the motion's, which near a singular
        position (σ_next small) and through f̄ = A_s⁺(−γ) gave accelerations off by up to 5e-5 on the
        double four-bar and an error that stopped falling with rtol (module docstring). At q itself
        where q is on the manifold. Complex-safe (the step's pseudo-inverse is differentiated exactly,
        :func:`~projeq.constraints.matrices.minimum_norm_solution`): the exact Jacobian is that of this
        rule, as differences see it."""
        if not self.m_h:
            return self._null_space(A_s)
        values = self.phi(q, t)
        if not np.any(values):
            return self._null_space(A_s)
        rank = self.tree.n_s - self.n_s
        if self._identity:
            q_star = q - minimum_norm_solution(A_s, np.concatenate((values, np.zeros(self.m_p))), ACTING, rank)
        else:
            q_star = self.tree.normalized(q - minimum_norm_solution(self.phi_q(q, t), values, ACTING))
        # past velocity_constraints' cache, which keeps (C, c) at q for q̇ and s̈ of the same state
        C, c = super(NullSpaceForm, self).velocity_constraints(q_star, t)
        return self._null_space(self._in_tree_velocities(q_star, t, C, c)[0])

    def particular(self, A_s: NDArray, c: NDArray) -> NDArray:
        """x₀ − F x₀[independent] with x₀ = A_s⁺ c, the pseudo-inverse over the largest
        n_s,tree − n_s singular values (the rank at q0) above ACTING σ_max, F that of :meth:`F` at the
        same A_s (else from its null space): A_s x = c with x[independent] = 0, where A_s x = c can hold."""
        if not A_s.size:
            return np.zeros(self.tree.n_s)
        x0 = minimum_norm_solution(A_s, c, ACTING, rank=self.tree.n_s - self.n_s)
        kept, N = self._tangent_of  # one read: another thread may replace it
        return x0 - self._scaled(N if kept is A_s else self._null_space(A_s)) @ x0[self.independent]

    def __repr__(self) -> str:
        return (f"ConstrainedSystem(n_q={self.n_q}, n_s={self.n_s}, {self.m_h} holonomic, {self.m_p} Pfaffian, "
                f"null-space form)")


def ratio_rate(A: NDArray, A_dot: NDArray, r: int) -> float:
    """dρ/dt of ρ = σ_r / σ_1, the r-th singular value of A(t) relative to the largest, from
    Ȧ: σ̇_i = u_iᵀ Ȧ v_i for a simple singular value σ_i > 0 with singular vectors u_i, v_i
    (Stewart & Sun, "Matrix Perturbation Theory", 1990, §IV.4; the first-order term of
    σ_i(A + ε Ȧ)), so dρ/dt = (σ̇_r − ρ σ̇_1) / σ_1."""
    U, sigma, Vt = np.linalg.svd(A)
    pair = [0, r - 1]
    rates = np.einsum("ij,ij->i", U[:, pair].T @ A_dot, Vt[pair])
    return float((rates[1] - sigma[r - 1] / sigma[0] * rates[0]) / sigma[0])


def _null_space_step(A_s: NDArray, N: NDArray, rank: int) -> NDArray:
    """The null-space basis N₀ of Re A_s (real SVD) carried to A_s = A₀ + i A₁ (a complex
    step, |A₁| ~ 1e-30) by one Newton step, N = N₀ − A₀⁺ (A_s N₀) = N₀ − i A₀⁺ A₁ N₀ (A₀⁺ over
    the ``rank`` largest singular values): A_s N = O(|A₁|²) where the rank of A_s is constant
    (redundant rows included: their left null vectors u satisfy uᵀ A₁ N₀ = 0), the
    normalisation N₀ᵀ dN = 0. F = N N_ind⁻¹ is then analytic in the step, and the complex step
    through it gives ∂F exactly (the SVD's own rotations conjugate; issue 16)."""
    return N - minimum_norm_solution(np.real(A_s), A_s @ N, ACTING, rank)

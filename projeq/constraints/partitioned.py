"""Constraints given as equations: closed loops and Pfaffian constraints on a tree (docs/theory.md §7).

A tree :class:`~projeq.System` keeps its own (now redundant) coordinates q and velocities
ṡ_tree; the user adds holonomic constraints Φ(q, t) = 0 and/or Pfaffian ones
A(q, t) q̇ = b(q, t). With q̇ = K ṡ_tree + k they read, at velocity level,

    C K ṡ_tree = c − C k,    C = [∂Φ/∂q; A],  c = [−∂Φ/∂t; b]         (A_s ṡ_tree = b_s)

and, differentiated once more with s̈_tree = 0 frozen, A_s s̈_tree = −γ. Coordinate
partitioning into independent and dependent velocities gives the minimal velocities ṡ:

    ṡ_tree = F ṡ + f,  F = [E; −A_dep⁻¹ A_ind] (rows permuted),  f = [0; A_dep⁻¹ b_s]
    s̈_tree = F s̈ + f̄,  f̄ = [0; −A_dep⁻¹ γ]

and the Projection Equation with the constraint inserted before the projection is

    Fᵀ (M_tree (F s̈ + f̄) + b_tree) = 0.

Derivatives of Φ, A and b (no user Jacobians needed) are taken by the complex step, exact to
round-off, if the callables take complex arguments (numpy functions do; ``exact`` says which),
else by a sixth-order central stencil. The second derivative in γ is the complex step inside a
sixth-order stencil on normalised directions, ≈ 1e-14 relative whatever the speed
(:meth:`~ConstrainedSystem.gamma`; issue 16: fixed-step differences lost the accuracy of slow
motions, 6e-3 relative at 1/1000 of the four-bar's rates). A Φ written with numpy operations on the
rows q[i] is evaluated at all points of a stencil in one call (:mod:`projeq.constraints.batched`,
the same stencils; checked once at q0, else point by point after a warning naming Φ); under
``correction="projection"`` Φ independent of t (checked at q0 and around it) spares ∂Φ/∂t and the
rheonomic parts of Φ″ (a Φ that depends on t — a cut joint across a joint prescribed in time, a
driven mechanism — has them, their stencils along t scaled by Φ's rate in t), and where every
tree joint has q̇ = ṡ_tree (K = E) neither are K, k nor K̇.
Position drift of the loop closures Φ = 0 is corrected either by a
Gauss–Newton projection of q onto Φ = 0 wherever :func:`projeq.simulate` normalises q
(segment ends and outputs; ``correction="projection"``, the default) or by Baumgarte's
first-order stabilisation q̇ += −β C_Φ⁺ Φ (``correction="baumgarte"``), or not at all
(``"none"``). ``Result.constraint_residual`` holds (Φ, A q̇ − b) along the run.

Re-pivoting. A partition good at q0 may degenerate later (a four-bar's rocker angle as the
independent coordinate at the rocker's extreme positions, where dq_rocker/dq_crank = 0).
With ``repivot`` (the default when the partition is chosen automatically) the partition
carries a limit on its condition number κ = ‖A_s‖₂ ‖A_dep⁻¹‖₂ (≥ cond(A_dep); unlike
cond(A_dep) it also sees a 1 × 1 block shrink to zero), max(REPIVOT_CONDITION, 10 κ at its
start), and :func:`projeq.simulate` stops the integration by a terminal event where κ rises
through it (:meth:`~ConstrainedSystem.events`), re-partitions by pivoted QR at the current q
(:meth:`~ConstrainedSystem.after_event`, ṡ_new = (F_old ṡ_old + f_old)[independent_new], the
same tree velocities) and continues.
``Result.partitions`` lists (t_k, independent_k): the ``s_dot`` rows at times t with
t_k < t ≤ t_k+1 are the tree velocities independent_k (the first partition also holds at
t_start); energies and constraint residuals are computed in each row's own partition.
Where the constraint rows themselves become nearly dependent at the event (cond(A_s) above a
tenth of the limit: every partition is as bad, a singular position of the mechanism such as
links coming into line) re-pivoting would carry on along another branch of the motion: the run
goes on from there in the null-space form (:class:`TangentSystem`, its branch started along
the partition's F there; :meth:`~ConstrainedSystem.after_event`), which runs through, and
``Result.partitions`` records the switch. Rows redundant along the whole motion (Bricard's
mechanism) or nearly dependent at q0 take that form from the start (``formulation``).
A user-fixed partition (``repivot=False``) stops the run at the same event with a
ValueError naming (q, t): integrated on, the solver could step across the degeneracy
(where ṡ_tree = F ṡ is ∞ · 0) and lose accuracy silently.

Evaluators. The projection Fᵀ M F needs the tree's mass matrix M and b of its Gauss form
(:meth:`ConstrainedSystem.tree_gauss_form`). By default (``method=None``) both come from the
compiled kernels where the tree's default evaluator is the compiled one
(:meth:`projeq.assembly.fast.FastEvaluator.gauss_form`: composite bodies and Newton–Euler
in numba), else from the dense reference (docs/theory.md §5), after one
:class:`~projeq.assembly.auto.InterpretedWarning` naming the piece of the tree the kernel does
not know; ``method="dense"`` takes the dense reference, and so does a complex argument (the
complex step of :mod:`projeq.analysis.jacobians`: the compiled kernels are real). With
``method="recursive"`` or ``"fast"`` b comes from that evaluator's free accelerations of the
tree, M s̈_free + b = 0, so that M s̈_tree + b = M (s̈_tree − s̈_free): all agree to round-off
(a cross-check of the tree's evaluators in the constrained motion). The constraint equations
Φ, A and b are the user's Python callables, evaluated and differentiated as such.
"""

from __future__ import annotations

import copy
import warnings
from numbers import Real

import numpy as np
from numpy.typing import NDArray

from projeq.assembly.linalg import solve_spd
from projeq.constraints.batched import batched_closure, time_rate
from projeq.constraints.compiled import OWN_RULE, compiled_cut_joints, compiled_partition, uncompiled, unsupported
from projeq.constraints.cut_joints import cut_joints, point_rows
from projeq.constraints.matrices import (
    RANK_TOLERANCE, REPIVOT_CONDITION, independent_indices, minimum_norm_solution, numerical_rank, pivoted_columns,
)
from projeq.constraints.tangent import SEPARATION, NullSpaceForm
from projeq.checks import depends_on_t, finite_result, kernel_state, positive, state_vector
from projeq.analysis.differentiation import (MIXED_STEP, complex_failure, derivative_along,
                                             derivative_along_differences, second_derivative_along,
                                             second_derivative_along_differences, warn_differences)
from projeq.joints import Joint
from projeq.spatial import numeric
from projeq.system import Model

CORRECTIONS = ("projection", "baumgarte", "none")
# the forms of the minimal velocities: chosen at construction ("auto"), or as the user says
FORMULATIONS = ("auto", "partitioned", "null_space")
# condition number κ = ‖A_s‖ ‖A_dep⁻¹‖ above which the partition is degenerate
PARTITION_CONDITION = 1e8
# |Φ| (relative to the largest coordinate, at least 1) accepted as on the manifold: 1e4 × round-off
POSITION_TOLERANCE = 1e-12
# Gauss–Newton evaluations of Φ that project may take onto Φ = 0
PROJECTION_STEPS = 20


class RedundantRowWarning(UserWarning):
    """A constraint row that is zero at and around q0 (value and gradient): it constrains nothing and
    is taken as redundant."""


class ConstrainedSystem(Model):
    """A tree System with constraint equations, in minimal velocities by coordinate partitioning.

    A :class:`~projeq.system.Model` like a System: ``accelerations(q, s_dot, t, method=...)``,
    ``gauss_form``, ``energy``, ``q_dot`` and the rest take and give the minimal velocities ṡ.

    Parameters
    ----------
    system : System
        The tree (cut the loops open: each closing joint becomes a constraint).
    phi : callable ``phi(q, t) -> (m_h,)``, or a list of PinClosure, optional
        Holonomic constraints Φ(q, t) = 0 (loop closures); a list of cut joints
        (:class:`~projeq.constraints.cut_joints.PinClosure`) stacks their closures.
    A, b : callables ``A(q, t) -> (m_p, n_q)``, ``b(q, t) -> (m_p,)``, optional
        Pfaffian constraints A q̇ = b (b defaults to 0).
    independent : sequence of int, optional
        Indices of ṡ_tree kept as minimal velocities ṡ; default: chosen by column-pivoted
        QR of A_s at q0 (the best-conditioned dependent block).
    q0 : array, optional
        Initial coordinates (default: the tree's q0); must satisfy Φ(q0) = 0 unless
        ``project_q0`` is set, which moves it onto Φ = 0 by Gauss–Newton.
    s_dot0 : array, optional
        Initial minimal velocities (default zero); consistent by construction.
    correction : "projection", "baumgarte" or "none"
        Position-drift correction of Φ = 0 (see the module docstring); ``beta`` (1/s) is
        Baumgarte's rate.
    repivot : bool, optional
        Re-choose the partition during a run when it degenerates (module docstring);
        default: True for the automatic partition, False for a user-fixed ``independent``
        (then a run stops with an error naming the configuration where κ reaches
        the limit, rather than lose accuracy silently).
    formulation : "auto", "partitioned" or "null_space"
        How the minimal velocities are formed (docs/theory.md §7). "auto" (the default)
        partitions the tree velocities where the constraint rows are independent on the
        constraint surface and well conditioned at q0 (the cheaper form, measured in
        ``benchmarks/iftomm.py``), and takes the null-space form
        (:class:`TangentSystem`) where rows are redundant along the motion (Bricard's
        mechanism) or nearly dependent at q0; a run that meets a singular position (links
        coming into line) goes on in the null-space form from there (``Result.partitions``
        records it). "partitioned" refuses redundant rows; "null_space" takes that form
        throughout. ``redundant`` lists the rows found redundant (their multipliers are the
        minimum-norm solution, :meth:`accelerations_tree`).
    separation : float
        The null-space form's continuation of the branch near singular positions
        (:class:`TangentSystem`; default SEPARATION).

    Examples
    --------
    A point mass on two sliders kept on a circle of radius 1 (a pendulum):

    >>> import numpy as np, projeq as pq
    >>> from projeq.constraints.partitioned import ConstrainedSystem
    >>> tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
    ...     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")},
    ...     gravity=(0, 0, -9.81))
    >>> pendulum = ConstrainedSystem(tree, phi=lambda q, t: [np.hypot(q[0], q[1]) - 1.0],
    ...                              q0=[0.6, -0.8], independent=[0])
    >>> pendulum.n_s
    1
    >>> r = pq.simulate(pendulum, 0.2, n_points=5, n_segments=2)
    >>> bool(np.abs(r.constraint_residual).max() < 1e-10)
    True
    """

    limit = REPIVOT_CONDITION  # κ of the partition that triggers re-pivoting; per partition once chosen
    formulation = "partitioned"  # the form of the minimal velocities (TangentSystem: "null space")

    def __init__(self, system, phi=None, A=None, b=None, independent=None, q0=None, s_dot0=None,
                 project_q0: bool = False, correction: str = "projection", beta: float = 10.0,
                 repivot: bool | None = None, formulation: str = "auto", separation: float = SEPARATION):
        if phi is None and A is None:
            raise ValueError("phi: give holonomic constraints phi(q, t) and/or Pfaffian ones A(q, t)")
        phi = cut_joints(phi)
        if point_rows(phi) is not None and phi.tree is not system:
            raise ValueError("phi: the cut joints hold points of another tree's bodies (PinClosure(tree, ...) "
                             "takes the tree given to ConstrainedSystem)")
        for name, f in (("phi", phi), ("A", A), ("b", b)):
            if f is not None and not callable(f):
                raise ValueError(f"{name}: expected a callable {name}(q, t), got {f!r}")
        if b is not None and A is None:
            raise ValueError("b: given without A (Pfaffian constraints are A(q, t) q̇ = b(q, t))")
        if correction not in CORRECTIONS:
            raise ValueError(f"correction: unknown method {correction!r}; use one of {list(CORRECTIONS)}")
        if formulation not in FORMULATIONS:
            raise ValueError(f"formulation: unknown form {formulation!r}; use one of {list(FORMULATIONS)}")
        if isinstance(separation, bool) or not isinstance(separation, Real) or not 0.0 <= separation < 1.0:
            raise ValueError(f"separation: expected a fraction of the largest singular value in [0, 1) "
                             f"(0: no continuation of the branch), got {separation!r}")
        self.separation = float(separation)
        self.tree, self._phi, self._A, self._b = system, phi, A, b
        self.correction, self.beta = correction, positive("beta", beta)
        self.names, self.subsystems, self.n_q = system.names, system.subsystems, system.n_q
        # q̇ = ṡ_tree for every joint (revolute, prismatic, elastic coordinates): K = E, k = 0, K̇ = 0
        self._identity = len(system._identity_q) == system.n_q == system.n_s
        q0 = system.check_q("q0", system.q0 if q0 is None else q0)
        self.m_h = self._constraint_rows("phi", phi, (q0, 0.0), 1)
        self.m_p = self._constraint_rows("A", A, (q0, 0.0), 2)
        if b is not None:
            self._constraint_rows("b", b, (q0, 0.0), 1, self.m_p)
        self.n_c = self.n_lambda = self.m_h + self.m_p
        self.exact = self._choose_derivatives(q0)
        # Φ's derivatives from one call at a batch of points (projeq.constraints.batched); cut joints
        # have compiled rows of their own once the system is built (_cut_joint_rows), else pointwise
        self._closure = batched_closure(phi, self.n_q, np.append(q0, 0.0), self.m_h) \
            if self.exact and self.m_h and point_rows(phi) is None else None
        # Φ(q, t) through a joint prescribed in time (a driven mechanism) or, with Baumgarte's correction, any
        # Φ: ∂Φ/∂t and the rheonomic parts of Φ″ are evaluated; else Φ(q) alone, whose are 0
        self.rheonomic = correction != "projection" or bool(self.m_h and depends_on_t(self.phi, q0))
        self._choose_form(q0, formulation, independent)
        self._choose_velocities(q0, independent, repivot)
        self.q0 = self._initial_q(q0, project_q0)
        self.s_dot0 = state_vector("s_dot0", np.zeros(self.n_s) if s_dot0 is None else s_dot0, self.n_s)
        self._cut_rows = False if point_rows(phi) is not None else None  # looked for once built (_cut_joint_rows)

    # -- the constraint functions -----------------------------------------------------------
    def _constraint_rows(self, name, f, args, ndim, n_cols=None) -> int:
        if f is None:
            return 0
        try:
            value = np.asarray(f(*args), dtype=float)
        except (TypeError, ValueError) as error:  # rows of different shapes, or not numbers
            raise ValueError(f"{name}: returns no array of numbers at q0 ({error})") from None
        expected = (n_cols,) if n_cols is not None else ((None, self.n_q) if ndim == 2 else (None,))
        if value.ndim != ndim or (ndim == 2 and value.shape[1] != self.n_q) or (
            n_cols is not None and value.shape != expected
        ):
            want = {1: "(m,)", 2: f"(m, n_q = {self.n_q})"}[ndim] if n_cols is None else f"({n_cols},)"
            raise ValueError(f"{name}: returns an array of shape {value.shape}, expected {want}")
        if not np.all(np.isfinite(value)):
            raise ValueError(f"{name}: returns non-finite values {value.tolist()} at q0")
        return value.shape[0]

    def _choose_derivatives(self, q0) -> bool:
        """The derivatives of Φ, A and b: by the complex step (exact to round-off) if the
        callables take complex arguments, else by Richardson's stencils (``exact`` False), with
        one :class:`~projeq.analysis.differentiation.DifferencesWarning` per callable that cannot."""
        given = {name: f for name, f in (("phi", self._phi), ("A", self._A), ("b", self._b)) if f is not None}
        failures = {name: complex_failure(lambda x, f=f: f(x[:-1], x[-1].real), np.append(q0, 0.0))
                    for name, f in given.items()}
        for name, failure in failures.items():
            if failure is not None:
                warn_differences(name, getattr(given[name], "__qualname__", repr(given[name])), failure)
        exact = not any(failures.values())
        self._d1 = derivative_along if exact else derivative_along_differences
        self._d2 = second_derivative_along if exact else second_derivative_along_differences
        return exact

    def phi(self, q: NDArray, t: float = 0.0) -> NDArray:
        """Φ(q, t), the holonomic constraints (empty without any)."""
        if not self.m_h:
            return np.zeros(0)
        rows = self._cut_joint_rows()
        if rows is not None and (rows.complex_safe or not np.iscomplexobj(q)):
            return rows.values(q, t)
        try:
            value = numeric(self._phi(q, t))
        except ValueError as error:  # rows of different shapes
            raise ValueError(f"phi: returns rows numpy cannot stack at t = {np.real(t):.6g} ({error})") from None
        if value.shape != (self.m_h,):
            raise ValueError(f"phi: returns shape {value.shape} at t = {np.real(t):.6g}, {(self.m_h,)} at q0: the "
                             "number of constraint rows must not change during a run")
        return value

    _cut_rows = None  # CutJointRows; None: Φ is not made of cut joints, or they do not compile; False: not looked for

    def _cut_joint_rows(self):
        """The compiled Φ, Φ_q and Φ″ of cut joints (:class:`~projeq.constraints.compiled.CutJointRows`),
        where Φ is made of them and the tree's kinematics compile (looked for once the system is
        built), else None."""
        if self._cut_rows is False:
            self._cut_rows = compiled_cut_joints(self)
        return self._cut_rows

    def _batched(self):
        """What gives Φ's derivatives at a batch of points (real arguments): the compiled cut joints'
        rows, the batched closure, or None (pointwise)."""
        rows = self._cut_joint_rows()
        return self._closure if rows is None else rows

    def _pfaffian(self, q, t) -> tuple[NDArray, NDArray]:
        if not self.m_p:
            return np.zeros((0, self.n_q)), np.zeros(0)
        b = np.zeros(self.m_p) if self._b is None else numeric(self._b(q, t))
        return numeric(self._A(q, t)), b

    def _phi_x(self, x: NDArray) -> NDArray:
        """Φ at x = (q, t)."""
        return self.phi(x[:-1], x[-1])

    def phi_q(self, q: NDArray, t: float = 0.0) -> NDArray:
        """∂Φ/∂q (m_h × n_q), column i = Φ′ along e_i (module docstring)."""
        return self._phi_derivatives(q, t)[0]

    def _phi_derivatives(self, q: NDArray, t: float) -> tuple[NDArray, NDArray]:
        """(∂Φ/∂q, ∂Φ/∂t): column j of Φ_x = Φ′ along e_j at x = (q, t), all from one call at a
        batch of points where Φ takes them (:mod:`projeq.constraints.batched`, real arguments)."""
        x = np.append(q, t)
        if not self.m_h:
            return np.zeros((0, self.n_q)), np.zeros(0)
        n = self.n_q + self.rheonomic  # the columns along q, and along t if Φ depends on it
        batched = self._batched()
        if batched is not None and (batched.complex_safe or not np.iscomplexobj(x)):
            Phi_x = batched.jacobian(x, n)
        else:
            Phi_x = np.array([self._d1(self._phi_x, x, e) for e in np.eye(self.n_q + 1)[:n]]).T.reshape(self.m_h, n)
        return Phi_x[:, :self.n_q], (Phi_x[:, -1] if self.rheonomic else np.zeros(self.m_h, dtype=Phi_x.dtype))

    def velocity_constraints(self, q: NDArray, t: float = 0.0) -> tuple[NDArray, NDArray]:
        """(C, c) of C q̇ = c: C = [∂Φ/∂q; A], c = [−∂Φ/∂t; b]."""
        A, b = self._pfaffian(q, t)
        Phi_q, Phi_t = self._phi_derivatives(q, t)
        return np.vstack((Phi_q, A)), np.concatenate((-Phi_t, b))

    def constraint_residual(self, q: NDArray, q_dot: NDArray, t: float = 0.0) -> NDArray:
        """(Φ(q, t), A q̇ − b): loop closures at position level, Pfaffian ones at velocity level."""
        A, b = self._pfaffian(q, t)
        return np.concatenate((self.phi(q, t), A @ q_dot - b))

    # -- partition --------------------------------------------------------------------------
    def _choose_velocities(self, q0, independent, repivot) -> None:
        """The minimal velocities: the partition (checked at q0) and its re-pivoting limit."""
        self.repivot = independent is None if repivot is None else _check_repivot(repivot)
        self.independent, self.dependent = self._partition(q0, independent)
        self.n_s = len(self.independent)
        self.limit = max(REPIVOT_CONDITION, 10 * self.condition(q0))

    def constraint_matrix(self, q: NDArray, t: float = 0.0) -> tuple[NDArray, NDArray]:
        """(A_s, b_s) of A_s ṡ_tree = b_s: A_s = C K, b_s = c − C k (C, c themselves where K = E, k = 0)."""
        return self._in_tree_velocities(q, t, *self.velocity_constraints(q, t))

    def _in_tree_velocities(self, q: NDArray, t: float, C: NDArray, c: NDArray) -> tuple[NDArray, NDArray]:
        """(A_s, b_s) = (C K, c − C k) from (C, c) at (q, t); ValueError naming q where they are not
        finite (a non-finite state, or one whose constraint rows overflow), before any factorisation."""
        if not np.isfinite(C).all():
            raise ValueError(f"q: the constraint matrix is not finite at q = {np.round(np.real(q), 6).tolist()}, "
                             f"t = {np.real(t):.6g} (a non-finite state, or one outside any range the constraints "
                             "describe)")
        if self._identity:
            return C, c
        return C @ self.tree.K(q, t), c - C @ self.tree.q_dot(q, np.zeros(self.tree.n_s), t)

    redundant = ()  # rows that depend on the others along the motion (found at construction, _rows_on_surface)

    def _choose_form(self, q0, formulation: str, independent) -> None:
        """The form of the minimal velocities (the ``formulation`` parameter): a ConstrainedSystem
        partitions where the rows are independent on the constraint surface and well conditioned at
        q0, else takes the null-space form (:class:`TangentSystem`, into which it turns); a subclass
        keeps its own (AugmentedSystem's tree velocities; a user's), partitioned ones refusing
        redundant rows."""
        self.redundant = self._rows_on_surface(q0)
        self.automatic = formulation == "auto"  # goes on in the null-space form from a singular position
        if isinstance(self, NullSpaceForm):
            return
        if type(self) is ConstrainedSystem and formulation != "partitioned" and (
                formulation == "null_space" or self.redundant
                or (independent is None and not self._well_conditioned(q0))):
            self.__class__ = TangentSystem
        elif type(self)._choose_velocities is ConstrainedSystem._choose_velocities:
            if self.redundant:
                raise ValueError(
                    f"phi: rows {list(self.redundant)} depend on the others along the motion (the rank of the "
                    f"constraints is {self.n_c - len(self.redundant)} of {self.n_c} at q0 and on the constraint surface "
                    "around it); formulation='partitioned' needs independent rows: remove them, or leave "
                    "formulation at its default, which takes redundant rows as they are")
            if self.n_c > self.tree.n_s:
                raise ValueError(f"phi: {self.n_c} constraints on only {self.tree.n_s} tree velocities")

    def _well_conditioned(self, q0) -> bool:
        """Whether the rows are far from a singular position at q0: σ_min ≥ σ_max / REPIVOT_CONDITION
        of A_s (every partition's κ ≥ cond(A_s) would start at the re-pivoting limit otherwise)."""
        sigma = np.linalg.svd(self.constraint_matrix(q0)[0], compute_uv=False)
        return not sigma.size or sigma[-1] * REPIVOT_CONDITION >= sigma[0]

    def _rows_on_surface(self, q0) -> tuple:
        """The rows that depend on those before them at q0 and on the constraint surface around it
        (redundant along the motion); ValueError naming phi (or A) and the cause for a row whose
        gradient vanishes at q0, and naming q0 where rows lose rank only there (a singular position)."""
        A_s = self.constraint_matrix(q0)[0]
        if not np.all(np.isfinite(A_s)):
            raise ValueError(f"phi: the constraint derivatives are not finite at q0 = {np.round(q0, 6).tolist()}")
        tol = 1e-9 * max(np.abs(A_s).max(initial=0.0), 1.0)  # far above round-off, far below a real row
        for i in np.flatnonzero(np.abs(A_s).max(axis=1, initial=0.0) <= tol):
            self._vanishing_row(int(i), q0, tol)
        redundant = _dependent_rows(A_s, tol)
        if not redundant:
            return ()
        nearby = self._nearby_on_surface(q0)
        if all(len(_dependent_rows(self.constraint_matrix(q)[0], tol)) < len(redundant) for q in nearby):
            raise ValueError(
                f"q0: a singular position of the constraints (rank {self.n_c - len(redundant)} of {self.n_c} at "
                f"q0 = {np.round(q0, 6).tolist()}, {self.n_c} on the constraint surface around it): rows "
                f"{redundant} lose their direction here (a dead-centre or aligned-links position), so the "
                "mobility at q0 is not the mechanism's; start the mechanism away from it")
        return tuple(redundant)

    def _nearby_on_surface(self, q0, count: int = 2) -> list:
        """``count`` points 1e-3 from q0, moved onto Φ(q, 0) = 0 (the constraint surface, where the rank
        of redundant rows stays low: off it they are independent); those that cannot be moved there
        are left out."""
        rng, points = np.random.default_rng(1), []
        for _ in range(count):
            q = self.tree.normalized(q0 + 1e-3 * rng.standard_normal(len(q0)))
            try:
                points.append(self.project(q) if self.m_h else q)
            except ValueError:
                continue
        return points

    def _vanishing_row(self, i: int, q0, tol: float) -> None:
        """Row i of the constraints, whose gradient vanishes at q0: a Φ row zero around q0 too
        constrains nothing (a RedundantRowWarning: taken as redundant); ValueError for a row of A,
        a Φ row with a saddle at q0 (its surface branches: a singular position), with an extremum
        (its solutions are isolated: the mechanism cannot move), or one only stationary there
        (curvature of one sign, some zero)."""
        where = f"q0 = {np.round(q0, 6).tolist()}"
        if i >= self.m_h:
            raise ValueError(f"A: row {i - self.m_h} vanishes at {where}: it constrains no velocity there; "
                             "remove it, or start where it acts")
        hessian = self._phi_hessian(i, q0)
        if np.abs(hessian).max(initial=0.0) <= tol and all(
                abs(self.phi(q)[i]) <= tol for q in q0 + 1e-2 * np.random.default_rng(2).standard_normal((3, len(q0)))):
            warnings.warn(f"phi: row {i} is zero at and around {where} (value and gradient): it constrains nothing "
                          "and is taken as a redundant row (the z row of a planar mechanism's pin, say); remove it "
                          "to spare its work", RedundantRowWarning, stacklevel=5)
            return
        curvature = np.linalg.eigvalsh((hessian + hessian.T) / 2)
        if curvature[0] < -tol and curvature[-1] > tol:
            raise ValueError(
                f"q0: a singular position of the constraints: Φ[{i}]'s gradient vanishes at {where}, where "
                f"the surface Φ[{i}] = 0 branches (like x z = 0 at the origin, two lines crossing), so the motion's "
                "directions are not determined there; start the mechanism away from it")
        if curvature[0] * curvature[-1] > 0 and min(abs(curvature[0]), abs(curvature[-1])) > tol:
            raise ValueError(
                f"phi: row {i} holds only at isolated points around {where}: Φ[{i}] has a "
                f"{'minimum' if curvature[0] > 0 else 'maximum'} there and its gradient vanishes (like a two-link "
                "arm stretched to its full reach), so no motion keeps it; it fixes every coordinate, not a "
                "degree of freedom: write the constraints the mechanism holds, or start where it can move")
        raise ValueError(
            f"phi: row {i}'s gradient ∂Φ[{i}]/∂q vanishes at {where}: Φ[{i}] is stationary there, so it fixes "
            "coordinates only to second order (like 1 − cos q = 0 at q = 0) and its velocity constraint is "
            "empty; write it with a gradient that does not vanish (q = 0), or start where it does not")

    def _phi_hessian(self, i: int, q0) -> NDArray:
        """∂²Φ[i]/∂q² at q0 by central differences of the exact first derivatives (step 1e-5):
        enough to tell the sign of its curvature."""
        h, n = 1e-5, self.n_q
        columns = [(self.phi_q(q0 + h * e)[i] - self.phi_q(q0 - h * e)[i]) / (2 * h) for e in np.eye(n)]
        return np.array(columns).T

    def _partition(self, q0, independent) -> tuple[NDArray, NDArray]:
        n_s = self.tree.n_s
        A_s = self.constraint_matrix(q0)[0]
        if independent is None:
            dependent = pivoted_columns(A_s, self.n_c)
        else:
            why = f"n_s = {n_s} minus {self.n_c} constraints"
            chosen = independent_indices(independent, n_s - self.n_c, n_s, why)
            dependent = np.setdiff1d(np.arange(n_s), chosen)
        free = np.setdiff1d(np.arange(n_s), dependent)
        self.independent, self.dependent = free, dependent
        self.check_configuration(q0, 0.0)
        return free, dependent

    def check_configuration(self, q: NDArray, t: float = 0.0) -> None:
        """Raise ValueError if the dependent block A_dep is singular at q (the partition
        degenerates: choose another ``independent`` set)."""
        self._check_dependent(self.constraint_matrix(q, t)[0], q, t)

    def condition(self, q: NDArray, t: float = 0.0) -> float:
        """κ = ‖A_s‖₂ ‖A_dep⁻¹‖₂ at (q, t), the condition number of the partition (1 without
        constraints, ∞ for a singular A_dep): ‖F‖ ≤ κ bounds the gain from ṡ to ṡ_tree."""
        return _partition_condition(self.constraint_matrix(q, t)[0], self.dependent)

    @property
    def partition(self) -> tuple:
        """The independent tree velocities: ṡ = ṡ_tree[partition]."""
        return tuple(self.independent.tolist())

    def events(self) -> tuple:
        """The terminal event ``event(t, q, s_dot) = κ − limit`` (rising) at which
        :func:`projeq.simulate` calls :meth:`after_event` (none without constraints)."""
        if not self.n_c:
            return ()

        def degenerates(t, q, s_dot):
            return self.condition(q, t) - self.limit

        degenerates.terminal, degenerates.direction = True, 1
        return (degenerates,)

    def after_event(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> tuple["ConstrainedSystem", NDArray]:
        """Re-partitioned where the partition degenerates: (system, s_dot) in the partition
        pivoted QR picks at (q, t), the same tree, the same tree velocities
        ṡ_tree = F_old ṡ_old + f_old, ṡ_new = ṡ_tree[independent_new]; the new system
        starts at (q, ṡ_new). Without ``repivot``: ValueError naming (q, t)."""
        if self._near_dependent(q, t) and self.automatic:  # a singular position: every partition is as bad
            return self._in_null_space(q, s_dot, t)
        if not self.repivot:
            raise self._degenerate(q, t, self.condition(q, t), self.limit)
        if self._near_dependent(q, t):  # re-pivoting here would carry on along another branch, silently
            raise self._singular_position(q, t)
        dependent = pivoted_columns(self.constraint_matrix(q, t)[0], self.n_c)
        new = self._in_partition(np.setdiff1d(np.arange(self.tree.n_s), dependent), q, t)
        new.s_dot0 = self._tree_velocities_now(q, s_dot, t)[new.independent]
        return new, new.s_dot0.copy()

    def _tree_velocities_now(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        """ṡ_tree = F ṡ + f at (q, t) where the partition changes: by the compiled kernel where the run built
        it (:meth:`~projeq.constraints.compiled.CompiledClosure.tree_velocities`, one call), else by
        :meth:`tree_velocities` (also where the kernel flags: it names why)."""
        found = self._compiled.tree_velocities(self, q, s_dot, t) if self._compiled else None
        return self.tree_velocities(q, s_dot, t) if found is None else found

    def _in_null_space(self, q: NDArray, s_dot: NDArray, t: float) -> tuple["TangentSystem", NDArray]:
        """(system, s_dot) going on from a singular position in the null-space form: a copy that is a
        :class:`TangentSystem` whose branch starts along this partition's F at (q, t) (the
        motion's tangent before the singular position), the same independent velocities if the
        user fixed them (else those pivoted QR picks from that tangent), the same tree velocities
        ṡ_tree = F ṡ + f."""
        F, f = self.F(q, t)
        new = copy.copy(self)
        new.__class__ = TangentSystem
        new._inverse, new._compiled, new._uncompiled = (None, None), False, None
        new._tangent = np.linalg.qr(F)[0]
        if self.repivot:
            new.independent = pivoted_columns(new._tangent.T, self.n_s)
            new.dependent = np.setdiff1d(np.arange(self.tree.n_s), new.independent)
        new.q0 = np.array(q, dtype=float)
        new.check_configuration(q, t)
        new.limit = max(REPIVOT_CONDITION, 10 * new.condition(q, t))
        new.s_dot0 = (F @ s_dot + f)[new.independent]
        return new, new.s_dot0.copy()

    def with_independent(self, independent, repivot: bool | None = None) -> "ConstrainedSystem":
        """This system (same tree, constraints and initial motion q0, ṡ_tree0) with the tree
        velocities ``independent`` as its minimal velocities; ``repivot`` as in the
        constructor (default: this system's). ValueError if A_dep is singular at q0."""
        free, dependent = copy.copy(self)._partition(self.q0, independent)  # checks, at q0
        new = self._in_partition(free, self.q0)
        new.s_dot0 = self.tree_velocities(self.q0, self.s_dot0)[free]
        new.repivot = self.repivot if repivot is None else _check_repivot(repivot)
        return new

    def row_models(self, result) -> list:
        """This system in the partition of each row of ``result`` (``Result.partitions``:
        (t_k, independent_k, formulation_k) holds for t_k < t ≤ t_k+1, the first one from the start)."""
        if not result.partitions:
            return [self] * len(result.t)
        starts = [t for t, *_ in result.partitions]
        systems = [self._in_partition(np.asarray(independent), self.q0, formulation=formulation)
                   for _, independent, formulation in result.partitions]
        return [systems[max(k - 1, 0)] for k in np.searchsorted(starts, result.t, side="left")]

    def _in_partition(self, independent, q, t=0.0, formulation: str | None = None) -> "ConstrainedSystem":
        """A copy with the partition ``independent`` (unchecked) in ``formulation`` (default: this
        system's), starting at q."""
        new = copy.copy(self)
        if formulation is not None and formulation != self.formulation:
            new.__class__ = TangentSystem if formulation == "null space" else ConstrainedSystem
            new._compiled = False
        new.independent, new.dependent = independent, np.setdiff1d(np.arange(self.tree.n_s), independent)
        new._inverse = (None, None)  # A_dep⁻¹ of the old partition
        new.q0 = np.array(q, dtype=float)
        new.limit = max(REPIVOT_CONDITION, 10 * new.condition(q, t))
        return new

    def _check_dependent(self, A_s, q, t) -> None:
        cond = _partition_condition(A_s, self.dependent)
        if not cond < PARTITION_CONDITION:
            raise self._degenerate(q, t, cond, PARTITION_CONDITION)

    def _degenerate(self, q, t, cond, limit) -> ValueError:
        where = f"q = {np.round(q, 6).tolist()}, t = {t:.6g}"
        if not self.repivot:
            return ValueError(
                f"independent: the dependent velocities {self.dependent.tolist()} cannot be solved for at {where} "
                f"(condition number of the partition {cond:.3g}, limit {limit:.3g}); choose other independent "
                "velocities (default: pivoted QR picks them at q0), or pass repivot=True"
            )
        if self._near_dependent(q, t):
            return self._singular_position(q, t)
        return ValueError(
            f"independent: the dependent velocities {self.dependent.tolist()} cannot be solved for at "
            f"{where}, reached within one step before the partition could be re-chosen; pass a smaller "
            "max_step to simulate, or pass formulation='null_space', which needs no partition"
        )

    def _near_dependent(self, q, t) -> bool:
        """Whether the constraint rows themselves are nearly dependent at (q, t): every partition's
        κ ≥ cond(A_s), so none can be 10 times below the limit."""
        sigma = np.linalg.svd(self.constraint_matrix(q, t)[0], compute_uv=False)
        return not sigma[-1] * self.limit > 10 * sigma[0]

    def _singular_position(self, q, t) -> ValueError:
        return ValueError(
            f"phi: the mechanism reaches a singular position at q = {np.round(q, 6).tolist()}, "
            f"t = {t:.6g}: its {self.n_c} constraint equations become dependent there (links coming into "
            "line, where the motion can branch), so that no choice of independent velocities carries the "
            "motion through it; the null-space form does (leave independent and repivot at their defaults, "
            "which go on in it from here, or pass formulation='null_space')"
        )

    def rank(self, q: NDArray, t: float = 0.0) -> int:
        """The numerical rank of A_s at (q, t): its singular values above RANK_TOLERANCE ‖A_s‖₂."""
        return self._rank_and_mobility(self.constraint_matrix(self.check_q("q", q), t)[0])[0]

    def mobility(self, q: NDArray, t: float = 0.0) -> int:
        """Degrees of freedom at (q, t): the tree's velocities minus :meth:`rank` (Grübler's count
        n_s,tree − n_c when no constraint is redundant)."""
        return self._rank_and_mobility(self.constraint_matrix(self.check_q("q", q), t)[0])[1]

    def _rank_and_mobility(self, A_s: NDArray) -> tuple[int, int]:
        """(rank, n_s,tree − rank) of the constraint matrix A_s."""
        rank = numerical_rank(A_s)
        return rank, self.tree.n_s - rank

    def F(self, q: NDArray, t: float = 0.0, constraint_matrix=None) -> tuple[NDArray, NDArray]:
        """(F, f) of ṡ_tree = F ṡ + f: F = [E; −A_dep⁻¹ A_ind], f = [0; A_dep⁻¹ b_s]
        (``constraint_matrix``: (A_s, b_s) at (q, t) if known)."""
        A_s, b_s = self.constraint_matrix(q, t) if constraint_matrix is None else constraint_matrix
        F = np.zeros((self.tree.n_s, self.n_s), dtype=np.result_type(A_s, b_s))
        F[self.independent] = np.eye(self.n_s)
        f = np.zeros(self.tree.n_s, dtype=F.dtype)
        if self.n_c:
            inverse = self._dependent_inverse(A_s, q, t)  # checked: the partition degenerates during a run
            F[self.dependent], f[self.dependent] = -inverse @ A_s[:, self.independent], inverse @ b_s
        return F, f

    def _dependent_inverse(self, A_s: NDArray, q: NDArray, t: float) -> NDArray:
        """A_dep⁻¹, kept for this A_s (F, f and f̄ of one state share it); ValueError where the
        partition's condition number κ = ‖A_s‖₂ ‖A_dep⁻¹‖₂ reaches PARTITION_CONDITION. The
        Frobenius norms bound κ from above (‖·‖₂ ≤ ‖·‖_F), so κ itself (two SVDs) is computed
        only where that bound reaches the limit."""
        kept, inverse = self._inverse  # one read: another thread may replace it
        if kept is A_s:
            return inverse
        try:
            inverse = np.linalg.inv(A_s[:, self.dependent])
        except np.linalg.LinAlgError:
            inverse = np.full((self.n_c, self.n_c), np.inf)
        if not np.linalg.norm(np.real(A_s)) * np.linalg.norm(np.real(inverse)) < PARTITION_CONDITION:
            self._check_dependent(A_s, q, t)
        self._inverse = (A_s, inverse)
        return inverse

    _inverse = (None, None)  # (A_s, A_dep⁻¹) of the latest F

    def particular(self, A_s: NDArray, c: NDArray) -> NDArray:
        """The solution x of A_s x = c with x[independent] = 0: [0; A_dep⁻¹ c]."""
        x = np.zeros(self.tree.n_s, dtype=np.result_type(A_s, c))  # complex under the complex step
        kept, inverse = self._inverse  # one read: another thread may replace it
        if kept is A_s:
            x[self.dependent] = inverse @ c
        else:
            x[self.dependent] = np.linalg.solve(A_s[:, self.dependent], c)
        return x

    def tree_velocities(self, q: NDArray, s_dot: NDArray, t: float = 0.0, constraint_matrix=None) -> NDArray:
        """ṡ_tree = F ṡ + f (``constraint_matrix``: (A_s, b_s) at (q, t) if known); ValueError naming q or
        s_dot for one of the wrong type or shape."""
        q, s_dot = kernel_state("q", q, self.n_q), kernel_state("s_dot", s_dot, self.n_s)
        F, f = self.F(q, t, constraint_matrix)
        return F @ s_dot + f

    # -- the Model protocol (projeq.system.Model) --------------------------------------------
    def check_q(self, name: str, q) -> NDArray:
        """q as the tree checks it."""
        return self.tree.check_q(name, q)

    def joint(self, name: str) -> Joint:
        """The tree joint that attaches subsystem ``name``."""
        return self.tree.joint(name)

    def K(self, q: NDArray, t: float = 0.0) -> NDArray:
        """K of q̇ = K ṡ + k in the minimal velocities: K_tree F."""
        q = kernel_state("q", q, self.n_q)
        return self.tree.K(q, t) @ self.F(q, t)[0]

    def q_dot(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> NDArray:
        """q̇ = K_tree (F ṡ + f) + k, minus β C_Φ⁺ Φ with Baumgarte's correction."""
        return self._q_dot(q, self.tree_velocities(q, s_dot, t), t)

    def _q_dot(self, q: NDArray, s_dot_tree: NDArray, t: float) -> NDArray:
        """q̇ = K_tree ṡ_tree + k, minus β C_Φ⁺ Φ with Baumgarte's correction."""
        q_dot = self.tree.q_dot(q, s_dot_tree, t)
        if self.correction == "baumgarte" and self.m_h:
            q_dot -= self.beta * minimum_norm_solution(self.phi_q(q, t), self.phi(q, t))
        return q_dot

    def normalized(self, q: NDArray, t: float = 0.0) -> NDArray:
        """The tree's normalisation, then (``correction="projection"``) Gauss–Newton steps
        q ← q − C_Φ⁺ Φ onto Φ(q, t) = 0 at the time t (a driven mechanism's Φ depends on it)."""
        q = self.tree.normalized(q)
        return self.project(q, t) if self.correction == "projection" else q

    def project(self, q: NDArray, t: float = 0.0, max_iter: int = PROJECTION_STEPS) -> NDArray:
        """q moved onto Φ(q, t) = 0 by minimum-norm Gauss–Newton steps (redundant rows: singular
        values of ∂Φ/∂q below RANK_TOLERANCE σ_max dropped); ValueError if it fails.

        Complex-safe (the steps are analytic): for q carrying a complex step, one step more
        than its real part needs, from the converged point, where the step's Jacobian is the
        projector E − Φ_q⁺Φ_q onto the tangent of Φ = 0, so that the complex step gives the
        derivative of the projection (the energy projection's gradient)."""
        q = numeric(np.array(q))
        tol = POSITION_TOLERANCE * max(1.0, np.abs(q).max())
        settled = not np.iscomplexobj(q)  # a real q is done where Φ is within tol
        for _ in range(max_iter):
            residual = self.phi(q, t)
            converged = not residual.size or np.abs(np.real(residual)).max() <= tol
            if converged and settled:
                return q
            settled = converged
            q = self.tree.normalized(q - minimum_norm_solution(self.phi_q(q, t), residual))
        raise ValueError(
            f"q: cannot be projected onto the constraints Φ(q, t) = 0 (residual "
            f"{np.array2string(self.phi(q, t), precision=3)} after {max_iter} Gauss–Newton steps)"
        )

    def _initial_q(self, q0, project_q0) -> NDArray:
        if not project_q0:
            self.check_closed("q0", q0, 0.0, remedy="pass project_q0=True to project it onto Φ = 0")
        return self.project(q0) if self.m_h else q0

    def check_closed(self, name: str, q: NDArray, t: float = 0.0, tol: float = 1e3 * POSITION_TOLERANCE,
                     remedy: str = "move it onto Φ = 0 with project(q, t)") -> None:
        """ValueError naming ``name`` if q violates the loop closures: |Φ(q, t)| above
        tol · max(1, |q|) (the default 1e-9, far above what :meth:`project` leaves, 1e-12)."""
        residual = self.phi(q, t)
        if residual.size and np.abs(residual).max() > tol * max(1.0, np.abs(q).max()):
            raise ValueError(f"{name}: violates the loop closures Φ({name}) = "
                             f"{np.array2string(residual, precision=4)}; give a consistent {name} or {remedy}")

    def energy(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> tuple[float, float]:
        """(kinetic, potential) of the tree at ṡ_tree = F ṡ + f."""
        return self.tree.energy(q, self.tree_velocities(q, s_dot, t), t)

    def output_row(self, q: NDArray, s_dot: NDArray, t: float = 0.0) -> tuple:
        """:meth:`Model.output_row <projeq.system.Model.output_row>` from one constraint matrix
        (A_s, b_s) at (q, t): ṡ_tree = F ṡ + f once for the energy and q̇, and the rank of A_s."""
        A_s, b_s = self.constraint_matrix(q, t)
        s_dot_tree = self.tree_velocities(q, s_dot, t, (A_s, b_s))
        residual = self.constraint_residual(q, self._q_dot(q, s_dot_tree, t), t)
        return self.tree._energy(q, s_dot_tree, float(t)), residual, self._rank_and_mobility(A_s)

    def rows(self, x_rows: NDArray, times: NDArray) -> tuple | None:
        """:meth:`Model.rows <projeq.system.Model.rows>` by the system's compiled kernel, partitioned or in
        the null-space form (:meth:`~projeq.constraints.compiled.CompiledClosure.rows`: the projection of
        :meth:`normalized`, ṡ_tree, the residuals and the rank of A_s) and the tree's energies together
        (:meth:`projeq.System.output_rows`); None where it does not apply (no compiled kernel built, a
        subclass's own rows or normalisation, a tree that normalises q) or a row is not finished there. The energies
        row by row where the tree's are not computed together (elastic bodies, springs)."""
        kernel = self._compiled  # only where the run built it (the numpy path's runs compile nothing)
        if not kernel or not self._rows_of_this_class() or self.tree._normalizing:
            return None
        x_rows = np.asarray(x_rows, dtype=float)
        found = kernel.rows(self, x_rows[:, :self.n_q], x_rows[:, self.n_q:], times, POSITION_TOLERANCE,
                            PROJECTION_STEPS)
        if found is None:
            return None
        q, s_dot_tree, residuals, ranks = found
        values = self.tree.output_rows(q, s_dot_tree, times)
        energies = np.reshape([self.tree._energy(*row, float(t)) for *row, t in zip(q, s_dot_tree, times)],
                              (len(times), 2)) if values is None else values[0]
        return q, energies, residuals, np.column_stack((ranks, self.tree.n_s - ranks))

    def _rows_of_this_class(self) -> bool:
        """Whether the output rows are those of this module's classes: normalized, output_row and rows not
        a subclass's (the kernel's F rule is checked by :meth:`compiled_kernel`)."""
        cls = type(self)
        return all(getattr(cls, name) is getattr(ConstrainedSystem, name) for name in ("normalized", "output_row",
                                                                                      "project", "rows"))

    # -- dynamics ---------------------------------------------------------------------------
    def gamma(self, q: NDArray, s_dot_tree: NDArray, t: float = 0.0, C=None) -> NDArray:
        """γ of A_s s̈_tree = −γ: d/dt (C q̇ − c) along the motion with s̈_tree = 0
        (``C``: the velocity constraint matrix at (q, t) if known), in x = (q, t) moving at
        v = (q̇, 1):

            γ = [Φ″(v, v); (A′ v) q̇ − b′ v] + C (K̇ ṡ_tree + k̇),

        Φ″(v, v) = Φ″(v_q, v_q) + 2 Φ″(v_q, v_t) + Φ″(v_t, v_t) with v_q = (q̇, 0), v_t = (0, 1)
        taken apart so that each part keeps its relative accuracy at any speed (the first is
        ∝ |q̇|², the rheonomic ones are not); the first derivatives by the complex step, Φ″ by
        the complex step inside Richardson's stencil (≈ 1e-14 relative, :data:`projeq.analysis.differentiation.MIXED_STEP`)."""
        tree, n = self.tree, self.n_q
        q_dot = tree.q_dot(q, s_dot_tree, t)
        x, v = np.append(q, t), np.append(q_dot, 1.0)
        C = self.velocity_constraints(q, t)[0] if C is None else C
        parts = []
        if self.m_h:
            parts.append(self._phi_second(x, q_dot))
        if self.m_p:
            parts.append(self._d1(lambda y: _pfaffian_residual(self, (y[:n], y[n]), y[n + 1:]), np.append(x, q_dot),
                                  np.append(v, np.zeros(n))))
        if self._identity:  # K = E: K̇ ṡ + k̇ = 0
            return np.concatenate(parts)
        # frozen arguments ride along in the point with zero rate (they may carry an outer complex step)
        q_ddot = derivative_along(lambda y: tree.q_dot(y[:n], y[n + 1:], y[n]), np.append(x, s_dot_tree),
                                  np.append(v, np.zeros(tree.n_s)))  # K̇ ṡ + k̇
        return np.concatenate(parts) + C @ q_ddot

    def _phi_second(self, x: NDArray, q_dot: NDArray) -> NDArray:
        """Φ″(v, v) = Φ″(v_q, v_q) + 2 Φ″(v_q, v_t) + Φ″(v_t, v_t) at x = (q, t), v_q = (q̇, 0),
        v_t = (0, 1) (:meth:`gamma`; the rheonomic parts only where Φ depends on t), by one call
        at a batch of points where Φ takes them."""
        batched = self._batched()
        if batched is not None and (batched.complex_safe or not (np.iscomplexobj(x) or np.iscomplexobj(q_dot))):
            return batched.second(x, q_dot, self.rheonomic)
        v_q, v_t = np.append(q_dot, 0.0), np.eye(len(x))[-1]
        value = self._d2(self._phi_x, x, v_q, v_q)
        if self.rheonomic:  # along t the stencil steps 1/σ as far (time_rate)
            Phi_x = np.column_stack(self._phi_derivatives(np.real(x[:-1]), float(np.real(x[-1]))))
            along_t = {"step": MIXED_STEP / time_rate(Phi_x)} if self.exact else {}
            value = value + 2 * self._d2(self._phi_x, x, v_q, v_t, **along_t) \
                + self._d2(self._phi_x, x, v_t, v_t, **along_t)
        return value

    def _projected(self, q: NDArray, s_dot: NDArray, t: float, method: str | None) -> tuple:
        """(A_s, F, f̄, M, b) at (q, ṡ, t): ṡ_tree = F ṡ + f, s̈_tree = F s̈ + f̄, and the tree's
        Gauss form M s̈_tree + b at ṡ_tree (b by the tree evaluator ``method``, module docstring)."""
        C, c = self.velocity_constraints(q, t)
        A_s, b_s = self._in_tree_velocities(q, t, C, c)
        F, f = self.F(q, t, (A_s, b_s))
        s_dot_tree = F @ s_dot + f
        M, b = self.tree_gauss_form(q, s_dot_tree, t, method)
        f_bar = np.zeros(self.tree.n_s, dtype=np.result_type(A_s, M, b))
        if self.n_c:
            f_bar = self.particular(A_s, -self.gamma(q, s_dot_tree, t, C))
        return A_s, F, f_bar, M, b

    def tree_gauss_form(self, q: NDArray, s_dot_tree: NDArray, t: float,
                        method: str | None = None) -> tuple[NDArray, NDArray]:
        """M and b of the tree's Gauss form M s̈_tree + b = 0 at ṡ_tree, compiled where the tree's
        default evaluator is (through its tier: the dense reference while its kernels are not
        compiled, :class:`projeq.assembly.auto.Tier`), else (and for ``method="dense"`` or complex
        arguments) the dense reference; b from the free accelerations of ``method`` = "recursive" or
        "fast" (module docstring)."""
        tree = self.tree
        compiled = self.compiled_tree(method) and not (np.iscomplexobj(q) or np.iscomplexobj(s_dot_tree))
        M, b = tree.evaluator("auto" if compiled else "dense").gauss_form(q, s_dot_tree, t)
        if method not in (None, "dense"):  # M s̈_free + b = 0
            b = -M @ tree.evaluator(method).accelerations(q, s_dot_tree, t)
        return M, b

    def compiled_tree(self, method: str | None = None) -> bool:
        """Whether :meth:`tree_gauss_form` takes the compiled kernels for ``method`` (at real
        arguments): the tree's default evaluator is the compiled one (else it warned once,
        naming the piece) and ``method`` is not "dense"."""
        return method != "dense" and self.tree.evaluator("auto").name == "fast"

    def gauss_form(self, q, s_dot, t: float = 0.0) -> tuple[NDArray, NDArray]:
        """M_min = FᵀMF and b_min = Fᵀ(M f̄ + b) of M_min s̈ + b_min = 0, the tree's Gauss form
        with the constraint inserted before the projection (module docstring)."""
        q, s_dot = self.check_state(q, s_dot, t)
        return _minimal(*self._projected(q, s_dot, float(t), None)[1:])

    def accelerations_tree(self, q: NDArray, s_dot: NDArray, t: float = 0.0,
                           method: str | None = None) -> tuple[NDArray, NDArray]:
        """(s̈_tree, λ): s̈_tree = F s̈ + f̄ from Fᵀ(M (F s̈ + f̄) + b) = 0, and the
        multipliers λ of M s̈_tree + b = A_sᵀ λ (the constraint forces); ``method`` picks
        the tree's evaluator (module docstring; None: compiled where the tree is). ValueError
        naming q or s_dot for a state of the wrong type or shape, or one where s̈_tree is not finite."""
        q, s_dot = kernel_state("q", q, self.n_q), kernel_state("s_dot", s_dot, self.n_s)
        s_ddot_tree, A_s, M, b = self._tree_accelerations(q, s_dot, t, method)
        finite_result("s̈_tree", s_ddot_tree, q=q, s_dot=s_dot)
        lam = np.zeros(0)
        if self.n_c:  # the minimum-norm λ where rows are redundant
            lam = np.linalg.lstsq(A_s.T, M @ s_ddot_tree + b, rcond=RANK_TOLERANCE)[0]
        return s_ddot_tree, lam

    def _tree_accelerations(self, q: NDArray, s_dot: NDArray, t: float, method: str | None) -> tuple:
        """(s̈_tree, A_s, M, b): s̈_tree = F s̈ + f̄ from Fᵀ(M (F s̈ + f̄) + b) = 0, in one compiled
        call by default where it applies (:mod:`projeq.constraints.compiled`), else (and where
        that call flags a degenerate partition or a singular FᵀMF, to raise the error naming it)
        by :meth:`_projected_accelerations`."""
        kernel = self.compiled_kernel() if method is None else None
        if kernel is not None and not (np.iscomplexobj(q) or np.iscomplexobj(s_dot)):
            found = kernel.accelerations(self, q, s_dot, t)
            if found is not None:
                return found
        return self._projected_accelerations(q, s_dot, t, method)

    def compiled_kernel(self):
        """The :class:`~projeq.constraints.compiled.CompiledClosure` of this system's Φ and tree
        (built on first use: numba compiles Φ, and warns once naming it if it cannot), or None
        where the compiled call does not apply, after one
        :class:`~projeq.constraints.compiled.UncompiledClosureWarning` naming the piece
        (:func:`projeq.constraints.compiled.unsupported`)."""
        if self._compiled is False:
            why = unsupported(self)
            self._compiled = self._compiled_rule() if why is None else uncompiled(self, why)
        return self._compiled

    def _compiled_rule(self):
        """The compiled kernel of coordinate partitioning, None (after one warning) for a subclass
        that forms F by its own rule."""
        if type(self).F is not ConstrainedSystem.F or type(self).particular is not ConstrainedSystem.particular:
            return uncompiled(self, OWN_RULE)
        return compiled_partition(self, PARTITION_CONDITION)

    _compiled = False  # the CompiledClosure, None where it does not apply; False: not looked at yet
    _uncompiled = None  # why it does not apply (said once, projeq.constraints.compiled.uncompiled)

    def _projected_accelerations(self, q: NDArray, s_dot: NDArray, t: float, method: str | None) -> tuple:
        """(s̈_tree, A_s, M, b) by numpy linear algebra on Φ's derivatives and the tree's Gauss
        form (the reference of the compiled call)."""
        A_s, F, f_bar, M, b = self._projected(q, s_dot, t, method)
        M_min, b_min = _minimal(F, f_bar, M, b)
        s_ddot = -solve_spd(M_min, b_min[:, None], "constrained mass matrix FᵀMF",
                            max(np.abs(np.diag(M_min)).max(initial=0.0), 1e-300))[:, 0]
        return F @ s_ddot + f_bar, A_s, M, b

    def evaluator(self, method: str | None = None) -> "PartitionedEvaluator":
        """s̈ with the tree evaluator ``method`` (None: compiled where the tree is, module
        docstring), unchecked: for :func:`projeq.simulate`."""
        return PartitionedEvaluator(self, method)

    def generalized_force(self, q: NDArray, t: float, joint_forces: dict) -> NDArray:
        """Fᵀ Q_tree: the tree's generalized forces projected like its Gauss form."""
        return self.F(q, t)[0].T @ self.tree.generalized_force(q, t, joint_forces)

    def __repr__(self) -> str:
        return f"ConstrainedSystem(n_q={self.n_q}, n_s={self.n_s}, {self.m_h} holonomic, {self.m_p} Pfaffian)"


class TangentSystem(NullSpaceForm, ConstrainedSystem):
    """The null-space form of a :class:`ConstrainedSystem` (:mod:`projeq.constraints.tangent`): F
    spans the null space of the constraints, so that the model runs through singular positions and
    takes redundant constraints as they are. A ConstrainedSystem takes this form where its rows are
    redundant or nearly dependent at q0, with ``formulation="null_space"``, and from a singular
    position its run meets on; built directly, it is that form throughout.

    The arguments are those of :class:`~projeq.constraints.partitioned.ConstrainedSystem`; its
    n_s is the mobility at q0 (tree velocities minus the rank of the constraints there), and
    ``independent`` (default: column-pivoted QR of the null space) names n_s tree velocities.
    ``separation`` (default SEPARATION = 1e-2): singular values of A_s below this fraction of the
    largest count as near-null, where N continues the branch's tangent; 0 takes the n_s smallest
    singular vectors everywhere (no continuation: an integrator stage off the constraint manifold
    near a singular position can then take a direction that has come free, module docstring).

    Examples
    --------
    A pendulum on x and z sliders, its constraint written twice (a redundant row):

    >>> import numpy as np, projeq as pq
    >>> tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
    ...     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")},
    ...     gravity=(0, 0, -9.81))
    >>> circle = lambda q, t: [np.hypot(q[0], q[1]) - 1.0, 2 * (np.hypot(q[0], q[1]) - 1.0)]
    >>> pendulum = pq.ConstrainedSystem(tree, phi=circle, q0=[0.6, -0.8])
    >>> pendulum.n_c, pendulum.rank(pendulum.q0), pendulum.n_s, pendulum.redundant, pendulum.formulation
    (2, 1, 1, (1,), 'null space')
    >>> r = pq.simulate(pendulum, 0.2, n_points=5, n_segments=2)
    >>> bool(np.abs(r.constraint_residual).max() < 1e-10)
    True
    """

    formulation = "null space"


class PartitionedEvaluator:
    """s̈ = s̈_tree[independent] of a ConstrainedSystem by the tree evaluator ``method``
    (checked here: an unknown name raises ValueError); the state is not checked.

    ``name``: ``"partitioned(fast)"`` when the tree's Gauss form is the compiled one,
    ``"partitioned(dense)"`` when it is the dense reference (``method`` names the tree
    evaluator that gives b, if any); ``reason``: why."""

    def __init__(self, system: ConstrainedSystem, method: str | None):
        if method is not None:
            system.tree.evaluator(method)
        compiled = system.compiled_tree(method)
        self.name = f"partitioned({'fast' if compiled else 'dense'})"
        # the motion needs no multipliers: s̈_tree without λ's least squares, unless a subclass
        # forms s̈_tree and λ together (the augmented Lagrangian)
        partitioned = type(system).accelerations_tree is ConstrainedSystem.accelerations_tree
        whole = method is None and partitioned and system.compiled_kernel() is not None
        if whole:  # s̈ and ẋ = (q̇, s̈) (simulate's right-hand side) in one compiled call
            self.accelerations, self.state_derivative = self._compiled_accelerations, self._state_derivative
        self.reason = ("Φ's derivatives, the partition and the projection of the tree's Gauss form in one "
                       "compiled call" if whole else
                       f"constraint equations projected on the tree's Gauss form M, b by the "
                       f"{'compiled kernels' if compiled else 'dense reference'}"
                       + (f", b from the {method!r} evaluator" if method not in (None, "dense") else "")
                       + (f"; not in one compiled call: {system._uncompiled}"
                          if method is None and partitioned and not whole else ""))
        self.system, self.method = system, method
        self._tree = system._tree_accelerations if partitioned else system.accelerations_tree

    def accelerations(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        system = self.system
        q, s_dot = kernel_state("q", q, system.n_q), kernel_state("s_dot", s_dot, system.n_s)
        return self._tree(q, s_dot, t, self.method)[0][system.independent]

    def loop_model(self):
        """The system as the compiled integration loop takes it
        (:meth:`projeq.constraints.compiled.CompiledClosure.loop_model`, made once), or None where its ẋ is
        not one compiled call of coordinate partitioning."""
        if not hasattr(self, "_loop_model"):
            whole = getattr(self, "state_derivative", None) == self._state_derivative  # one compiled call
            kernel = self.system.compiled_kernel() if whole else None
            self._loop_model = None if kernel is None else kernel.loop_model(self.system)
        return self._loop_model

    def _compiled_accelerations(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        """s̈ by the system's compiled kernel at real arguments; by the numpy path at complex ones (a
        complex step) and where the kernel flags (which raises the error naming the cause)."""
        system = self.system
        q, s_dot = kernel_state("q", q, system.n_q), kernel_state("s_dot", s_dot, system.n_s)  # before the kernel reads
        if q.dtype.kind != "c" and s_dot.dtype.kind != "c":  # (np.iscomplexobj costs more than the check)
            s_ddot = system.compiled_kernel().minimal_accelerations(system, q, s_dot, t)
            if s_ddot is not None:
                return s_ddot
        return system._projected_accelerations(q, s_dot, t, None)[0][system.independent]

    def _state_derivative(self, t: float, x: NDArray):
        """ẋ = (q̇, s̈) by the system's compiled kernel, or None
        (:meth:`projeq.constraints.compiled.CompiledClosure.state_derivative`); ValueError naming x
        for one of the wrong type or shape."""
        system = self.system
        return system.compiled_kernel().state_derivative(system, kernel_state("x", x, system.n_q + system.n_s), t)


def _minimal(F: NDArray, f_bar: NDArray, M: NDArray, b: NDArray) -> tuple[NDArray, NDArray]:
    """FᵀMF and Fᵀ(M f̄ + b): the Gauss form in the minimal velocities."""
    return F.T @ M @ F, F.T @ (M @ f_bar + b)


def _check_repivot(repivot) -> bool:
    if repivot not in (True, False):
        raise ValueError(f"repivot: expected True, False or None (automatic), got {repivot!r}")
    return bool(repivot)


def _partition_condition(A_s: NDArray, dependent: NDArray) -> float:
    """κ = ‖A_s‖₂ / σ_min(A_dep) = ‖A_s‖₂ ‖A_dep⁻¹‖₂ (1 for no rows, ∞ for a singular A_dep)."""
    if not A_s.size:
        return 1.0
    sigma = np.linalg.svd(A_s[:, dependent], compute_uv=False)
    return float(np.linalg.svd(A_s, compute_uv=False)[0] / sigma[-1]) if sigma[-1] > 0 else np.inf














def _pfaffian_residual(system: ConstrainedSystem, q_t, q_dot) -> NDArray:
    A, b = system._pfaffian(*q_t)
    return A @ q_dot - b


def _dependent_rows(A_s: NDArray, tol: float) -> list:
    """The rows of A_s in the span of the rows before them (rank test at ``tol``)."""
    kept, dependent = [], []
    for i in range(len(A_s)):
        (kept if np.linalg.matrix_rank(A_s[kept + [i]], tol) > len(kept) else dependent).append(i)
    return dependent

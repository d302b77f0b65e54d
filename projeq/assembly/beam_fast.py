"""The evaluator of a beam on a moving hub, ``method="hub_beam"``: one RitzBeam whose root
follows a prescribed motion (a rheonomic hub, docs/theory.md §4) or is fixed to the ground — the
spin-up beam.

Then the beam's reference frame moves as given, ẏ = (w(t), q̇_e) with the hub's twist w
and ÿ = (ζ(t), q̈_e) with ζ = Ḟ⁶ θ̇ + F⁶ θ̈ (the parent is the ground at rest), and the
Projection Equation B(14) projected on the only minimal velocities ṡ = q̇_e,

    M_ee q̈_e = h_e − M_eR ζ,

needs neither the kinematic chain nor the passes of docs/theory.md §6: the beam's terms and one
n_e × n_e solve. With precomputed shape integrals (:mod:`projeq.subsystems.beam.integrals`)
and no rotary inertia only the elastic rows (M_ee, M_eR, h_e) are formed
(:meth:`~projeq.subsystems.beam.beam.RitzBeam.elastic_terms`). M_ee = ∫ Φ_rᵀ Φ_r dm is
positive definite for the independent Ritz functions a RitzBeam accepts, so a plain LU
solve suffices. Equal to the general evaluators to round-off
(tests/assembly/test_fast.py).

Compiled by default: a RitzBeam, rotary inertia and torsion included (its slice and rotation
fields, which the compiled kernel evaluates, :func:`projeq.assembly.kernels.elastic_body` and
:func:`~projeq.assembly.kernels.rotary_body`, the same statement of the beam's terms as the
order-n kernel's elastic block) on a Prescribed Revolute or Prismatic, a Fixed joint or any
joint without coordinates (read by its ``relative_values``; a motion given in sympy by the C
callback of its printed row, :mod:`projeq.assembly.given`, in one compiled call; a callable
motion's angles in Python) is one call of
:func:`projeq.assembly.kernels.hub_beam` per s̈. Any other subsystem with internal
coordinates and the beam's layout ẏ = (twist, q̇_e) (a user's subsystem, a RitzBeam that
restates its terms) takes the interpreted path through its ``elastic_terms``
(:class:`projeq.Subsystem`: by default the last n_e rows of its own ``gauss_terms``).
Complex arguments (the complex-step derivatives of :mod:`projeq.analysis.jacobians`) take
the same kernel, compiled for complex128 (a second specialization of the same source).

>>> import numpy as np, projeq as pq
>>> system = pq.scenes.spin_up_beam(omega_s=4.0, n_shapes=2, family="clamped_free")
>>> ev = HubBeamEvaluator(system)
>>> ev.compiled == pq.assembly.kernels.has_numba()
True
>>> q, s_dot = np.array([0.01, 0.0, 0.002, 0.0]), np.array([0.1, 0.0, 0.0, 0.0])
>>> bool(np.allclose(ev.accelerations(q, s_dot, 3.0), system.accelerations(q, s_dot, 3.0), rtol=1e-12, atol=1e-12))
True
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import COMPLEX_STEP
from projeq.assembly import given, kernels
from projeq.assembly.linalg import SINGULAR_PIVOT, SingularMassError, mass_scale
from projeq.checks import callable_name, kernel_state
from projeq.joints import Prescribed


def hub_beam_unsupported(system) -> str | None:
    """Why ``system`` is not one subsystem with internal coordinates laid out as a beam's,
    ẏ = (twist, q̇_e) (``S`` = [E; 0], a RitzBeam), on a root joint without coordinates,
    whose motion is a given function of time (Prescribed, Fixed) (None if it is)."""
    if len(system.subsystems) != 1:
        return f"the system has {len(system.subsystems)} subsystems (the beam path takes one RitzBeam)"
    name, beam, joint = system.names[0], system.subsystems[0], system.joints[0]
    if not beam.n_e or beam.S is None or not np.array_equal(beam.S, np.eye(6 + beam.n_e, 6)):
        return (f"subsystem {name!r} is a {type(beam).__name__}, not one with internal coordinates and "
                "ẏ = (twist, q̇_e) (a RitzBeam)")
    if joint.n_q or joint.n_s or joint.coupling:
        return (f"joint {name!r} is a {type(joint).__name__} with coordinates (the beam path takes hubs "
                "whose motion is given: Prescribed or Fixed)")
    if system.forces:
        return "the system has force laws (the beam path knows gravity only)"
    return None


def elastic_unsupported(body) -> str | None:
    """Why the kernel's elastic block (:func:`projeq.assembly.kernels.elastic_body` and
    :func:`~projeq.assembly.kernels.rotary_body`) cannot take ``body`` (None if it can): it takes
    bodies with ẏ = (twist, q̇_e) whose terms are the slice sums of their ``slice_field`` and
    ``rotation_field`` (translation and rotary inertia) with linear restoring forces (a RitzBeam)."""
    if not hasattr(body, "slice_field") or not hasattr(body, "rotation_field") or body.S is None \
            or not np.array_equal(body.S, np.eye(6 + body.n_e, 6)):
        return "(the kernel knows elastic bodies by the slice and rotation fields of a RitzBeam)"
    owner = next(c for c in type(body).__mro__ if "slice_field" in vars(c))
    if type(body).gauss_terms is not owner.gauss_terms:
        return ("that restates gauss_terms (the kernel knows the terms of the slice field, not the ones "
                "it adds)")
    return None


def compiled_unsupported(system) -> str | None:
    """Why :func:`projeq.assembly.kernels.hub_beam` cannot evaluate ``system``, one subsystem on
    a hub (:func:`hub_beam_unsupported`), (None if it can)."""
    name, body = system.names[0], system.subsystems[0]
    reason = elastic_unsupported(body)
    if reason is not None:
        return f"subsystem {name!r} is a {type(body).__name__} {reason}"
    return None if kernels.has_numba() else "numba is not installed"


class HubBeamEvaluator:
    """q̈_e of one RitzBeam on a prescribed or fixed hub (module docstring).

    Parameters
    ----------
    system : System
        One RitzBeam (or another subsystem with internal coordinates and ẏ = (twist, q̇_e),
        through its ``elastic_terms``) on a :class:`~projeq.Prescribed` or
        :class:`~projeq.Fixed` joint to the ground, without force laws; otherwise
        ValueError naming the reason.
    compiled : bool
        True (default): by the compiled kernel where it knows the subsystem
        (:func:`compiled_unsupported` says why not; then interpreted); False: interpreted.

    Attributes: ``name`` ("hub_beam"), ``compiled`` (whether real arguments take the compiled
    kernel), ``interpreted_reason`` (why not, or None), ``interpreted`` (what the compiled kernel takes
    from Python at every evaluation, by name: a callable hub motion's angles), ``n_calls``.
    """

    name = "hub_beam"

    def __init__(self, system, compiled: bool = True):
        reason = hub_beam_unsupported(system)
        if reason is not None:
            raise ValueError(f"system: {reason}")
        self.system = system
        self.beam, self.joint = system.subsystems[0], system.joints[0]
        self._empty = np.zeros(0)
        self.n_calls = 0
        self.interpreted_reason = compiled_unsupported(system) if compiled else "compiled=False"
        self.compiled, self.interpreted = self.interpreted_reason is None, []
        if self.compiled:
            self._pack(system)

    def _pack(self, system) -> None:
        """The kernel's constants: the hub's kind, axis and frame, the beam's slice field
        (:meth:`projeq.RitzBeam.slice_field`), K_e, damping and rotation field
        (:meth:`projeq.RitzBeam.rotation_field`); and its workspace."""
        beam, joint = self.beam, self.joint
        inner = joint.joint if isinstance(joint, Prescribed) else joint
        kind = kernels.KINDS.get(getattr(inner, "compiled_kind", None), kernels.GIVEN)
        self._kind = kind if isinstance(joint, Prescribed) or kind == kernels.FIXED else kernels.GIVEN
        # a hub whose motion is printed (a Prescribed motion in sympy): its row by its C callback in one compiled
        # call (projeq.assembly.given), in place of the motion's Python per evaluation; a callable motion keeps
        # its angles in Python here (its row printed by sympy would cost `projeq run` the import of sympy, for
        # 1.04-1.12x of the spin-up's evaluation)
        printed = not (isinstance(joint, Prescribed) and joint.expression is None)
        callback = given.joint_callback(joint) if self._kind != kernels.FIXED and printed else None
        if not printed:
            self.interpreted = [f"the hub's motion {callable_name(joint.motion)} (θ, θ̇, θ̈ once per evaluation)"]
        self._kind = kernels.GIVEN if callback is not None else self._kind
        self._axis = np.array(inner.axis if self._kind in (kernels.REVOLUTE, kernels.PRISMATIC) else np.zeros(3),
                              dtype=float)
        self._rows = np.zeros((1, max(kernels.GIVEN_F, given.row_width(joint))))
        self._angles, self._given = np.zeros(3), self._rows[0]
        self._table = None if callback is None else given.joint_table(
            [(0, joint, slice(0, 0), slice(0, 0), None)], [callback])
        self._motions = given.motions_kernel() if callback is not None else None
        self._orientation, self._gravity = np.array(joint.orientation, dtype=float), np.array(system.gravity, float)
        self._field = (np.array(beam.mass_weights, dtype=float), *(np.ascontiguousarray(a) for a in beam.slice_field()),
                       np.array(beam.K_e, dtype=float), float(beam.damping),
                       *(np.ascontiguousarray(a) for a in beam.rotation_field()))
        n_y = 6 + beam.n_e
        self._pivot_min = SINGULAR_PIVOT * mass_scale(system)
        self._kernel, self._jacobian = kernels.hub_beam_kernel(True), kernels.hub_beam_jacobian_kernel(True)
        # the kernel's arguments before and after the state, packed once (the hub's rows are overwritten in
        # place); after it the workspace M_n, h_n, M_ee's Cholesky factor and the frame's pose and twist, one
        # per dtype (complex for the complex step)
        self._head = (self._kind, self._axis, self._angles, self._given, self._orientation,
                      np.array(joint.r_pn, dtype=float), self._gravity, *self._field)
        self._tail = {np.dtype(dtype): (self._pivot_min, np.zeros((n_y, n_y), dtype), np.zeros(n_y, dtype),
                                        np.zeros((beam.n_e, beam.n_e), dtype), np.zeros((6, 3), dtype))
                      for dtype in (float, complex)}
        self._pose = _HubPose(self._tail[np.dtype(float)][4])

    def accelerations(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        """q̈_e = M_ee⁻¹ (h_e − M_eR ζ) at (q, ṡ, t) = (q_e, q̇_e, t)."""
        q, s_dot = self._state(q, s_dot)
        if self.compiled:
            x = np.concatenate((q, s_dot))
            x = x.astype(complex if x.dtype.kind == "c" else float)
            x_dot, status = self._compiled(x, t)
            if status >= 0 and not np.all(np.isfinite(x)):
                raise FloatingPointError(f"the state is not finite at t = {t:.6g} (NaN or overflowed): no mass "
                                         "matrix M_ee can be formed")
            return x_dot[len(q):]
        self.n_calls += 1
        joint = self.joint
        hub = joint.relative(self._empty, self._empty, t)
        R = joint.orientation @ hub.A  # the ground is at rest: R_n = A_pn
        y_dot = np.concatenate((hub.w, s_dot))
        M_e, h_e = self.beam.elastic_terms(y_dot, R, self.system.gravity, q)
        return np.linalg.solve(M_e[:, 6:], h_e - M_e[:, :6] @ hub.zeta)

    def _state(self, q, s_dot) -> tuple[NDArray, NDArray]:
        """q_e and q̇_e checked as the kernel reads them, n_e entries each
        (:func:`projeq.checks.kernel_state`)."""
        return kernel_state("q", q, self.beam.n_e), kernel_state("s_dot", s_dot, self.beam.n_e)

    def state_derivative(self, t: float, x: NDArray) -> NDArray | None:
        """ẋ = (q̇_e, q̈_e) at the state x = (q_e, q̇_e) in one compiled call (q̇ = ṡ: the
        beam's elastic coordinates are the system's), for :func:`projeq.simulate`'s
        right-hand side; None when x or ẋ is not finite, or the path is interpreted (the
        caller's checked path then evaluates, and names what is not finite)."""
        if not self.compiled or x.dtype.kind != "f":
            return None
        x_dot, status = self._compiled(x, t)
        return x_dot if status < 0 else None

    def state_jacobian(self, t: float, x: NDArray) -> NDArray | None:
        """∂ẋ/∂x at the real state x = (q_e, q̇_e) by the complex step through the kernel,
        :func:`projeq.assembly.kernels.hub_beam_jacobian`: all n_x columns in one call on the
        complex workspace; None when the path is interpreted or the kernel stops (M_ee singular,
        x or ẋ not finite: the caller's evaluation then raises, naming it)."""
        if not self.compiled:
            return None
        self._check_x(x)
        self._hub(t)
        self.n_calls += len(x)
        J = np.empty((len(x), len(x)))
        status = self._jacobian(*self._head, kernels.kernel_array(x), COMPLEX_STEP, *self._tail[np.dtype(complex)], J)
        return J if status < 0 else None

    def energy(self, q: NDArray, s_dot: NDArray, t: float) -> tuple[float, float]:
        """(kinetic, potential) at the real (q, ṡ, t) = (q_e, q̇_e, t) on the terms of one
        compiled call (:meth:`_evaluate`, :func:`projeq.assembly.kernels.hub_beam`): T = ½ ẏᵀ M_n ẏ
        with the kernel's M_n (the one it solves with) and ẏ = (w, q̇_e), the hub's twist w it
        writes; V, the beam's own potential energy at the pose it writes, R = A_pJ A_Jn,
        r = r_pJ + A_pJ r_Jn (:meth:`projeq.System.potential_energy`); the beam's
        ``check_spin`` at w's ω (the rows of :func:`projeq.simulate` say so). ValueError on the
        interpreted path (the reference energy of ``System.energy(method="recursive")`` is the
        one for it)."""
        if not self.compiled:
            raise ValueError(f"method: the 'hub_beam' energy is compiled only; this system's path is interpreted: "
                             f"{self.interpreted_reason}")
        x = kernels.kernel_array(np.concatenate(self._state(q, s_dot)))
        if self._evaluate(x, t)[1] == 1 and not np.all(np.isfinite(x)):
            raise FloatingPointError(f"the state is not finite at t = {t:.6g} (NaN or overflowed): no energy")
        M, frame = self._tail[x.dtype][1], self._tail[x.dtype][4]
        self.beam.check_spin(frame[5])  # said once where the spin makes an unstiffened beam unstable
        y_dot = np.concatenate((frame[4:].ravel(), x[len(q):]))
        return float(0.5 * (y_dot @ M @ y_dot)), float(self.system.potential_energy(self._pose, x[: len(q)]))

    def _hub(self, t: float) -> None:
        """The hub's row at t into the kernel's: by its C callback where its motion is printed
        (:func:`projeq.assembly.given.given_motions`), else the (θ, θ̇, θ̈) of a Prescribed joint
        (its checked ``angles``) or the numbers of its ``relative_values``."""
        if self._table is not None:
            self._motions(self._table, self._empty, self._empty, float(t), self._rows)
        elif self._kind == kernels.GIVEN:
            self._given[:24] = self.joint.relative_values(self._empty, self._empty, t)[:24]
        elif self._kind != kernels.FIXED:
            angles = self._angles
            angles[0], angles[1], angles[2] = self.joint.angles(t)

    def _compiled(self, x: NDArray, t: float) -> tuple[NDArray, int]:
        """(ẋ, status) of :func:`projeq.assembly.kernels.hub_beam` at (x, t) (:meth:`_evaluate`),
        counted; SingularMassError where it finds M_ee singular (status 0)."""
        self.n_calls += 1
        x_dot, status = self._evaluate(x, t)
        if status == 0:
            raise SingularMassError(f"M_ee of subsystem {self.system.names[0]!r} is singular or indefinite at "
                                    f"t = {t:.6g}: the state has left the range the model describes")
        return x_dot, status

    def _check_x(self, x: NDArray) -> None:
        """ValueError for an x that is not (q_e, q̇_e), 2 n_e entries (the kernel's workspace is
        sized for them)."""
        if x.shape != (2 * self.beam.n_e,):
            raise ValueError(f"x: expected the state (q_e, q̇_e) of 2 n_e = {2 * self.beam.n_e} entries, "
                             f"got shape {x.shape}")

    def _evaluate(self, x: NDArray, t: float) -> tuple[NDArray, int]:
        """(ẋ, status) of one call of :func:`projeq.assembly.kernels.hub_beam` at (x, t), the hub's
        motion first (:meth:`_hub`); its terms stay in the workspace of x's dtype (x checked,
        :meth:`_check_x`)."""
        self._check_x(x)
        self._hub(t)
        x_dot = np.empty(x.shape[0], x.dtype)
        return x_dot, self._kernel(*self._head, x, *self._tail[x.dtype], x_dot)


class _HubPose:
    """The pose of the beam's reference frame as :meth:`projeq.System.potential_energy` reads
    it, R_n and r_n: the beam's, rows of the kernel's ``frame`` (:func:`projeq.assembly.kernels.hub_beam`),
    then the ground's."""

    def __init__(self, frame: NDArray):
        self.R, self.r = (frame[:3], np.eye(3)), (frame[3], np.zeros(3))

"""The order-n passes of docs/theory.md §6 in one compiled loop over flat arrays ("fast").

The System stays frozen; :class:`FastEvaluator` packs its tree once into arrays (parents,
joint kinds, axes, joint frames, masses, r_c, I_c, M_n) and each call runs
:func:`projeq.assembly.kernels.chain_terms` (T_np, ζ_n, F_n, h_n; docs/theory.md §3–4) and
:func:`projeq.assembly.kernels.passes` (Bremer's backward and forward passes, §6).
Both are compiled by numba (a dependency) on first use (cached on
disk); ``method="fast"`` is this kernel or a ValueError saying why not (numba missing, or
a piece of the system the kernel does not know). ``compiled=False`` runs the same kernel
source interpreted (for testing: correct, but slower than the recursive evaluator).
``method="auto"`` (:mod:`projeq.assembly.auto`) picks this evaluator where it can, and
another one where it cannot. :meth:`FastEvaluator.gauss_form` gives M(q) and b of the
Gauss form from the same terms (:func:`projeq.assembly.kernels.gauss_form`, composite
bodies and Newton–Euler, compiled), for coupled joints and for the constrained models of
:mod:`projeq.constraints`, which project it.

Supported: trees of subsystems with rigid-body terms (``rigid_inertia``: :class:`~projeq.RigidBody`,
:class:`~projeq.PointMass`, :class:`~projeq.Frame`, and :class:`~projeq.PlanarBody`, whose
selection S the kernel does not apply: the spatial terms of the same body, projected on
joint velocities that keep it in its plane — which the System checks when it is built —
give the same equations as the selected ones, docs/theory.md §3) on any joint: the kernel
computes the relative motion of the joints whose ``compiled_kind`` it has
(:class:`~projeq.Revolute`, :class:`~projeq.Prismatic`, :class:`~projeq.Fixed`); every
other joint (Planar, Free, Spherical, Screw, Prescribed, UserJoint — non-holonomic ones
too) states it before each call, which the kernel reads (kind ``GIVEN``, 0–6 minimal
velocities): by the C callbacks of its ``compiled_values`` in one compiled call where every
such joint has them (:mod:`projeq.assembly.given`: UserJoints from sympy, Planar, Free,
Prescribed motions in sympy or as callables numba compiles), else by its own
``relative_values``. Coupled joints (gears, ropes: shared minimal velocities) are evaluated in
every joint's own velocities ṡ_all = P ṡ and projected, M = Pᵀ M_all P, b = Pᵀ b_all (B(14)
with ∂ṡ_all/∂ṡ = P), by the compiled Gauss form.
Under gravity and any force laws: between the compiled kinematics and the compiled passes
the laws add their loads to the kernel's h_n — those with constant loads or stated terms
(every law of :mod:`projeq.forces` without a callable load) in compiled code, by the
statement their ``add_to`` calls (:mod:`projeq.assembly.loads`); any other (a callable
load, a user's own law) by its own ``add_to``, reading poses, twists, F_n and T̃_np from
the kernel's workspace (in the selected coordinates of the bodies that have a selection
S, whose loads are then carried back by Sᵀ). One :class:`~projeq.RitzBeam` on a prescribed or fixed hub
has its own fast evaluator, ``method="hub_beam"`` (:mod:`projeq.assembly.beam_fast`); RitzBeams
anywhere in a tree (rotary inertia and torsion included, joints on their stations, beside
coupled joints too) are the kernel's elastic block, from the beams' slice and rotation fields
(:func:`projeq.assembly.kernels.elastic_body`, :func:`~projeq.assembly.kernels.rotary_body`);
any other subsystem without rigid-body terms (a user's subsystem, one that overrides
``gauss_terms``) is refused with the piece named: it is evaluated by the reference ones
(recursive, or dense for coupled joints).

Complex arguments (the complex step of :mod:`projeq.analysis.jacobians`) run the same kernels,
compiled by numba for complex128, on a complex workspace allocated on first use (force laws
and joints of kind GIVEN state their numbers on it too); where no Python runs between the
kernels, :meth:`FastEvaluator.state_derivative` gives ẋ = (ṡ, s̈) and
:meth:`FastEvaluator.state_jacobian` all columns of ∂ẋ/∂x, each in one compiled call
(:func:`projeq.assembly.kernels.tree_state_derivative`, :func:`~projeq.assembly.kernels.tree_jacobian`:
the same evaluation, :func:`~projeq.assembly.kernels.tree_accelerations`, the compiled force
laws' loop included).

>>> import numpy as np, projeq as pq
>>> system = pq.scenes.chain(3)
>>> ev = FastEvaluator(system, compiled=False)
>>> ev.name, ev.compiled
('fast', False)
>>> q, s_dot = np.array([0.5, -0.2, 0.1]), np.array([0.3, 0.0, -1.0])
>>> bool(np.allclose(ev.accelerations(q, s_dot, 0.0), system.accelerations(q, s_dot, method="dense"), atol=1e-12))
True
"""

from __future__ import annotations

import functools
import warnings

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import COMPLEX_STEP
from projeq.assembly import given, kernels, loads
from projeq.assembly.beam_fast import elastic_unsupported, hub_beam_unsupported
from projeq.assembly.kinematics import Kinematics, describing_velocities, selected_chain_terms
from projeq.assembly.linalg import SINGULAR_PIVOT, SingularMassError, column_scales, mass_scales
from projeq.checks import kernel_state
from projeq.forces import ForceLaw
from projeq.joints.standard import MotionValues
from projeq.subsystems.rigid import gravity_potential, rigid_mass_matrix


#: bytes of the output rows' poses and twists that :meth:`FastEvaluator.energies` stacks at once
ROWS_BYTES = 8 * 2**20


class InterpretedWarning(UserWarning):
    """The default evaluator fell back to an interpreted reference evaluator (the message names the
    joint, subsystem or force law the compiled kernel does not know)."""


class PythonPieceWarning(UserWarning):
    """The compiled kernel evaluates a System but states one of its joints or force laws in Python at
    every evaluation (the message names the piece and says how to compile it)."""


#: how to keep a joint and a force law on the compiled path (:class:`PythonPieceWarning`)
HOW_TO_COMPILE = {
    "joint": "state a joint's motion once as statement(q_n, t, m) (docs/architecture.md, 'Adding a joint') or in "
             "sympy (UserJoint.from_sympy; a Prescribed motion as an expression in t, or as a callable t -> "
             "(θ, θ̇, θ̈) written with numpy and math on numbers and arrays, which numba compiles)",
    "force law": "build the loads from the laws of projeq.forces, a load that varies as a callable "
                 "(t, q, s_dot) written with numpy and math on numbers and arrays (numba compiles it), or "
                 "state a load on a body once as a projeq.BodyLoad (docs/architecture.md, 'Adding a force law')",
}


class FastEvaluator:
    """s̈ of one System by the order-n kernel, and its Gauss form by the compiled
    composite-body kernel.

    Parameters
    ----------
    system : System
        A tree the kernel knows (module docstring); otherwise ValueError naming the piece
        it does not know.
    compiled : bool
        True (default): compiled by numba (ValueError if it is not installed); False: the
        same kernel interpreted.

    Attributes: ``name`` ("fast"), ``compiled``, ``n_calls``, ``interpreted`` (the joints and force
    laws it states in Python at every evaluation, by name: compiled, it warns once naming them,
    :class:`PythonPieceWarning`). The workspace (T_np, ζ_n,
    f_n, M̂_n, ĥ_n) is allocated once and overwritten by every call.
    """

    name = "fast"

    def __init__(self, system, compiled: bool = True):
        reason = unsupported(system)
        if reason is not None:
            hub_beam = " (method='hub_beam' is the fast one for it)" if hub_beam_unsupported(system) is None else ""
            raise ValueError(
                f"system: the fast kernel cannot evaluate it: {reason}; method='auto' picks the best "
                f"evaluator available{hub_beam}"
            )
        self.system = system
        self.n_calls = 0
        self.compiled = bool(compiled)
        self._pack(system)
        rigid = bool(np.all(self._index[:, kernels.N_Y] == 6))
        self._chain_terms, self._passes = kernels.kernel(self.compiled, rigid=rigid)
        self._gauss_form, self._projected_accelerations = kernels.gauss_form_kernel(self.compiled, rigid=rigid)
        self._add_loads = loads.kernel(self.compiled) if len(self._laws) else None
        # ẋ and ∂ẋ/∂x in one call where no Python runs between the kernels (no force law without a
        # compiled row, no coupling; joints of kind GIVEN all with compiled values, stated by their C
        # callbacks, given.py): without joints of kind GIVEN every joint has q̇ = ṡ (K = E)
        self._given_motions = given.motions_kernel() if self._given and not self._python_joints and self.compiled \
            else None
        self.interpreted = [f"joint {system.names[n]!r} ({type(system.joints[n]).__name__}"
                            f"{f': {why}' if why else ''})" for n, why in zip(self._python_joints, self._python_joint_why)] \
            + [f"force law {type(law).__name__} ({why})"
               for law, why in zip(self._python_laws, self._python_why)]
        if self.interpreted and self.compiled:
            how = "; ".join(hint for piece, hint in HOW_TO_COMPILE.items()
                            if any(name.startswith(piece) for name in self.interpreted))
            warnings.warn(f"system: {', '.join(self.interpreted)} run in Python at every evaluation, between the "
                          f"compiled kernels (several times slower); to compile: {how}", PythonPieceWarning,
                          stacklevel=3)
        self._x_dot, self._jacobian = None, None
        if not (self._python_laws or system.coupled or self._python_joints):
            self._x_dot, self._jacobian = given.state_kernels(self.compiled, rigid) if self._given else \
                kernels.state_kernels(loads, self.compiled, rigid=rigid)

    def _pack(self, system) -> None:
        """Flat arrays of the tree (built once) and the real workspace (a complex one on first use,
        :class:`_Workspace`); bodies are padded to the largest n_y (6, or 6 + n_e of an elastic
        body) and joints to the most columns of F."""
        N = len(system.joints)
        joints, bodies = system.joints, system.subsystems
        kind = [kernels.KINDS.get(j.compiled_kind, kernels.GIVEN) for j in joints]
        self._given = [n for n in range(N) if kind[n] == kernels.GIVEN]
        # the joints of kind GIVEN without compiled values, or moved by a callable numba cannot compile
        # (given.python_reason), stated in Python; where there are none, their C callbacks' tables of each
        # dtype are built on first use (None where numba cannot compile one)
        python = [(n, given.python_reason(joints[n], self.compiled)) for n in self._given]
        self._python_joints = [n for n, why in python if why is not None]
        self._python_joint_why = [why for _, why in python if why is not None]
        # joints moved by a callable the kernels call compiled (given.motion_callbacks): where s̈ is not
        # finite, the reference evaluator names a motion that is not (Prescribed.angles), as in Python
        self._moved = any(isinstance(joints[n].compiled_values(), MotionValues) for n, why in python if why is None)
        self._tables, self._loop_model = {}, None
        n_cols = [j.n_s + b.n_e for j, b in zip(joints, bodies)]
        # every joint's own coordinates and velocities (and a body's internal ones after them), in
        # the order of the joints (q and ṡ themselves unless joints are coupled: then q_all = P_q q,
        # ṡ_all = P ṡ)
        q_index = np.cumsum([0] + [j.n_q + b.n_e for j, b in zip(joints[:-1], bodies)])
        s_index = np.cumsum([0] + n_cols[:-1])
        self._index = np.array([kind, system.parent, q_index, s_index, n_cols, [6 + b.n_e for b in bodies]],
                               dtype=np.int64).T.copy()  # the columns kernels.KIND ... N_Y
        ports = system.plan.port
        self._geometry = np.array([
            [j.axis if k in (kernels.REVOLUTE, kernels.PRISMATIC) else np.zeros(3),
             np.zeros(3) if ports[n] else j.r_pn, *j.orientation]
            for n, (k, j) in enumerate(zip(kind, joints))
        ], dtype=float).reshape(N, 5, 3)  # the rows kernels.AXIS, OFFSET, ORIENTATION
        self._expansion = _expansion(system) if system.coupled else None
        self._n_all = sum(n_cols)
        rigid = [b.rigid_inertia or (0.0, np.zeros(3), np.zeros((3, 3))) for b in bodies]
        self._inertia = np.array([[r_c, *I_c, (m, 0.0, 0.0)] for m, r_c, I_c in rigid],
                                 dtype=float).reshape(N, 5, 3)  # the rows kernels.CENTRE, INERTIA, MASS
        self._elastic, self._ports = _elastic_fields(system, self._index), _port_fields(system)
        self._width, self._depth = 6 + max(b.n_e for b in bodies), max(6, max(n_cols))
        self._rigid_M = [rigid_mass_matrix(*inertia) for inertia in rigid]
        self._gravity = np.asarray(system.gravity, dtype=float)
        # each joint's pivot against the mass it carries (linalg.mass_scales); the coupled joints' one M
        # factored as D M D = (P D)ᵀ M_all (P D), D = diag(c_j^(−1/2)) with c_j the mass its velocity moves
        # (linalg.column_scales): each pivot of D M D is that of M over c_j, compared with SINGULAR_PIVOT,
        # and s̈ = D (D M D)⁻¹ (−D b)
        self._pivot_min = SINGULAR_PIVOT * mass_scales(system)
        self._D = 1.0 / np.sqrt(column_scales(system)) if system.coupled else None
        self._P_D = self._expansion[1] * self._D if system.coupled else None
        self._given_plan = [
            (n, joints[n], slice(q_index[n], q_index[n] + joints[n].n_q),
             slice(s_index[n], s_index[n] + joints[n].n_s), kernels.GIVEN_F + 6 * joints[n].n_s)
            for n in self._given
        ]
        self._n_cols = n_cols
        self._x_shape = (system.n_q + system.n_s,)
        self._internal = [(n, system.e_s_slice[n]) for n, b in enumerate(bodies) if b.n_e]  # ṡ_e of ẏ_n
        self._laws, self._law_constants, python = loads.compiled_rows(system, self.compiled)
        self._python_laws = [law for law, _ in python]  # their own add_to
        self._python_why = [why for _, why in python]
        # the h_n the force laws load in the reference evaluators' coordinates: rows of n_y for
        # the bodies with a selection S (zeroed before each evaluation), the workspace's rows for
        # the others, none for the ground
        S = system.S[:-1]
        self._selected = [(n, S[n].T) for n in range(N) if S[n] is not None]
        self._S_rows = [None if S[n] is None else S[n].shape[0] for n in range(N)]
        self._workspaces = {}
        self._real = self._workspace(float)

    def _workspace(self, dtype) -> _Workspace:
        """The workspace of ``dtype``: float, or complex for the complex step
        (:mod:`projeq.analysis.jacobians`), allocated on first use and overwritten by every call."""
        dtype = np.dtype(dtype)
        if dtype not in self._workspaces:
            self._workspaces[dtype] = _Workspace(self, dtype)
        return self._workspaces[dtype]

    def _relative_motions(self, ws: _Workspace, q_all: NDArray, s_all: NDArray, t: float) -> None:
        """A, r, w, ζ and F⁶ of the joints of kind GIVEN, one row each: by their C callbacks in one
        compiled call where they all have them (:func:`projeq.assembly.given.given_motions`), else by
        their own ``relative_values`` (the numbers of the ``relative`` the reference evaluators call)."""
        values = ws.given_values
        table = self._joint_table(values.dtype) if self._given_motions is not None and not isinstance(t, complex) \
            else None
        if table is not None:
            self._given_motions(table, q_all, s_all, float(t), values)
            return
        for n, joint, q_n, s_n, width in self._given_plan:
            values[n, :width] = joint.relative_values(q_all[q_n], s_all[s_n], t)

    def _joint_table(self, dtype) -> NDArray | None:
        """The rows of :func:`projeq.assembly.given.joint_table` with the C callbacks of ``dtype`` (float,
        or complex for the complex step) of the joints of kind GIVEN, built on first use; None where
        numba cannot compile one (then they are stated in Python). Interpreted (``compiled=False``):
        their ``compiled_values`` functions."""
        dtype = np.dtype(dtype)
        if dtype not in self._tables:
            joints = [joint for _, joint, _, _, _ in self._given_plan]
            callbacks = [given.joint_callback(joint, dtype) for joint in joints] if self.compiled else joints
            self._tables[dtype] = None if None in callbacks else given.joint_table(self._given_plan, callbacks,
                                                                                     self.compiled)
        return self._tables[dtype]

    def _add_forces(self, ws: _Workspace, q: NDArray, s_dot: NDArray, t: float) -> None:
        """The own ``add_to`` of the laws without a compiled row (a callable load, a user's
        law) on the kernel's kinematics (T̃_np = [[T_np, ζ_n], [0, 1]] from the workspace when a law reads
        it); bodies with a selection S take their loads in their own coordinates (h_n += Sᵀ h_S)."""
        kin, h = ws.kin, ws.h_hat
        kin.stale = True
        h[-1] = 0.0  # the ground's row: reactions land there, nothing reads them
        if self._selected:
            ws.h_S[:] = 0.0
            kin, h = _SelectedKinematics(self.system, kin, s_dot), ws.h_loaded
        for force in self._python_laws:
            force.add_to(h, kin, t, q, s_dot)
        for n, S_T in self._selected:
            ws.h_hat[n] += S_T @ h[n]

    def _kinematics(self, ws: _Workspace, q: NDArray, s_dot: NDArray, t: float) -> tuple[NDArray, NDArray]:
        """The poses, twists, T_np, ζ_n, F_n, M_n and the gravity part of h_n of every body into the
        workspace ``ws`` (:func:`projeq.assembly.kernels.chain_terms`); returns (q_all, ṡ_all), every
        joint's own coordinates and velocities."""
        q_all, s_all = (q, s_dot) if self._expansion is None else (self._expansion[0] @ q, self._expansion[1] @ s_dot)
        if self._given:
            self._relative_motions(ws, q_all, s_all, t)
        self._chain_terms(
            self._index, self._geometry, self._inertia, self._gravity, q_all, s_all, ws.given_values,
            self._elastic, self._ports, ws.T, ws.zeta, ws.F, ws.M_n, ws.h_hat, ws.R, ws.r, ws.twist,
        )
        return q_all, s_all

    def _terms(self, ws: _Workspace, q: NDArray, s_dot: NDArray, t: float) -> None:
        """T_np, ζ_n, F_n, h_n (forces included) of every body into the workspace ``ws``."""
        q_all, s_all = self._kinematics(ws, q, s_dot, t)
        if self._add_loads is not None:
            if isinstance(t, complex) and t.imag and np.any(self._laws[:, loads.CALLBACK]):
                raise ValueError(f"t: the compiled loop of force laws takes a real time, got {t}")
            failed = self._add_loads(self._laws, self._law_constants, self._index, float(np.real(t)), q, s_dot,
                                     q_all, s_all, ws.R, ws.r, ws.twist, ws.F, ws.T, ws.h_hat)
            if failed >= 0:
                self.system.evaluator("recursive").accelerations(q, s_dot, t)  # the law's add_to says why
                raise ValueError(f"forces: law {failed} of the compiled ones cannot be evaluated at t = {t:.6g}")
        if ws.kin is not None:
            self._add_forces(ws, q, s_dot, t)

    def energy(self, q: NDArray, s_dot: NDArray, t: float) -> tuple[float, float]:
        """(kinetic, potential) at the real (q, ṡ, t) on the compiled kinematics (:meth:`_kinematics`):
        T = ½ Σ ẏ_nᵀ M_n ẏ_n with the kernel's M_n (those its passes use, an elastic body's at its
        q_e) and ẏ_n = (twist_n, ṡ_e) (the spatial twist: a planar body's is in its plane); V, the
        subsystems' and force laws' potentials at the kernel's poses
        (:meth:`projeq.System.potential_energy`). Each beam's ``check_spin`` at its ω, as the
        reference's terms do (the rows of :func:`projeq.simulate` say where a spin makes an
        unstiffened beam unstable)."""
        q, s_dot, ws = self._state(q, s_dot)
        if ws is not self._real:
            raise ValueError("q, s_dot: the compiled energy takes a real state; System.energy takes a "
                             "complex step by the reference")
        self._kinematics(ws, q, s_dot, t)
        y_dot = ws.y_dot
        y_dot[:, :6] = ws.twist[:-1]
        for n, e_s in self._internal:
            y_dot[n, 6 : 6 + e_s.stop - e_s.start] = s_dot[e_s]
            self.system.subsystems[n].check_spin(ws.twist[n, 3:6])
        kinetic = 0.5 * np.vdot(y_dot, np.einsum("nij,nj->ni", ws.M_n, y_dot))
        potential = self.system.potential_energy(_SelectedKinematics(self.system, ws, s_dot), q)
        return float(kinetic), float(potential)

    def energies(self, q_rows: NDArray, s_rows: NDArray, times: NDArray) -> NDArray | None:
        """(T, V) of each row (q, ṡ, t) of a run's output, as :meth:`energy` gives them, with one compiled
        kinematics pass per row and T = ½ Σ ẏ_nᵀ M_n ẏ_n and the rigid bodies' gravity potential
        (:func:`projeq.subsystems.rigid.gravity_potential`) for all rows at once; None where a body has
        coordinates of its own or a subsystem or force law a potential of its own (elastic bodies,
        springs: :meth:`energy` row by row)."""
        system = self.system
        if self._internal or system._own_potential or any(type(f).potential is not ForceLaw.potential
                                                          for f in system.forces):
            return None
        ws, rigid, (m, r_c) = self._real, system._rigid_potential[0], system._rigid_potential[1:]
        q_rows, s_rows = np.asarray(q_rows, dtype=float), np.asarray(s_rows, dtype=float)
        if self._expansion is not None:  # every joint's own coordinates and velocities
            q_rows, s_rows = q_rows @ self._expansion[0].T, s_rows @ self._expansion[1].T
        rows_kinematics = kernels.rows_kernel(self.compiled)
        # joints of kind GIVEN: their relative motions at each row's time, in the compiled rows kernel where
        # their callbacks are (given.rows_kernel), else from Python a row at a time
        table = self._joint_table(float) if self._given and self._given_motions is not None else None
        chunk = max(1, ROWS_BYTES // (8 * 6 * ws.twist.size))  # rows stacked at once: R, r and the twists
        energies = np.zeros((len(times), 2))
        for start in range(0, len(times), chunk):
            rows = range(start, min(start + chunk, len(times)))
            twists, R, r = (np.empty((len(rows), *a.shape)) for a in (ws.twist[:-1], ws.R[rigid], ws.r[rigid]))
            by_row = self._given and table is None
            for block in ([slice(k, k + 1) for k in range(len(rows))] if by_row else [slice(0, len(rows))]):
                q_all, s_all = (np.ascontiguousarray(a[start:][block]) for a in (q_rows, s_rows))
                arguments = (self._index, self._geometry, self._inertia, self._gravity, q_all, s_all,
                             ws.given_values, self._elastic, self._ports, ws.T, ws.zeta, ws.F, ws.M_n, ws.h_hat,
                             ws.R, ws.r, ws.twist, rigid, twists[block], R[block], r[block])
                if table is not None:
                    given.rows_kernel()(table, np.ascontiguousarray(times[start:][block], dtype=float), *arguments)
                    continue
                if by_row:  # the relative motions of joints of kind GIVEN at the row's time
                    self._relative_motions(ws, q_all[0], s_all[0], float(times[start + block.start]))
                rows_kinematics(*arguments)
            energies[rows, 0] = 0.5 * np.einsum("kni,nij,knj->k", twists, ws.M_n[:, :6, :6], twists)  # rigid M_n
            if len(rigid):
                energies[rows, 1] = gravity_potential(m, r_c, R, r, system.gravity)
        return energies

    def gauss_form(self, q: NDArray, s_dot: NDArray, t: float) -> tuple[NDArray, NDArray]:
        """M(q) and b(q, ṡ, t) of M s̈ + b = 0 (docs/theory.md §5), by the compiled kernels."""
        self.n_calls += 1
        q, s_dot, ws = self._state(q, s_dot)
        self._terms(ws, q, s_dot, t)
        return self._assembled(ws)

    def _state(self, q, s_dot) -> tuple[NDArray, NDArray, _Workspace]:
        """q and ṡ as C-contiguous arrays of one dtype, float or complex (a complex step), and its
        workspace; ValueError naming q or ṡ when either is not an array of n_q (n_s) numbers
        (:func:`projeq.checks.kernel_state`: the kernels read that many entries, never more)."""
        q, s_dot = kernel_state("q", q, self.system.n_q), kernel_state("s_dot", s_dot, self.system.n_s)
        if q.dtype.kind == "f" and s_dot.dtype.kind == "f":
            return q, s_dot, self._real
        return q.astype(complex), s_dot.astype(complex), self._workspace(complex)

    def _assembled(self, ws: _Workspace) -> tuple[NDArray, NDArray]:
        """M and b of the terms in the workspace: :func:`projeq.assembly.kernels.gauss_form` in
        every joint's own velocities, projected with P for coupled joints."""
        M, b = ws.M_all, ws.b_all
        self._gauss_form(self._index, ws.T, ws.zeta, ws.F, ws.M_n, ws.h_hat, M, b)
        if self._expansion is None:
            return M.copy(), b.copy()
        P = self._expansion[1]
        return P.T @ M @ P, P.T @ b

    def accelerations(self, q: NDArray, s_dot: NDArray, t: float) -> NDArray:
        """s̈ at (q, ṡ, t) (docs/theory.md §6; −M⁻¹ b for coupled joints), complex for complex
        arguments (the complex step of :mod:`projeq.analysis.jacobians`); raises
        SingularMassError for a zero pivot of D_n (of M)."""
        self.n_calls += 1
        q, s_dot, ws = self._state(q, s_dot)
        self._terms(ws, q, s_dot, t)
        s_ddot = np.empty(self.system.n_s, dtype=q.dtype)
        if self._expansion is not None:
            self._assembled(ws)
            failed = self._projected_accelerations(ws.M_all, ws.b_all, self._P_D, SINGULAR_PIVOT, ws.M, s_ddot)
            s_ddot *= self._D
        else:
            failed = self._passes(self._index, ws.T, ws.zeta, ws.F, ws.M_n, ws.M_hat, ws.h_hat, self._pivot_min,
                                  s_ddot)
        if failed >= 0 and not (np.all(np.isfinite(q)) and np.all(np.isfinite(s_dot))):
            raise FloatingPointError(f"the state is not finite at t = {t:.6g} (NaN or overflowed): no pivot D_n "
                                     "can be formed, which no mass matrix explains")
        if failed >= 0 and self._expansion is not None:
            raise SingularMassError("system mass matrix M(q) (of the coupled joints' shared velocities) is singular: "
                                    "a motion along its minimal velocities moves no mass or inertia")
        if failed >= 0:
            self.system.evaluator("recursive").accelerations(q, s_dot, t)  # raises naming the motion that moves nothing
            raise SingularMassError(
                f"D_n = F_nᵀ M̂_n F_n of joint {self.system.names[failed]!r} is singular: "
                "it moves no mass or inertia"
            )
        if self._moved and not np.isfinite(s_ddot).all():
            self.system.evaluator("recursive").accelerations(q, s_dot, t)  # raises naming a motion not finite
        return s_ddot

    def state_derivative(self, t: float, x: NDArray) -> NDArray | None:
        """ẋ = (q̇, s̈) at the real state x = (q, ṡ) in one call,
        :func:`projeq.assembly.kernels.tree_state_derivative` (q̇ = ṡ; the compiled force laws' loads
        included) or with joints of kind GIVEN :func:`projeq.assembly.given.given_state_derivative`
        (their rows and q̇ by their C callbacks), for :func:`projeq.simulate`'s right-hand side; None
        where Python runs between the kernels (as :meth:`state_jacobian`), for a complex x, or where x
        or ẋ is not finite or an evaluation fails (the caller's checked evaluation then raises, naming
        it); ValueError for an x that is not the tree's state (the kernels read n_q + n_s entries)."""
        if self._x_dot is None or x.dtype.kind != "f":
            return None
        if x.shape != self._x_shape:
            self._refuse(x)
        head = self._head(float, t)
        if head is None:
            return None
        self.n_calls += 1
        x_dot = np.empty(len(x))
        tree, workspace = self._one_call_arguments(self._real)
        failed = self._x_dot(*head, *tree, kernels.kernel_array(x), self.system.n_q, *workspace, x_dot)
        return x_dot if failed < 0 else None

    def _refuse(self, x: NDArray) -> None:
        """ValueError: x is not the tree's state (q, ṡ) of n_q + n_s entries."""
        raise ValueError(f"x: expected the tree's state (q, ṡ) of n_q + n_s = {self._x_shape[0]} entries, got shape "
                         f"{x.shape}")

    def _head(self, dtype, t: float) -> tuple | None:
        """The one-call kernels' arguments before the tree's: the time t, after the table of C callbacks
        of ``dtype`` of the joints of kind GIVEN where the tree has them
        (:func:`projeq.assembly.given.given_state_derivative`; None where numba cannot compile one)."""
        if not self._given:
            return (float(t),)
        table = self._joint_table(dtype)
        return None if table is None else (table, float(t))

    def state_jacobian(self, t: float, x: NDArray) -> NDArray | None:
        """∂ẋ/∂x at the real state x = (q, ṡ) by the complex step through the kernels,
        :func:`projeq.assembly.kernels.tree_jacobian`: all n_x columns of ∂s̈/∂x in one call on
        the complex workspace, the compiled force laws' loads included, ∂q̇/∂x = [0, E] (q̇ = ṡ); with
        joints of kind GIVEN :func:`projeq.assembly.given.given_jacobian`, ∂q̇/∂x included (their
        complex callbacks); None where Python runs between the kernels (joints stated in Python only,
        a force law without a compiled row, coupled joints: the caller takes the complex step column
        by column through :meth:`accelerations`) or an evaluation fails (a singular pivot, a
        spring-damper's coincident points: the caller's evaluation then raises, naming it)."""
        if self._jacobian is None:
            return None
        if x.shape != self._x_shape:
            self._refuse(x)
        head = self._head(complex, t)
        if head is None:
            return None
        self.n_calls += len(x)
        n_q = self.system.n_q
        J = np.zeros((len(x), len(x)))
        if not self._given:  # q̇ = ṡ; with joints of kind GIVEN the kernel writes all of ∂ẋ/∂x, ∂q̇/∂x included
            J[:n_q, n_q:] = np.eye(n_q)
        tree, workspace = self._one_call_arguments(self._workspace(complex))
        rows = J if self._given else J[n_q:]
        failed = self._jacobian(*head, *tree, kernels.kernel_array(x), n_q, COMPLEX_STEP, *workspace, rows)
        return J if failed < 0 else None

    def loop_model(self) -> LoopModel | None:
        """The model as the compiled integration loop takes it (:class:`LoopModel`, made once), or None
        where ẋ has no one-call compiled kernel (Python runs between the kernels, or interpreted)."""
        if self._x_dot is None or not self.compiled:
            return None
        if self._loop_model is None:
            head = self._head(float, 0.0)
            if head is None:
                return None
            tree, workspace = self._one_call_arguments(self._real)
            self._loop_model = LoopModel(self._x_dot, head[:-1], tree, workspace)
        return self._loop_model

    def _one_call_arguments(self, ws: _Workspace) -> tuple[tuple, tuple]:
        """The arguments of the one-call kernels (:func:`~projeq.assembly.kernels.tree_state_derivative`,
        :func:`~projeq.assembly.kernels.tree_jacobian`) before the state and after it: the tree and
        its compiled laws; the workspace ``ws`` and the pivot bound."""
        return ((self._index, self._geometry, self._inertia, self._gravity, self._laws, self._law_constants),
                (ws.given_values, self._elastic, self._ports, ws.T, ws.zeta, ws.F, ws.M_n, ws.M_hat, ws.h_hat,
                 ws.R, ws.r, ws.twist, self._pivot_min))


class LoopModel:
    """A model as the compiled integration loop (:mod:`projeq.simulation.loop`) takes it: its ẋ kernel
    ``kernel(*pre, t, *tree, x, n_q, *post, x_dot)`` (as :meth:`FastEvaluator.state_derivative` calls
    it) with the arrays before t, the tree's and the workspace's; ``loops``, the loops compiled for it,
    by method; ``event``: the model's own terminal event where it has one (a ConstrainedSystem's
    partition degenerating, κ − limit rising), as (an array whose first entry the kernel writes at each
    evaluation, the limit that value rises through), which the explicit methods locate in the loop
    (``checks_events``: it has one); ``before()``: called before each compiled segment (state the kernel
    keeps between calls); ``lapack``: the kernel calls LAPACK on matrices large enough that the loop holds
    BLAS to one thread (:func:`projeq.assembly.linalg.one_blas_thread`)."""

    def __init__(self, kernel, pre: tuple, tree: tuple, post: tuple, event: tuple | None = None, before=None,
                 lapack: bool = False):
        self.kernel, self.pre, self.tree, self.post, self.loops = kernel, pre, tree, post, {}
        self.checks_events, self.before, self.lapack = event is not None, before, lapack
        self.event = (np.zeros(1), np.inf) if event is None else event


class _Workspace:
    """The arrays one evaluation of :class:`FastEvaluator` overwrites, of one dtype (float, or
    complex for the complex step): T_np, ζ_n, F_n, M_n, M̂_n, ĥ_n, the poses and twists, one
    row per joint of kind GIVEN for its ``relative_values`` (A, r, w, ζ, F⁶ by columns: the
    entries kernels.GIVEN_A ... GIVEN_F, which the chain terms' kernel copies into F), the Gauss
    form's M and b, and the force laws' kinematics and loads. Every array is C-contiguous: numba
    compiles one specialisation of a kernel per layout of its arguments (a transposed view
    would give F the layouts 'F' for one body and 'A' for more, each another cold compilation)."""

    def __init__(self, ev: FastEvaluator, dtype):
        N, width, depth = len(ev._rigid_M), ev._width, ev._depth
        self.M_all, self.b_all = np.zeros((ev._n_all, ev._n_all), dtype), np.zeros(ev._n_all, dtype)
        self.M = np.zeros((ev.system.n_s,) * 2, dtype)
        self.M_n = np.zeros((N, width, width), dtype)
        self.M_n[:, :6, :6] = ev._rigid_M
        self.given_values = np.zeros((N, max([kernels.GIVEN_F + 36] + [given.row_width(ev.system.joints[n])
                                                                          for n in ev._given])), dtype)
        self.F = np.zeros((N, width, depth), dtype)
        self.T, self.zeta = np.zeros((N, width, width), dtype), np.zeros((N, width), dtype)
        self.y_dot = np.zeros((N, width), dtype)
        self.M_hat, self.h_hat = np.zeros((N, width, width), dtype), np.zeros((N + 1, width), dtype)
        self.R, self.r, self.twist = np.zeros((N + 1, 3, 3), dtype), np.zeros((N + 1, 3), dtype), np.zeros((N + 1, 6), dtype)
        self.kin = _WorkspaceKinematics(ev._n_cols, self.R, self.r, self.twist, self.F, self.T, self.zeta) \
            if ev._python_laws else None
        self.h_S = np.zeros((N, max((S_T.shape[1] for _, S_T in ev._selected), default=0)), dtype)
        self.h_loaded = [self.h_S[n, :k] if k is not None else self.h_hat[n] for n, k in enumerate(ev._S_rows)] \
            + [np.zeros(0, dtype)]


def unsupported(system) -> str | None:
    """Why the fast kernel cannot evaluate ``system`` (None if it can)."""
    for n, (name, joint, body) in enumerate(zip(system.names, system.joints, system.subsystems)):
        if body.n_e:
            reason = elastic_unsupported(body)
            if reason:
                return f"subsystem {name!r} is a {type(body).__name__} {reason}"
            python = loads.compiled_rows(system, kernels.has_numba())[2]
            if python:
                return (f"subsystem {name!r} is elastic in a system with force laws the kernel cannot compile "
                        f"({'; '.join(f'{type(law).__name__}: {why}' for law, why in python)})")
        elif body.rigid_inertia is None:
            return (f"subsystem {name!r} is a {type(body).__name__} (the kernel knows the terms of rigid bodies, "
                    "rigid_inertia, spatial or selected by S, and of RitzBeams)")
        if system.plan.port[n] and not hasattr(system.plan.stations[n], "field"):
            return f"joint {name!r} sits on a port of {type(system.subsystems[system.parent[n]]).__name__} without a field"
    return None


def _elastic_fields(system, index) -> tuple:
    """(slot, e_index, n_e, m_k, r₀, Ψ, Q, K_e, damping, I, Φ_θ, T) of
    :func:`projeq.assembly.kernels.chain_terms`: the station fields of the elastic bodies
    (:meth:`projeq.RitzBeam.slice_field`, :meth:`projeq.RitzBeam.rotation_field`), padded to
    the most stations and internal coordinates (zero masses, rotary inertias and columns);
    e_index: where a body's internal coordinates and velocities start in the kernel's q_all
    and ṡ_all (after its joint's own, in the layout of ``index``, :meth:`FastEvaluator._pack`)."""
    N, beams = len(system.subsystems), [n for n, b in enumerate(system.subsystems) if b.n_e]
    slot = np.full(N, -1, dtype=np.int64)
    own = np.array([[joint.n_q, joint.n_s] for joint in system.joints], dtype=np.int64).reshape(N, 2)
    e_index = index[:, [kernels.Q_INDEX, kernels.S_INDEX]] + own
    n_e = np.array([b.n_e for b in system.subsystems], dtype=np.int64)
    K = max([len(system.subsystems[n].mass_weights) for n in beams], default=1)
    E = max([system.subsystems[n].n_e for n in beams], default=1)
    B = len(beams)
    m, r0, Psi, Q = np.zeros((B, K)), np.zeros((B, K, 3)), np.zeros((B, K, 3, E)), np.zeros((B, K, E, E))
    K_e, damping = np.zeros((B, E, E)), np.zeros(B)
    I, Phi_theta, T = np.zeros((B, K, 3)), np.zeros((B, K, 3, E)), np.zeros((B, K, E, E))
    for i, n in enumerate(beams):
        beam = system.subsystems[n]
        slot[n], k, e = i, len(beam.mass_weights), beam.n_e
        m[i, :k] = beam.mass_weights
        r0[i, :k], Psi[i, :k, :, :e], Q[i, :k, :e, :e] = beam.slice_field()
        I[i, :k], Phi_theta[i, :k, :, :e], T[i, :k, :e, :e] = beam.rotation_field()
        K_e[i, :e, :e], damping[i] = beam.K_e, beam.damping
    return slot, e_index, n_e, m, r0, Psi, Q, K_e, damping, I, Phi_theta, T


def _port_fields(system) -> tuple:
    """(slot, r₀, Ψ, Q, angles, c) of :func:`projeq.assembly.kernels.chain_terms`: the fields of
    the stations that joints sit at (:class:`projeq.subsystems.beam.beam.BeamPort`), padded."""
    N, stations = len(system.joints), system.plan.stations
    slot = np.full(N, -1, dtype=np.int64)
    E = max([system.subsystems[system.parent[n]].n_e for n in stations], default=1)
    P = len(stations)
    r0, Psi, Q, angles, c = np.zeros((P, 3)), np.zeros((P, 3, E)), np.zeros((P, E, E)), np.zeros((P, 3, E)), np.zeros((P, 3))
    for i, (n, port) in enumerate(stations.items()):
        slot[n], e = i, port.field[1].shape[1]
        r0[i], Psi[i, :, :e], Q[i, :e, :e], angles[i, :, :e] = port.field
        c[i] = port.offset
    return slot, r0, Psi, Q, angles, c


def _expansion(system) -> tuple[NDArray, NDArray]:
    """(P_q, P): q_all = P_q q and ṡ_all = P ṡ, every joint's own coordinates and velocities
    (a coupled joint's computed from those it follows) followed by its body's internal ones
    (the layout of :meth:`FastEvaluator._pack`), read off the System's joint getters (linear
    maps) at the unit vectors."""
    def matrix(getter, internal, n):
        return np.column_stack([np.concatenate([np.concatenate((getter(k)(e), e[internal[k]])) for k in range(N)])
                                for e in np.eye(n)])

    N = len(system.joints)
    return (matrix(system.joint_q_getter, system.e_q_slice, system.n_q),
            matrix(system.joint_s_dot_getter, system.e_s_slice, system.n_s))


class _SelectedKinematics(Kinematics):
    """The :class:`~projeq.assembly.kinematics.Kinematics` of the reference evaluators for a
    tree with selections S (ẏ_n = S_n twist, and F_n = S_n F⁶, T̃_np = S̃_n T̃⁶ S̃_pᵀ by
    :func:`projeq.assembly.kinematics.selected_chain_terms`) over the kernel's spatial
    ``kinematics`` (the workspace itself for :meth:`FastEvaluator.energy`'s potentials); ẏ_n
    and the chain terms are computed when a force law first reads them (a force or torque on a
    body, a potential, reads only its pose)."""

    def __init__(self, system, kinematics: Kinematics, s_dot: NDArray):
        self.R, self.r, self.twist = kinematics.R, kinematics.r, kinematics.twist
        self._system, self._spatial, self._s_dot = system, kinematics, s_dot

    @functools.cached_property
    def y_dot(self) -> list:
        return describing_velocities(self._system, self._system.plan, self.twist, self._s_dot)

    @functools.cached_property
    def _chain(self) -> tuple[list, list]:
        spatial = self._spatial
        return selected_chain_terms(self._system, self._system.plan, spatial.F, spatial.T_aug, [None] * len(spatial.F))

    @property
    def T_aug(self) -> list:
        return self._chain[0]

    @property
    def F(self) -> list:
        return self._chain[1]


class _WorkspaceKinematics(Kinematics):
    """The :class:`~projeq.assembly.kinematics.Kinematics` the force laws read, as views of the
    kernel's workspace (poses, twists = ẏ_n, the n_s columns of F_n); the T̃_np stack (the
    ground's row last) is filled from T_np and ζ_n when a law first reads it after an
    evaluation (``stale``): most laws read poses and twists only."""

    def __init__(self, n_cols, R, r, twist, F, T, zeta):
        self.R, self.r, self.twist, self.y_dot = R, r, twist, twist
        self.F = [F[n, :, :k] for n, k in enumerate(n_cols)]
        self._T, self._zeta = T, zeta
        self._T_aug = np.zeros((len(n_cols) + 1, 7, 7), T.dtype)
        self._T_aug[:, 6, 6] = 1.0
        self.stale = True

    @property
    def T_aug(self) -> NDArray:
        if self.stale:
            self._T_aug[:-1, :6, :6] = self._T
            self._T_aug[:-1, :6, 6] = self._zeta
            self.stale = False
        return self._T_aug

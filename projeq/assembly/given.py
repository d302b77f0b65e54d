"""Joints of kind GIVEN in compiled code: their relative motion through C callbacks of their own
printed expressions (docs/theory.md §4).

A joint the kernels of :mod:`projeq.assembly.kernels` do not know (kind ``GIVEN``) states A, r,
w, ζ and F⁶ by its ``relative_values``. Where its ``compiled_values()`` is printed scalar code
(:func:`projeq.joints.user_compiler.printed_values`: a UserJoint from sympy, a Prescribed motion
given in sympy, Planar, Free) — the row A, r, w, ζ, F⁶ followed by its rates q̇ = K ṡ + k — the
same code is compiled by numba as a C callback ``into(q_n, ṡ_n, t, row)`` (:func:`joint_callback`,
float64, or complex128 for the complex step of :mod:`projeq.analysis.jacobians`; built once per
expressions in a process and cached on disk, :func:`generated_module`), which compiled kernels call
through its address (:func:`intrinsics`) for every joint of kind GIVEN of a tree
(:func:`given_motions`, one row per joint of :func:`joint_table`). A Prescribed joint moved by a
callable t ↦ (θ, θ̇, θ̈) has its row printed at θ, θ̇, θ̈ and the callable compiled as a load's is,
its values checked against its own (:func:`motion_callbacks`); one numba cannot compile is stated
in Python, and the fast evaluator names it (:func:`python_reason`). The fast evaluator's one-call
kernels (:func:`given_state_derivative`, :func:`given_jacobian`) then take such trees: ẋ = (q̇, s̈)
with q̇ of those joints from their rows (:func:`given_rates`), and ∂ẋ/∂x, ∂q̇/∂x included, by the
complex step (Squire & Trapp, "Using complex variables to estimate derivatives of real functions",
SIAM Review 40, 1998); the closure kernels of :mod:`projeq.constraints.compiled` call the same
callbacks.
"""

from __future__ import annotations

import functools
import types
from typing import NamedTuple

import numpy as np

from projeq.assembly import kernels, loads
from projeq.assembly.generated import (
    DTYPES,
    callable_callbacks,
    callback,
    frozen_callbacks,
    generated_module,
    intrinsics,
    parameters,
    printed_source,
)
from projeq.assembly.kernels import (
    GIVEN,
    GIVEN_F,
    KIND,
    N_COLS,
    Q_INDEX,
    S_INDEX,
    rows_kinematics,
    tree_accelerations,
    tree_state_derivative,
)
from projeq.checks import callable_name
from projeq.joints.standard import MotionValues


class UncompiledJointWarning(UserWarning):
    """numba could not compile a joint's printed relative motion: it is stated in Python."""


#: the C callback of a joint's printed row (:func:`joint_callback`), at q_n, ṡ_n of one dtype and the
#: joint's parameters p (float64)
JOINT_INTO = """
@numba.cfunc(nb.void(nb.CPointer(nb.{dtype}), nb.CPointer(nb.{dtype}), nb.float64, nb.CPointer(nb.float64),
                     nb.CPointer(nb.{dtype})), cache=True)
def into(q_pointer, s_pointer, t, p_pointer, row_pointer):
    q_n, s_n, row = numba.carray(q_pointer, ({n_q},)), numba.carray(s_pointer, ({n_s},)), numba.carray(row_pointer, ({width},))
    found = function(q_n, s_n, t, numba.carray(p_pointer, ({n_p},)))
    for i in range({width}):
        row[i] = found[i]
"""



#: the C callbacks of a Prescribed joint moved by a callable (:func:`motion_callbacks`): its printed row
#: ``moved_row`` at the values (θ, θ̇, θ̈) at t of the callable printed as ``function(t, p)``
MOTION_INTO = """
@numba.cfunc(nb.void(nb.CPointer(nb.{dtype}), nb.CPointer(nb.{dtype}), nb.float64, nb.CPointer(nb.float64),
                     nb.CPointer(nb.{dtype})), cache=True)
def {name}(q_pointer, s_pointer, t, p_pointer, row_pointer):
    theta, theta_dot, theta_ddot = function(t, numba.carray(p_pointer, ({n_p},)))
    found, row = moved_row(theta, theta_dot, theta_ddot), numba.carray(row_pointer, ({width},))
    for i in range({width}):
        row[i] = found[i]
"""

#: the times at which a motion's compiled values are checked against its own (:func:`motion_callbacks`)
MOTION_TIMES = (0.0, 0.37, 1.9)


class JointCallback(NamedTuple):
    """A joint's C callback as the compiled kernels call it (:func:`joint_table`): its ``address`` and
    its ``parameters`` p (float64, kept alive by the caches that built them), whose address it reads."""

    address: int
    parameters: np.ndarray


def row_width(joint) -> int:
    """The entries of a joint's compiled row: A, r, w, ζ, F⁶ (:data:`projeq.assembly.kernels.GIVEN_F`
    + 6 n_s), then q̇ (n_q)."""
    return GIVEN_F + 6 * joint.n_s + joint.n_q


def joint_callback(joint, dtype=float) -> JointCallback | None:
    """The joint's ``compiled_values()`` (its row, :func:`row_width` entries) compiled as a C callback
    ``into(q_n, ṡ_n, t, p, row)`` at q_n, ṡ_n and row of ``dtype`` (float or complex), t float64 and
    the values p of its constants (:func:`parameters`: data, not code, so joints that differ only in
    their parameters' values share one callback), built once per printed source and dtype in a process
    and cached on disk (:func:`generated_module`), or of a Prescribed joint moved by a callable
    (:func:`motion_callbacks`); None for a joint without compiled values, where numba cannot compile
    its motion (:func:`python_reason` says why), or (after one :class:`UncompiledJointWarning`) where
    numba cannot compile its printed row."""
    values = joint.compiled_values()
    if values is None:
        return None
    if isinstance(values, MotionValues):
        callbacks, p = motion_callbacks(values)
        complex_step = np.dtype(dtype).kind == "c"
        return None if callbacks is None else JointCallback(callbacks[1 if complex_step else 0].address, p)
    into = JOINT_INTO.format(dtype=DTYPES[np.dtype(dtype)], n_q=joint.n_q, n_s=joint.n_s, width=row_width(joint),
                             n_p=len(values.constants))
    back = callback(values, into, f"joint: numba cannot compile the relative motion of {joint!r} for {np.dtype(dtype)}",
                    UncompiledJointWarning)
    return None if back is None else JointCallback(back.address, parameters(values))


def python_reason(joint, compiled: bool = True) -> str | None:
    """Why a joint of kind GIVEN is stated in Python at every evaluation: "" where it has no compiled
    values (a UserJoint from callables), the reason numba cannot compile the callable moving a
    Prescribed joint (``compiled``: :func:`motion_callbacks`); None where the kernels state it."""
    values = joint.compiled_values()
    if values is None:
        return ""
    if compiled and isinstance(values, MotionValues):
        callbacks, why = motion_callbacks(values)
        if callbacks is None:
            return f"numba cannot compile its motion {callable_name(values.motion)} ({why})"
    return None


def motion_callbacks(values: MotionValues) -> tuple:
    """((float64, complex128) C callbacks ``into(q_n, ṡ_n, t, p, row)``, p) of a Prescribed joint moved
    by a callable (``values``: :class:`projeq.joints.standard.MotionValues`): its printed row
    ``moved_row`` at the callable's (θ, θ̇, θ̈) at t, the callable compiled as a load's is and its
    values checked against its own at :data:`MOTION_TIMES` (:func:`projeq.assembly.generated.callable_callbacks`:
    printed from its source with the numbers it reads as the data p, one module per source cached on
    disk, or by ``numba.njit`` with them frozen); or (None, why) where numba cannot compile it."""
    row = values.row
    width = len(row(0.0, 0.0, 0.0))

    def stated_into(n_p: int) -> str:
        return "\n".join([printed_source(row, "moved_row"), *(
            MOTION_INTO.format(dtype=dtype, name=name, n_p=n_p, width=width)
            for dtype, name in (("float64", "into"), ("complex128", "complex_into")))])

    return callable_callbacks(values.motion, ("motion", row.source), [(t,) for t in MOTION_TIMES], 3, stated_into,
                              lambda jitted: _frozen_motion(jitted, row, width))


def _frozen_motion(jitted, row, width: int) -> tuple:
    """The C callbacks of :func:`motion_callbacks` around a compiled callable (its numbers frozen, p
    unread) and its printed row (compiled on its own, :func:`generated_module`)."""
    import numba
    from numba import types as nb

    moved_row = generated_module(row, "").function

    def into(q_pointer, s_pointer, t, p_pointer, row_pointer):
        theta, theta_dot, theta_ddot = jitted(t)
        found, values = moved_row(theta, theta_dot, theta_ddot), numba.carray(row_pointer, (width,))
        for i in range(width):
            values[i] = found[i]

    return frozen_callbacks(into, lambda kind: nb.void(nb.CPointer(kind), nb.CPointer(kind), nb.float64,
                                                       nb.CPointer(nb.float64), nb.CPointer(kind)))


def joint_table(plan, callbacks, compiled: bool = True) -> np.ndarray:
    """One row (n, first coordinate, n_q, first velocity, n_s, callback, parameters) per joint of kind
    GIVEN of a fast evaluator's ``plan`` (its (n, joint, q slice, ṡ slice, width) rows), as
    :func:`given_motions` reads them: the addresses of its C callback and of its parameters' values
    (``callbacks``: :class:`JointCallback`), or interpreted (``compiled=False``) its
    ``compiled_values`` function (its constants in its closure) and None."""
    rows = []
    for (n, joint, q_n, s_n, _), back in zip(plan, callbacks):
        rows.append([n, q_n.start, joint.n_q, s_n.start, joint.n_s, back.address, back.parameters.ctypes.data]
                    if compiled else [n, q_n.start, joint.n_q, s_n.start, joint.n_s, joint.compiled_values(), None])
    return np.array(rows, dtype=np.int64 if compiled else object).reshape(len(rows), 7)


def given_into(values, p, q_n, s_n, t, row):
    """row ← the compiled row (A, r, w, ζ, F⁶, q̇) of a joint of kind GIVEN at (q_n, ṡ_n, t): in the
    compiled kernels ``values`` is the address of its C callback (:func:`joint_callback`, called by
    an intrinsic, :func:`intrinsics`) and ``p`` that of its parameters' values; interpreted, the
    joint's ``compiled_values`` function itself (its constants in its closure)."""
    found = values(q_n, s_n, t)
    row[:found.shape[0]] = found


def given_motions(joints, q, s_dot, t, given):
    """given[n] ← the rows of the tree's joints of kind GIVEN at (q, ṡ, t) (``joints``: one row of
    :func:`joint_table` each), the numbers the fast evaluator's kernels read."""
    for g in range(joints.shape[0]):
        n, q0, n_q, s0, n_s = joints[g, 0], joints[g, 1], joints[g, 2], joints[g, 3], joints[g, 4]
        given_into(joints[g, 5], joints[g, 6], q[q0:q0 + n_q], s_dot[s0:s0 + n_s], t, given[n])


def given_rates(index, elastic, given, x, n_q, x_dot):
    """x_dot[:n_q] ← q̇ at x = (q, ṡ): a joint of kind GIVEN's q̇_n = K ṡ_n + k from its row (after
    F⁶), every other joint's and the elastic bodies' q̇ = ṡ (K = E); for trees without coupled
    joints (q and ṡ in the layout of ``index``). Under this name the one-call kernels of trees with
    joints of kind GIVEN call it in place of q̇ = ṡ (:func:`state_kernels`)."""
    N, n_e = index.shape[0], elastic[2]
    for n in range(N):
        q0, s0 = index[n, Q_INDEX], index[n, S_INDEX]
        k_q = (index[n + 1, Q_INDEX] if n + 1 < N else n_q) - q0 - n_e[n]  # the joint's own coordinates
        k_s = index[n, N_COLS] - n_e[n]
        for i in range(k_q):
            x_dot[q0 + i] = given[n, GIVEN_F + 6 * k_s + i] if index[n, KIND] == GIVEN else x[n_q + s0 + i]
        for i in range(n_e[n]):
            x_dot[q0 + k_q + i] = x[n_q + s0 + k_s + i]


def given_state_derivative(joints, t, index, geometry, inertia, gravity, laws, constants, x, n_q, given, elastic,
                           port, T, zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, x_dot):
    """ẋ = (q̇, s̈) at the state x = (q, ṡ) (real, or complex for a complex step) into x_dot in one
    call for a tree with joints of kind GIVEN: their rows by :func:`given_motions` (``joints``, at
    time t), then :func:`projeq.assembly.kernels.tree_state_derivative` with q̇ by :func:`given_rates`.
    Returns its status (−1: done)."""
    given_motions(joints, x[:n_q], x[n_q:], t, given)
    return tree_state_derivative(t, index, geometry, inertia, gravity, laws, constants, x, n_q, given, elastic, port,
                                 T, zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, x_dot)


def given_jacobian(joints, t, index, geometry, inertia, gravity, laws, constants, x, n_q, step, given, elastic, port,
                   T, zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, J):
    """∂ẋ/∂x of :func:`given_state_derivative` at the real state x by the complex step, column
    k = Im ẋ(x + i step e_k) / step, ∂q̇/∂x included, all n_x columns in one call on a complex
    workspace with the joints' complex callbacks (``joints``); written into J (n_x × n_x). Returns
    −1, or the first failed evaluation's status."""
    n_x = x.shape[0]
    z, z_dot = np.empty(n_x, T.dtype), np.empty(n_x, T.dtype)
    for k in range(n_x):
        z[:] = x
        z[k] += 1j * step
        failed = given_state_derivative(joints, t, index, geometry, inertia, gravity, laws, constants, z, n_q, given,
                                        elastic, port, T, zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, z_dot)
        if failed >= 0:
            return failed
        for i in range(n_x):
            J[i, k] = z_dot[i].imag / step
    return -1


def state_kernels(compiled: bool = True, rigid: bool = False):
    """(:func:`given_state_derivative`, :func:`given_jacobian`) compiled by
    numba (with the ``rigid`` passes of :func:`projeq.assembly.kernels.kernel`; the tree's one-call
    kernels with q̇ by :func:`given_rates`, the callbacks called by :func:`intrinsics`), or with
    ``compiled=False`` interpreted (the joints' ``compiled_values`` functions called as they are)."""
    if not compiled:
        namespace = {**vars(kernels), **globals(), "add_loads": loads.add_loads, "_rates": given_rates}
        for f in (tree_accelerations, tree_state_derivative, given_state_derivative, given_jacobian):
            namespace[f.__name__] = types.FunctionType(f.__code__, namespace, f.__name__)
        return namespace["given_state_derivative"], namespace["given_jacobian"]
    kernels.kernel(True)  # the same refusal without numba
    return _compiled(rigid)


@functools.cache
def _compiled(rigid: bool) -> tuple:
    """:func:`state_kernels` compiled (cached on disk, :func:`projeq.assembly.kernels.jit`)."""
    chain_terms, passes = kernels.kernel(True, rigid=rigid)
    callees = {"chain_terms": chain_terms, "passes": passes, "add_loads": loads.kernel(True), **intrinsics()}
    prefix = "rigid_" if rigid else ""
    return kernels.jit(given_state_derivative, given_jacobian,
                       callees=(given_motions, given_rates, tree_accelerations, tree_state_derivative,
                                given_state_derivative),
                       kernels=callees, names=(prefix + "given_state_derivative", prefix + "given_jacobian"),
                       _rates=given_rates)


def given_rows_kinematics(joints, times, index, geometry, inertia, gravity, q_rows, s_rows, given, elastic, port, T,
                          zeta, F, M, h, R, r_O, twist, bodies, twists, R_rows, r_rows):
    """:func:`projeq.assembly.kernels.rows_kinematics` of a tree with joints of kind GIVEN: at each row,
    their relative motions at the row's time (:func:`given_motions`) first, so that a run's output rows
    take one compiled call, not a Python step per row (the Whipple bicycle's 501 rows: 7 ms of its 13.5 ms
    run over 2 s)."""
    for k in range(q_rows.shape[0]):
        given_motions(joints, q_rows[k], s_rows[k], times[k], given)
        rows_kinematics(index, geometry, inertia, gravity, q_rows[k:k + 1], s_rows[k:k + 1], given, elastic, port,
                        T, zeta, F, M, h, R, r_O, twist, bodies, twists[k:k + 1], R_rows[k:k + 1], r_rows[k:k + 1])


@functools.cache
def rows_kernel():
    """:func:`given_rows_kinematics` compiled (cached on disk), calling the compiled rows kernel."""
    kernels.kernel(True)
    return kernels.jit(given_rows_kinematics, callees=(given_motions,),
                       kernels={"rows_kinematics": kernels.rows_kernel(), **intrinsics()})[0]


@functools.cache
def motions_kernel():
    """:func:`given_motions` compiled alone (the fast evaluator's s̈, whose force laws may run in Python;
    ValueError without numba, as :func:`projeq.assembly.kernels.kernel`)."""
    kernels.kernel(True)
    return kernels.jit(given_motions, kernels=intrinsics())[0]

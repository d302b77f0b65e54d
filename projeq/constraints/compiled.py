"""The constrained s̈ of a closed loop in one compiled call (docs/theory.md §7).

:class:`~projeq.constraints.partitioned.ConstrainedSystem` forms, at every evaluation, the
Jacobian A_s = Φ_q of the loop closures and their second derivative γ = Φ″(q̇, q̇) by the complex
step, the minimal velocities ṡ_tree = F ṡ, s̈_tree = F s̈ + f̄ — by coordinate partitioning,
F = [E; −A_dep⁻¹ A_ind], f̄ = [0; −A_dep⁻¹ γ], or in
:class:`~projeq.constraints.partitioned.TangentSystem` by the null space N of A_s = U Σ Vᵀ,
F = N N_ind⁻¹, f̄ = x₀ − F x₀[independent] with x₀ = A_s⁺(−γ) —,
the tree's Gauss form M s̈_tree + b at ṡ_tree, and solves the Projection Equation with the
constraint inserted before the projection,

    Fᵀ (M (F s̈ + f̄) + b) = 0,

in about fifty numpy calls and two Python calls of Φ. Here the same steps run in one function
compiled by numba (:func:`partitioned`, :func:`tangent`; cached on disk), with the user's Φ itself
compiled (``numba.njit`` of the function as written — a four-bar's ``[a * np.cos(q[0]) + …, …]``
compiles — wrapped as a C callback the kernel calls through its address) at the same complex
points: Φ_q e_j = Im Φ(q + i h e_j) / h and Φ″(v, v) = |v|² Σ_k c_k Im Φ(q + ε_k v̂ + i h v̂) / h
(Martins, Sturdza & Alonso, "The complex-step derivative approximation", ACM TOMS 29, 2003;
the stencil's nodes ε_k and weights c_k are those of :mod:`projeq.constraints.batched`), and
the tree's M and b from the kernels of :mod:`projeq.assembly.kernels` (composite bodies and
Newton–Euler, Featherstone, "Rigid Body Dynamics Algorithms", 2008, §5.3, §6.2) on the fast
evaluator's workspace, with the loads of the tree's force laws added to h_n by the fast
evaluator's own compiled loop over the laws' rows (:func:`projeq.assembly.loads.add_loads`: each
law's terms stated once, in :mod:`projeq.forces`). The numbers are those of the numpy path to
round-off; the tangent kept along the branch is read from and written to the system as the numpy
path keeps it.

Cut joints (Φ made of :class:`~projeq.constraints.cut_joints.PinClosure`, points of rigid bodies or
the frames at a RitzBeam's stations) are the kernels' own: A_s = ∂Φ/∂ṡ_tree row by row from the point's
velocity R_n A_P (T⁶_P ẏ_n + F_P q̇_e)[:3] with the bodies' Jacobians J_n = T_np J_p + F_n, and
γ = Φ̈ at s̈ = 0 from the point's acceleration with ζ̄_n = T_np ζ̄_p + ζ_n (the chain's own terms,
docs/theory.md §4; a station's frame by :func:`projeq.assembly.kernels.port_motion`) — exact, no
complex step, at any speed; :class:`CutJointRows` gives the same Φ, Φ_q and Φ″ to the numpy
path's projections, conditions and residuals.

Pfaffian rows A(q) q̇ = 0 join Φ_q in A_s and γ gains their part (∂(A q̇)/∂q) q̇ = Im A(q + i h q̇) q̇ / h,
A compiled and called as Φ is; the joints of kind GIVEN that are UserJoints from sympy (the
Whipple bicycle's rear frame) state their relative motion A, r, w, ζ, F⁶ by compiled code of
their own expressions (:meth:`~projeq.joints.UserJoint.compiled_values`, a second C callback)
once ṡ_tree = F ṡ is known. Functions printed from sympy
(:func:`projeq.symbolic.codegen.numeric_function`) are compiled once and cached on disk.

Where it applies (:func:`unsupported` says why not): at least one holonomic constraint, Pfaffian
rows with b = 0 and A independent of t, Φ independent of t (``correction="projection"``),
q̇ = ṡ_tree (revolute and prismatic joints, UserJoints from sympy with K = E), a tree whose
whole Gauss form the compiled kernels compute (force laws with compiled rows only — not a
callable load or a user's own ``add_to`` —, no joints that state their own relative motion in
Python, no coupled joints; elastic bodies take the Gauss form's variant that reads each body's
n_y), and F by one of the two rules above (not a
subclass's own, such as the augmented Lagrangian's). A Φ (or A) numba cannot compile, or whose
compiled values differ from its own at complex points near q0, keeps the numpy path after one
:class:`UncompiledClosureWarning` naming it; so does a model outside the kernel, the warning naming
the piece (:func:`unsupported`: a Pfaffian row, a joint, a force law, ...) — never silently.
Where the compiled call meets a degenerate partition (κ bound reached, or N_ind singular) or a
singular FᵀMF it returns a flag and the numpy path
repeats the evaluation, which raises the error that names the cause (so does a force law without
a value, a spring-damper whose two points coincide).
"""

from __future__ import annotations

import functools
import re
import time
import types
import warnings
import weakref

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import COMPLEX_STEP
from projeq.assembly import compilation, kernels, loads
from projeq.assembly.given import generated_module, given_motions, intrinsics, joint_callback, joint_table
from projeq.assembly.kernels import (N_COLS, N_Y, PARENT, S_INDEX, add_cross, add_motion_cross, bias_rates,
                                     chain_matrix_into, cholesky, cholesky_solve, dot6, port_motion)
from projeq.assembly.linalg import SINGULAR_PIVOT, one_blas_thread
from projeq.checks import depends_on_t
from projeq.constraints.batched import NODES, WEIGHTS
from projeq.constraints.cut_joints import point_rows
from projeq.constraints.matrices import RANK_TOLERANCE

#: flags of the kernels (:func:`partitioned`, :func:`tangent`): done; partition bound reached (or
#: A_dep, N_ind singular, or A_s not finite); FᵀMF not positive definite; a force law without a value
#: (a spring-damper whose two points coincide) — the numpy path then raises the error naming it; not
#: compiled yet (:class:`Deferred`: the numpy path evaluates)
DONE, DEGENERATE, SINGULAR, UNLOADED, NOT_COMPILED = 0, 1, 2, 3, -1

#: the share of a partition's event limit from which the compiled loop's ẋ (:func:`partitioned_state_derivative`)
#: writes κ itself, not its bound: below 1, so that round-off between the bound and κ cannot miss the event
EVENT_MARGIN = 0.999

#: the entries of A_s (m · n) from which :func:`_svd` calls LAPACK (faster from 14 × 15 on, its docstring)
LAPACK_SVD_SIZE = 200


class UncompiledClosureWarning(UserWarning):
    """The constrained s̈ of a model is not one compiled call and takes the numpy path (about ten
    times slower per call): the message names the piece — a Φ numba cannot compile, or what
    :func:`unsupported` finds. Said once per model, when its kernel is first looked for."""


def unsupported(system) -> str | None:
    """Why the constrained s̈ of ``system`` (a ConstrainedSystem that forms F by coordinate
    partitioning) cannot be one compiled call (None if it can), module docstring."""
    tree = system.tree
    checks = (
        (system.m_p > 0 and _rheonomic_rows(system),
         "Pfaffian constraints A(q, t) q̇ = b(q, t) with b ≠ 0 or A depending on t"),
        (system.m_h == 0, "no holonomic constraints"),
        (system.correction != "projection", f"correction {system.correction!r} (the kernels project)"),
        (system.rheonomic and point_rows(system._phi) is None, "Φ depends on t (a function of t, not cut joints)"),
        (not system._identity and bool(_kinematics_joints(tree)), _kinematics_piece(tree)),
        (not system.exact, "Φ does not take complex arguments (no complex step)"),
        (not system.compiled_tree(), "the tree's default evaluator is not the compiled one "
                                     f"({tree.evaluator('auto').reason})"),
    )
    for failed, why in checks:
        if failed:
            return why
    return _tree_piece(tree)


def _kinematics_joints(tree) -> list:
    """The joints with q̇ ≠ ṡ (K ≠ E): those with kinematics of their own but a UserJoint from
    sympy whose rates are its speeds (UserJoint.rates_are_speeds)."""
    return [n for n in tree._general_kinematics if not getattr(tree.joints[n], "rates_are_speeds", False)]


def _kinematics_piece(tree) -> str:
    """The joints with q̇ ≠ ṡ (K ≠ E), named."""
    names = [f"{tree.names[n]!r} ({type(tree.joints[n]).__name__})" for n in _kinematics_joints(tree)]
    return f"joints with q̇ ≠ ṡ (K ≠ E){': ' + ', '.join(names) if names else ''}"


def _tree_piece(tree) -> str | None:
    """The first piece of the tree whose terms the kernels do not compute in the closure kernel
    (named), else None."""
    ev = tree.evaluator("fast")
    python = ev._python_joints
    if python:
        n = python[0]
        return (f"joint {tree.names[n]!r} ({type(tree.joints[n]).__name__}) states its own relative motion in "
                "Python (no compiled values: a UserJoint from callables, a Prescribed motion that is a callable numba "
                "cannot compile)")
    if ev._expansion is not None:
        return "coupled joints (shared minimal velocities)"
    for law, why in zip(ev._python_laws, ev._python_why):
        return f"force law {tree.forces.index(law)} ({type(law).__name__}) runs in Python: {why}"
    return None


#: why a subclass of ConstrainedSystem or TangentSystem that restates F or the particular solution
#: takes the numpy path (the kernels state the two rules of the module docstring)
OWN_RULE = "F by its own rule: a subclass's F or particular"


def uncompiled(system, why: str) -> None:
    """One :class:`UncompiledClosureWarning` that the constrained s̈ of ``system`` takes the numpy
    path, and ``why`` (which the system keeps, ``_uncompiled``); None (no kernel), for the caller
    that looks once per model."""
    system._uncompiled = why
    warnings.warn(
        f"system: the constrained s̈ of this {type(system).__name__} is not one compiled call ({why}); it "
        "takes the numpy path (about ten times slower per call)", UncompiledClosureWarning, stacklevel=4,
    )


def _rheonomic_rows(system) -> bool:
    """Whether the Pfaffian rows A(q, t) q̇ = b(q, t) have a b or an A that depends on t
    (:func:`~projeq.checks.depends_on_t`: at q0 and around it)."""
    return system._b is not None or depends_on_t(system._A, system.q0)


def compiled_phi(phi, n: int, m, q0: NDArray, name: str = "phi", jitted=None):
    """``numba.njit(phi)`` if it compiles for q complex (n,), t float and gives Φ's own values
    (``m`` rows, or the shape ``m`` of a matrix such as the Pfaffian rows A), real and imaginary
    parts each to 1e-13 relative, at three complex points near q0; else None after one
    :class:`UncompiledClosureWarning` naming ``phi`` (as the argument ``name``); ``jitted``: its
    compiled form if already built (:func:`~projeq.assembly.given.generated_module`), checked the same way."""
    import numba

    shape = (m,) if np.ndim(m) == 0 else tuple(m)
    rng = np.random.default_rng(11)
    X = q0[:, None] + 1e-2 * rng.standard_normal((n, 3)) + 1j * COMPLEX_STEP * rng.standard_normal((n, 3))
    try:
        jitted = numba.njit(phi) if jitted is None else jitted
        got = np.stack([np.asarray(jitted(x.copy(), 0.0), dtype=complex) for x in X.T], axis=-1)
        want = np.stack([np.asarray(phi(x.copy(), 0.0), dtype=complex) for x in X.T], axis=-1)
    except Exception as exc:  # noqa: BLE001 — numba's typing and lowering errors have no common base
        lines = [line.strip() for line in re.sub(r"\x1b\[[0-9;]*m", "", str(exc)).splitlines() if line.strip()]
        why = f"{type(exc).__name__}: {' '.join(lines[:3])[:300]}"
    else:
        scale = max(1.0, np.abs(want.real).max(initial=0.0))
        rate = max(1.0, np.abs(want.imag / COMPLEX_STEP).max(initial=0.0))
        if got.shape == want.shape == (*shape, 3) and np.all(np.abs(got.real - want.real) <= 1e-13 * scale) \
                and np.all(np.abs(got.imag - want.imag) / COMPLEX_STEP <= 1e-13 * rate):
            return jitted
        why = "its compiled values differ from its own at complex points near q0"
    warnings.warn(
        f"{name}: numba cannot compile {getattr(phi, '__qualname__', repr(phi))} ({why}); the constrained s̈ "
        "takes the numpy path (about ten times slower): write it with numpy operations on scalars q[i] "
        "(no Python objects, dicts or calls of uncompiled functions)",
        UncompiledClosureWarning, stacklevel=4,
    )
    return None


def _key(phi):
    """A hashable key of Φ's code and captured values (one compiled kernel for closures of the
    same source and constants, a scene built twice), else Φ itself."""
    try:
        cells = tuple(_frozen(c.cell_contents) for c in (phi.__closure__ or ()))
        key = (phi.__code__, cells, phi.__defaults__)
        hash(key)
    except (AttributeError, TypeError, ValueError):
        return phi
    return key


def _frozen(value):
    """An array as (dtype, shape, bytes), hashable; anything else as it is."""
    return (value.dtype.str, value.shape, value.tobytes()) if isinstance(value, np.ndarray) else value


_CALLBACKS: dict = {}  # _key(Φ) -> its C callback (numba.cfunc), or None where Φ did not compile


def closure_callback(phi, n: int, m, q0: NDArray, name: str = "phi"):
    """Φ (n coordinates, m rows; or the Pfaffian rows A, ``m`` their shape) compiled as a C
    callback ``into(x, t, value)`` (value ← Φ(x, t), x and value complex, a matrix row by row),
    built once per Φ source and constants in a process — and, for a function printed by
    :func:`projeq.symbolic.codegen.numeric_function`, compiled once and cached on disk
    (:func:`~projeq.assembly.given.generated_module`); None (after one warning) if Φ does not compile (:func:`compiled_phi`)."""
    key = (_key(phi), m)
    if key not in _CALLBACKS:
        size = int(np.prod(m))
        module = _printed_module(phi, _ROWS_INTO.format(n=n, size=size))
        jitted = compiled_phi(phi, n, m, q0, name, None if module is None else module.function)
        _CALLBACKS[key] = None if jitted is None else module.into if module is not None else _callback(jitted, n, m)
    return _CALLBACKS[key]


#: the C callback of a printed Φ or A at complex x (:func:`~projeq.assembly.given.generated_module`; a joint's relative
#: motion: :func:`projeq.assembly.given.joint_callback`)
_ROWS_INTO = """
@numba.cfunc(nb.void(nb.CPointer(nb.complex128), nb.float64, nb.CPointer(nb.complex128)), cache=True)
def into(x_pointer, t, value_pointer):
    x, value = numba.carray(x_pointer, ({n},)), numba.carray(value_pointer, ({size},))
    found = function(x, t).ravel()
    for i in range({size}):
        value[i] = found[i]
"""


def _printed_module(phi, into: str):
    """:func:`~projeq.assembly.given.generated_module` of a function printed by :mod:`projeq.symbolic.codegen` (its
    ``source`` and ``constants``), None for any other or where it does not compile (then
    :func:`compiled_phi` compiles Φ in memory, or warns naming it)."""
    if not (hasattr(phi, "source") and hasattr(phi, "constants")):
        return None
    try:
        return generated_module(phi, into)
    except Exception:  # noqa: BLE001 — numba's typing and lowering errors have no common base
        return None


def _callback(jitted, n: int, m):
    import numba
    from numba import types as nb

    if np.ndim(m) == 0:
        def into(x_pointer, t, value_pointer):
            x, value = numba.carray(x_pointer, (n,)), numba.carray(value_pointer, (m,))
            phi_value = jitted(x, t)
            for r in range(m):
                value[r] = phi_value[r]
    else:
        rows, cols = m

        def into(x_pointer, t, value_pointer):
            x, value = numba.carray(x_pointer, (n,)), numba.carray(value_pointer, (rows, cols))
            phi_value = jitted(x, t)
            for r in range(rows):
                for c in range(cols):
                    value[r, c] = phi_value[r][c]  # an array or nested lists

    pointer = nb.CPointer(nb.complex128)
    return numba.cfunc(nb.void(pointer, nb.float64, pointer))(into)


def phi_into(phi, x, t, value):
    """value ← Φ(x, t): in the compiled kernels ``phi`` is the address of Φ's C callback (an
    intrinsic calls it, :func:`~projeq.assembly.given.intrinsics`); interpreted, ``phi`` is Φ itself."""
    value[:] = np.asarray(phi(x, t))


def _constraint_rows(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, A):
    """A ← A_s = [Φ_q; A(q)] (q̇ = ṡ_tree): Φ_q by :func:`_jacobian` in the first ``m_h`` rows, the
    Pfaffian rows below them (:func:`_pfaffian_rows`). The kernels' variant for cut joints
    (:func:`_compiled`) calls :func:`_pin_constraint_rows` under this name instead."""
    _jacobian(phi, q, t, A[:m_h])
    _pfaffian_rows(pfaffian, q, t, m_h, A)


def _pin_constraint_rows(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, A):
    """:func:`_constraint_rows` of cut joints (``pins``, ``fields``: :func:`pin_table`): their rows by
    :func:`_pin_jacobian` from the tree's chain terms at q and ṡ_tree = 0, its joints of kind GIVEN
    stated there (positions and F⁶ need no velocities; their motions in time alone move the tree),
    which stay in the workspace (:func:`_pin_values`, :func:`_pin_rates`); the Pfaffian rows below."""
    rest = np.zeros(q.shape[0], q.dtype)
    given_motions(joints, q, rest, t, tree[4])
    _chain_terms(tree, q, rest)
    _pin_jacobian(pins, fields, tree, q, A[:m_h])
    _pfaffian_rows(pfaffian, q, t, m_h, A)


#: the constraints' b_s where they do not move in time (:func:`_constraint_rates`): no rows
_AT_REST = np.zeros(0)


def _constraint_rates(pins, joints, fields, tree, q, m_h, m):
    """b_s of A_s ṡ_tree = b_s where the constraints move in time, else an empty array: here always
    (Φ and the Pfaffian rows independent of t: :func:`unsupported`). The kernels' variant for cut
    joints calls :func:`_pin_constraint_rates` under this name instead."""
    return _AT_REST


def _pin_constraint_rates(pins, joints, fields, tree, q, m_h, m):
    """:func:`_constraint_rates` of cut joints: b_s = [−∂Φ/∂t; 0] by :func:`_pin_rates` from the chain
    at ṡ_tree = 0 that :func:`_pin_constraint_rows` leaves in the workspace, where a joint of kind
    GIVEN moves the tree (the Pfaffian rows' b = 0: :func:`unsupported`)."""
    b_s = np.zeros(m if joints.shape[0] else 0)
    if joints.shape[0]:
        _pin_rates(pins, fields, tree, q, b_s[:m_h])
    return b_s


def _pfaffian_rows(pfaffian, q, t, m_h, A):
    """A[m_h:] ← the Pfaffian rows A(q) (``pfaffian``, as Φ in :func:`phi_into`), if any."""
    n, m_p = q.shape[0], A.shape[0] - m_h
    if m_p > 0:
        x, value = np.empty(n, np.complex128), np.empty((m_p, n), np.complex128)
        for i in range(n):
            x[i] = q[i]
        phi_into(pfaffian, x, t, value)
        for r in range(m_p):
            for j in range(n):
                A[m_h + r, j] = value[r, j].real


def _constraint_gamma(phi, pins, fields, pfaffian, joints, tree, q, q_dot, t, m_h, m):
    """γ = [Φ″(q̇, q̇); (∂(A q̇)/∂q) q̇] at q̇ = ṡ_tree: Φ″ by :func:`_gamma`, the Pfaffian part by
    :func:`_pfaffian_gamma`. The kernels' variant for cut joints calls :func:`_pin_constraint_gamma`
    under this name instead."""
    gamma = np.zeros(m)
    gamma[:m_h] = _gamma(phi, q, q_dot, t, m_h)
    _pfaffian_gamma(pfaffian, q, q_dot, t, m_h, gamma)
    return gamma


def _pin_constraint_gamma(phi, pins, fields, pfaffian, joints, tree, q, q_dot, t, m_h, m):
    """:func:`_constraint_gamma` of cut joints: their part by :func:`_pin_gamma` from the tree's chain
    terms at (q, q̇ = ṡ_tree), its joints of kind GIVEN stated there; the Pfaffian part below it."""
    gamma = np.zeros(m, q.dtype)
    given_motions(joints, q, q_dot, t, tree[4])
    _chain_terms(tree, q, q_dot)
    _pin_gamma(pins, fields, tree, q, q_dot, gamma[:m_h])
    _pfaffian_gamma(pfaffian, q, q_dot, t, m_h, gamma)
    return gamma


def _pfaffian_gamma(pfaffian, q, q_dot, t, m_h, gamma):
    """gamma[m_h:] ← (∂(A q̇)/∂q) q̇ as the numpy path takes it, Im (A(q + i h q̇) q̇) / h (A independent
    of t, b = 0: :func:`unsupported`), if there are Pfaffian rows."""
    n, m_p = q.shape[0], gamma.shape[0] - m_h
    if m_p > 0:
        x, value = np.empty(n, np.complex128), np.empty((m_p, n), np.complex128)
        for i in range(n):
            x[i] = q[i] + 1j * COMPLEX_STEP * q_dot[i]
        phi_into(pfaffian, x, t, value)
        for r in range(m_p):
            total = 0.0
            for j in range(n):
                total += value[r, j].imag * q_dot[j]
            gamma[m_h + r] = total / COMPLEX_STEP


def _pin_frame(pins, fields, elastic, r, side, q, s_dot, A_port, r_port, F_port, zeta_port):
    """The frame P of the point on side ``side`` (0: a, 1: b) of cut-joint row r relative to its
    body n, which it returns (−1: the ground): for a rigid body the point ρ (A = E, r = ρ, F = 0,
    ζ = 0); for the station of an elastic body (``pins[r, 3 + side]``: its slot of ``fields``,
    :func:`pin_table`) the station's frame by :func:`projeq.assembly.kernels.port_motion` — its
    pose, the columns F (k = n_e) of its twist F q̇_e and ζ = Ḟ q̇_e."""
    n, slot = int(pins[r, side]), int(pins[r, 3 + side])
    if n < 0:
        return n
    if slot >= 0:
        n_e, e_index, k_max = elastic[2], elastic[1], (fields.shape[2] - 2) // 2
        k, i0, s0 = n_e[n], e_index[n, 0], e_index[n, 1]
        field = fields[slot]
        port_motion(field[:3, 0], field[:3, 2:2 + k], field[3:3 + k, :k], field[:3, 2 + k_max:2 + k_max + k],
                    field[:3, 1], q[i0:i0 + k], s_dot[s0:s0 + k], A_port, r_port, F_port[:, :k], zeta_port)
        return n
    A_port[:, :] = 0.0
    for a in range(3):
        A_port[a, a] = 1.0
        r_port[a] = pins[r, 5 + 3 * side + a]
    F_port[:, :] = 0.0
    zeta_port[:] = 0.0
    return n


def _port_chain(A_port, r_port, T6):
    """T6 ← T⁶ = [[A_Pᵀ, −A_Pᵀ r̃_P], [0, A_Pᵀ]] of a frame P at r_P, turned by A_P."""
    A_np = np.empty((3, 3), A_port.dtype)
    for a in range(3):
        for b in range(3):
            A_np[a, b] = A_port[b, a]
    chain_matrix_into(A_np, r_port, T6)


def cut_joint_rows(pins, fields, joints, tree, q, q_dot, t, values, A, b_s, gamma):
    """Φ, Φ_q = A_s (K = E), b_s = −∂Φ/∂t and γ = Φ̈ at s̈_tree = 0 of cut joints alone (the rows a
    ConstrainedSystem asks for outside its accelerations: projections, conditions, residuals), by the
    kernels' own helpers (a Φ of cut joints alone: no Φ callback, no Pfaffian rows): Φ, A_s and b_s
    from the chain at ṡ_tree = 0 (:func:`_pin_constraint_rows`, :func:`_pin_values`,
    :func:`_pin_rates`), γ by :func:`_pin_constraint_gamma` where q̇ ≠ 0 or a joint of kind GIVEN moves
    the tree."""
    m_h = pins.shape[0]
    _pin_constraint_rows(0, pins, fields, 0, joints, tree, q, t, m_h, A)
    _pin_values(pins, fields, tree, q, values)
    if joints.shape[0]:  # only joints of kind GIVEN move the tree at ṡ_tree = 0
        _pin_rates(pins, fields, tree, q, b_s)
    if joints.shape[0] or np.any(q_dot != 0.0):
        gamma[:] = _pin_constraint_gamma(0, pins, fields, 0, joints, tree, q, q_dot, t, m_h, m_h)
    else:
        gamma[:] = 0.0


def _pin_values(pins, fields, tree, q, values):
    """values[r] ← Φ_r = (P_a − P_b)[axis] of cut-joint row r: P = r_n + R_n r_P with r_P the point's
    frame (:func:`_pin_frame`), or ρ_b itself for the ground."""
    elastic, R, r_O, k_max, dtype = tree[5], tree[12], tree[13], (fields.shape[2] - 2) // 2, q.dtype
    A_port, r_port = np.empty((3, 3), dtype), np.empty(3, dtype)
    F_port, zeta_port, rest = np.empty((6, k_max), dtype), np.empty(6, dtype), np.zeros(q.shape[0], dtype)
    for r in range(pins.shape[0]):
        axis, values[r] = int(pins[r, 2]), 0.0
        for side in range(2):
            sign = 1.0 if side == 0 else -1.0
            n = _pin_frame(pins, fields, elastic, r, side, q, rest, A_port, r_port, F_port, zeta_port)
            if n < 0:
                values[r] += sign * pins[r, 5 + 3 * side + axis]
            else:
                values[r] += sign * (r_O[n, axis] + R[n, axis, 0] * r_port[0] + R[n, axis, 1] * r_port[1]
                                     + R[n, axis, 2] * r_port[2])


def _pin_rates(pins, fields, tree, q, b_s):
    """b_s[r] ← −Φ̇_r of cut-joint row r with the bodies' twists in the tree's workspace (at ṡ_tree = 0:
    those of its joints prescribed in time, so Φ̇ = ∂Φ/∂t): the points' velocities R_n A_P v_P,
    (v_P, ω_P) = T⁶_P ẏ_n (:func:`_pin_jacobian`; the stations' own rates are 0 at rest)."""
    elastic, R, twist = tree[5], tree[12], tree[14]
    k_max, dtype = (fields.shape[2] - 2) // 2, twist.dtype
    A_port, r_port, F_port, zeta_port = np.empty((3, 3), dtype), np.empty(3, dtype), np.empty((6, k_max), dtype), \
        np.empty(6, dtype)
    T6, e, rest = np.empty((6, 6), dtype), np.empty(3, dtype), np.zeros(q.shape[0], dtype)
    for r in range(pins.shape[0]):
        axis = int(pins[r, 2])
        b_s[r] = 0.0
        for side in range(2):
            n = _pin_frame(pins, fields, elastic, r, side, q, rest, A_port, r_port, F_port, zeta_port)
            if n < 0:
                continue
            _port_chain(A_port, r_port, T6)
            _inertial_axis(R, n, axis, A_port, e)
            sign = -1.0 if side == 0 else 1.0
            for a in range(3):
                b_s[r] += sign * e[a] * dot6(T6[a], twist[n])


def _pin_jacobian(pins, fields, tree, q, A):
    """A[r] ← the row ∂Φ_r/∂ṡ_tree of cut-joint row r (one inertial ``axis`` of P_a − P_b; the
    points' frames by :func:`_pin_frame`), from the point's velocity R_n A_P v_P with the twist of
    its frame P, (v_P, ω_P) = T⁶_P (v_n, ω_n) + F_P q̇_e (the chain step of a joint's base frame,
    T⁶ = [[A_Pᵀ, −A_Pᵀ r̃_P], [0, A_Pᵀ]]), and the bodies' twists ẏ_n = J_n ṡ_tree: the Jacobians
    J_n = ∂ẏ_n/∂ṡ_tree by the chain, J_n = T_np J_p + F_n (in the columns of joint n's ṡ_n)."""
    index, elastic, T, F, R = tree[0], tree[5], tree[7], tree[9], tree[12]
    n_s, k_max, dtype, n_y = A.shape[1], (fields.shape[2] - 2) // 2, T.dtype, index[:, N_Y]
    J = np.zeros((index.shape[0], T.shape[1], n_s), dtype)
    _body_jacobians(index, T, F, J)
    A_port, r_port, F_port, zeta_port = np.empty((3, 3), dtype), np.empty(3, dtype), np.empty((6, k_max), dtype), \
        np.empty(6, dtype)
    T6, v, e, rest = np.empty((6, 6), dtype), np.empty(3, dtype), np.empty(3, dtype), np.zeros(q.shape[0], dtype)
    A[:, :] = 0.0
    for r in range(pins.shape[0]):
        axis = int(pins[r, 2])
        for side in range(2):
            n = _pin_frame(pins, fields, elastic, r, side, q, rest, A_port, r_port, F_port, zeta_port)
            if n < 0:
                continue
            _port_chain(A_port, r_port, T6)
            sign, k = 1.0 if side == 0 else -1.0, n_y[n] - 6
            _inertial_axis(R, n, axis, A_port, e)
            for j in range(n_s):
                for a in range(3):  # v_P of the unit velocity ṡ_tree = e_j
                    v[a] = dot6(T6[a], J[n, :6, j])
                    for i in range(k):
                        v[a] += F_port[a, i] * J[n, 6 + i, j]
                A[r, j] += sign * (e[0] * v[0] + e[1] * v[1] + e[2] * v[2])


def _body_jacobians(index, T, F, J):
    """J[n] ← J_n = ∂ẏ_n/∂ṡ_tree root → leaves: J_n = T_np J_p + F_n in the columns of joint n's ṡ_n."""
    n_y, parent, s_index, n_cols = index[:, N_Y], index[:, PARENT], index[:, S_INDEX], index[:, N_COLS]
    for n in range(index.shape[0]):
        p, m = parent[n], n_y[n]
        if p >= 0:
            for a in range(m):
                for j in range(J.shape[2]):
                    J[n, a, j] = 0.0
                    for c in range(n_y[p]):
                        J[n, a, j] += T[n, a, c] * J[p, c, j]
        for c in range(n_cols[n]):
            for a in range(m):
                J[n, a, s_index[n] + c] += F[n, a, c]


def _inertial_axis(R, n, axis, A_port, e):
    """e ← (R_n A_P)ᵀ e_axis: the inertial direction ``axis`` in the axes of the point's frame P."""
    for a in range(3):
        e[a] = R[n, axis, 0] * A_port[0, a] + R[n, axis, 1] * A_port[1, a] + R[n, axis, 2] * A_port[2, a]


def _pin_gamma(pins, fields, tree, q, s_dot_tree, gamma):
    """γ_r = (Φ̈_r at s̈_tree = 0) of cut-joint row r: the point's acceleration R_n A_P (v̇_P + ω_P × v_P)
    with its frame's twist (v_P, ω_P) = u + w, u = T⁶_P ẏ_n, w = F_P q̇_e, and its rate at s̈ = 0,
    ζ̄_P = T⁶_P ζ̄_n + F_P q̈_e + u × w + ζ_P (the chain's step, docs/theory.md §4), with the bodies'
    rates at s̈ = 0, ζ̄_n = T_np ζ̄_p + ζ_n (the components' derivatives in body axes)."""
    index, elastic, T, zeta, R, twist = tree[0], tree[5], tree[7], tree[8], tree[12], tree[14]
    k_max, dtype, n_y = (fields.shape[2] - 2) // 2, T.dtype, index[:, N_Y]
    zeta_bar = np.zeros((index.shape[0], T.shape[1]), dtype)
    bias_rates(index, T, zeta, zeta_bar)
    A_port, r_port, F_port, zeta_port = np.empty((3, 3), dtype), np.empty(3, dtype), np.empty((6, k_max), dtype), \
        np.empty(6, dtype)
    T6, u, w, rate = np.empty((6, 6), dtype), np.empty(6, dtype), np.empty(6, dtype), np.empty(6, dtype)
    acc, e = np.empty(3, dtype), np.empty(3, dtype)
    for r in range(pins.shape[0]):
        axis = int(pins[r, 2])
        gamma[r] = 0.0
        for side in range(2):
            n = _pin_frame(pins, fields, elastic, r, side, q, s_dot_tree, A_port, r_port, F_port, zeta_port)
            if n < 0:
                continue
            _port_chain(A_port, r_port, T6)
            sign, k, s0 = 1.0 if side == 0 else -1.0, n_y[n] - 6, elastic[1][n, 1]
            for a in range(6):
                u[a] = dot6(T6[a], twist[n])
                rate[a] = dot6(T6[a], zeta_bar[n, :6]) + zeta_port[a]
                w[a] = 0.0
                for i in range(k):
                    w[a] += F_port[a, i] * s_dot_tree[s0 + i]
                    rate[a] += F_port[a, i] * zeta_bar[n, 6 + i]
            add_motion_cross(u, w, rate)
            for a in range(6):
                u[a] += w[a]  # the frame's twist
            for a in range(3):  # v̇_P + ω_P × v_P
                acc[a] = rate[a]
            add_cross(u[3:], u[:3], acc)
            _inertial_axis(R, n, axis, A_port, e)
            gamma[r] += sign * (e[0] * acc[0] + e[1] * acc[1] + e[2] * acc[2])


def _jacobian(phi, q, t, A):
    """A ← Φ_q: column j = Im Φ(q + i h e_j) / h."""
    n, m = A.shape[1], A.shape[0]
    x, value = np.empty(n, np.complex128), np.empty(m, np.complex128)
    for j in range(n):
        for i in range(n):
            x[i] = q[i]
        x[j] = q[j] + 1j * COMPLEX_STEP
        phi_into(phi, x, t, value)
        for r in range(m):
            A[r, j] = value[r].imag / COMPLEX_STEP


def _gamma(phi, q, q_dot, t, m):
    """γ = Φ″(q̇, q̇) = |q̇|² Σ_k c_k Im Φ(q + ε_k u + i h u) / h, u = q̇/|q̇|: the complex step
    inside the sixth-order stencil of :mod:`projeq.constraints.batched`."""
    n = q.shape[0]
    x, value, gamma = np.empty(n, np.complex128), np.empty(m, np.complex128), np.zeros(m)
    speed = np.sqrt(np.sum(q_dot * q_dot))
    if speed == 0.0:
        return gamma
    for node in range(NODES.shape[0]):
        for i in range(n):
            u = q_dot[i] / speed
            x[i] = q[i] + u * NODES[node] + 1j * COMPLEX_STEP * u
        phi_into(phi, x, t, value)
        for r in range(m):
            gamma[r] += WEIGHTS[node] * (value[r].imag / COMPLEX_STEP)
    for r in range(m):
        gamma[r] *= speed * speed
    return gamma


def _matvec(F, v):
    """F v (loops: the matrices are small, and numba's @ wants contiguous operands)."""
    out = np.zeros(F.shape[0])
    for i in range(F.shape[0]):
        for c in range(F.shape[1]):
            out[i] += F[i, c] * v[c]
    return out


def _matmul(A, B):
    """A B (loops, as :func:`_matvec`)."""
    out = np.zeros((A.shape[0], B.shape[1]))
    for i in range(A.shape[0]):
        for j in range(A.shape[1]):
            for c in range(B.shape[1]):
                out[i, c] += A[i, j] * B[j, c]
    return out


def _chain_terms(tree, q, s_dot_tree):
    """The tree's chain terms, poses, twists and h_n at (q, ṡ_tree) into its workspace (the
    relative motions of its joints of kind GIVEN stated before)."""
    index, geometry, inertia, gravity, given, elastic, port, T, zeta, F_n, M_n, h, R, r_O, twist, laws, constants = tree
    chain_terms(index, geometry, inertia, gravity, q, s_dot_tree, given, elastic, port, T, zeta, F_n, M_n, h, R, r_O,
                twist)


def _projected(tree, q, s_dot_tree, t, F, f_bar, pivot, M, b, s_ddot_tree):
    """The tree's M, b at (q, ṡ_tree) by the compiled kernels (its joints of kind GIVEN stated
    there), the loads of its force laws added to h_n by their compiled rows
    (:func:`projeq.assembly.loads.add_loads`, the loop of the fast evaluator), then s̈ from
    Fᵀ(M (F s̈ + f̄) + b) = 0 and s̈_tree ← F s̈ + f̄; DONE, UNLOADED where a law cannot be evaluated,
    or SINGULAR where a squared pivot of FᵀMF is not above ``pivot`` times its largest diagonal entry."""
    _chain_terms(tree, q, s_dot_tree)
    index, T, zeta, F_n, M_n, h = tree[0], tree[7], tree[8], tree[9], tree[10], tree[11]
    R, r_O, twist, laws, constants = tree[12], tree[13], tree[14], tree[15], tree[16]
    if laws.shape[0] and add_loads(laws, constants, index, t, q, s_dot_tree, q, s_dot_tree, R, r_O, twist, F_n, T,
                                   h) >= 0:
        return UNLOADED
    gauss_form(index, T, zeta, F_n, M_n, h, M, b)
    n, k = F.shape
    MF, g = np.zeros((n, k)), b.copy()  # M F and M f̄ + b
    for i in range(n):
        for j in range(n):
            g[i] += M[i, j] * f_bar[j]
            for c in range(k):
                MF[i, c] += M[i, j] * F[j, c]
    M_min, s_ddot = np.zeros((k, k)), np.zeros(k)  # FᵀMF and −Fᵀ(M f̄ + b)
    for r in range(k):
        for i in range(n):
            s_ddot[r] -= F[i, r] * g[i]
            for c in range(k):
                M_min[r, c] += F[i, r] * MF[i, c]
    scale = 1e-300
    for c in range(k):
        scale = max(scale, abs(M_min[c, c]))
    if k == 1:  # a division, as the numpy path's solve
        if not M_min[0, 0] > pivot * scale:
            return SINGULAR
        s_ddot[0] = s_ddot[0] / M_min[0, 0]
    elif cholesky(M_min, k, pivot * scale):
        cholesky_solve(M_min, k, s_ddot)
    else:
        return SINGULAR
    for i in range(n):  # F s̈ + f̄
        total = 0.0
        for c in range(k):
            total += F[i, c] * s_ddot[c]
        s_ddot_tree[i] = total + f_bar[i]
    return DONE


def partitioned(phi, pins, fields, pfaffian, joints, tree, q, s_dot, t, m_h, independent, dependent, bound, pivot,
                q_dot, s_ddot_tree, A, M, b, kappa):
    """The constrained s̈ of :class:`~projeq.constraints.partitioned.ConstrainedSystem` (module
    docstring) from Φ (``phi``: :func:`phi_into`; ``m_h`` rows) and the Pfaffian rows A(q)
    (``pfaffian``), the tree's packed arrays and workspace (``tree``: those of
    :func:`projeq.assembly.kernels.chain_terms`) with its joints of kind GIVEN (``joints``:
    :func:`given_motions`), q, ṡ, t and the partition; ṡ_tree = F ṡ + f with f = [0; A_dep⁻¹ b_s]
    (b_s = −∂Φ/∂t of cut joints across joints prescribed in time, else 0); writes q̇ = ṡ_tree (K = E), s̈_tree,
    A_s = [Φ_q; A], M and b, and ‖A_s‖_F ‖A_dep⁻¹‖_F (≥ κ) into ``kappa[0]``; returns DONE, SINGULAR
    (:func:`_projected`) or DEGENERATE where that bound is not below ``bound``."""
    n, m = q.shape[0], dependent.shape[0]
    _constraint_rows(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, A)
    F, inv, s_dot_tree = _partition(pins, joints, fields, tree, q, s_dot, m_h, A, independent, dependent, kappa)
    if not kappa[0] < bound:
        return DEGENERATE
    q_dot[:] = s_dot_tree
    gamma = _constraint_gamma(phi, pins, fields, pfaffian, joints, tree, q, s_dot_tree, t, m_h, m)
    f_bar = np.zeros(n)  # f̄ = [0; −A_dep⁻¹ γ]
    minus_gamma = _matvec(inv, -gamma)
    for r in range(m):
        f_bar[dependent[r]] = minus_gamma[r]
    given_motions(joints, q, s_dot_tree, t, tree[4])
    return _projected(tree, q, s_dot_tree, t, F, f_bar, pivot, M, b, s_ddot_tree)


def _partition(pins, joints, fields, tree, q, s_dot, m_h, A, independent, dependent, kappa):
    """(F, A_dep⁻¹, ṡ_tree = F ṡ + f) of coordinate partitioning from A_s (``A``, at q, with the
    workspace :func:`_constraint_rows` leaves): F = [E; −A_dep⁻¹ A_ind], f = [0; A_dep⁻¹ b_s]; writes
    ‖A_s‖_F ‖A_dep⁻¹‖_F (≥ κ) into ``kappa[0]`` (F not finite where A_dep is singular)."""
    n, m, k = q.shape[0], dependent.shape[0], independent.shape[0]
    A_dep = np.empty((m, m))
    for r in range(m):
        for c in range(m):
            A_dep[r, c] = A[r, dependent[c]]
    inv = _inverse(A_dep)
    kappa[0] = np.sqrt(np.sum(A * A)) * np.sqrt(np.sum(inv * inv))
    F = np.zeros((n, k))  # F = [E; −A_dep⁻¹ A_ind]
    for c in range(k):
        F[independent[c], c] = 1.0
        for r in range(m):
            total = 0.0
            for i in range(m):
                total += inv[r, i] * A[i, independent[c]]
            F[dependent[r], c] = -total
    s_dot_tree = _matvec(F, s_dot)
    b_s = _constraint_rates(pins, joints, fields, tree, q, m_h, m)
    if b_s.shape[0]:  # ṡ_tree = F ṡ + f, f = [0; A_dep⁻¹ b_s]
        f = _matvec(inv, b_s)
        for r in range(m):
            s_dot_tree[dependent[r]] += f[r]
    return F, inv, s_dot_tree


def closure_rows(phi, pins, fields, pfaffian, joints, tree, q_rows, s_rows, times, m_h, independent, partitioned,
                 dependent, bound, rank, separation, acting, kept, tolerance, rank_tolerance, max_iter, q_out,
                 s_tree_out, residuals, ranks):
    """The output rows of :class:`~projeq.constraints.partitioned.ConstrainedSystem` (its ``output_row``
    after ``normalized``, K = E) at the states (``q_rows``, ``s_rows``) and ``times``: q moved onto
    Φ(q, t) = 0 by minimum-norm Gauss–Newton steps q ← q − Φ_q⁺ Φ (singular values below
    ``rank_tolerance`` σ_max dropped; converged where |Φ| ≤ ``tolerance`` · max(1, |q|), at most
    ``max_iter`` evaluations, :func:`_projected_onto`), ṡ_tree = F ṡ + f there — ``partitioned``: by
    :func:`_partition` (``dependent``, ``bound``), else by the null-space rule of
    :class:`~projeq.constraints.partitioned.TangentSystem` (:func:`_tangent_velocities`: ``rank``,
    ``separation``, ``acting``, the tangent ``kept`` continued from row to row in their order, as the
    numpy path's rows continue it) —, the residuals (Φ(q, t), A q̇) and the rank of A_s, into ``q_out``,
    ``s_tree_out``, ``residuals``, ``ranks`` (:func:`_write_row`). Returns the number of rows done: fewer
    where a row's projection does not converge, its partition reaches ``bound`` or its N_ind is singular
    (the numpy path then names why)."""
    A, values, kappa = np.zeros((residuals.shape[1], q_rows.shape[1])), np.zeros(m_h), np.zeros(1)
    for row in range(q_rows.shape[0]):
        q, t = q_rows[row].copy(), times[row]
        if not _projected_onto(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, tolerance, rank_tolerance,
                               max_iter, A, values):
            return row
        if partitioned:
            _, _, s_dot_tree = _partition(pins, joints, fields, tree, q, s_rows[row], m_h, A, independent,
                                          dependent, kappa)
            done, sigma = kappa[0] < bound, np.linalg.svd(A)[1]
        else:
            _, sigma, _, _, F, s_dot_tree = _tangent_velocities(phi, pins, fields, pfaffian, joints, tree, q,
                                                                s_rows[row], t, m_h, independent, rank, separation,
                                                                acting, kept, A, kappa)
            done = F.shape[0] > 0
        if not done:
            return row
        _write_row(row, q, A, sigma, values, s_dot_tree, m_h, rank_tolerance, q_out, s_tree_out, residuals, ranks)
    return q_rows.shape[0]


def _write_row(row, q, A, sigma, values, s_dot_tree, m_h, rank_tolerance, q_out, s_tree_out, residuals, ranks):
    """Row ``row`` of the output: q, ṡ_tree, the residuals (Φ(q, t), A q̇ − b) with q̇ = ṡ_tree and b = 0
    (the Pfaffian rows of A_s, ``A[m_h:]``), and the rank of A_s from its singular values ``sigma``."""
    q_out[row], s_tree_out[row] = q, s_dot_tree
    residuals[row, :m_h] = values
    residuals[row, m_h:] = _matvec(A[m_h:], s_dot_tree)
    ranks[row] = np.sum(sigma > rank_tolerance * sigma[0])


def _projected_onto(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, tolerance, rank_tolerance, max_iter, A,
                    values) -> bool:
    """q moved onto Φ(q, t) = 0 in place (:func:`closure_rows`), leaving A_s (``A``) and Φ (``values``) at
    the point reached; whether it converged (|Φ| ≤ ``tolerance`` · max(1, |q|) of the q given)."""
    scale = max(1.0, np.max(np.abs(q)))
    for _ in range(max_iter):
        _constraint_rows(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, A)
        _constraint_values(phi, pins, fields, tree, q, t, values)
        if not (np.all(np.isfinite(A)) and np.all(np.isfinite(values))):
            return False
        if m_h == 0 or np.max(np.abs(values)) <= tolerance * scale:
            return True
        U, sigma, Vt = np.linalg.svd(A[:m_h], full_matrices=False)
        for j in range(sigma.shape[0]):
            if sigma[j] > rank_tolerance * sigma[0]:
                weight = np.sum(U[:, j] * values) / sigma[j]
                for i in range(q.shape[0]):
                    q[i] -= Vt[j, i] * weight
    return False


def tangent(phi, pins, fields, pfaffian, joints, tree, q, s_dot, t, m_h, independent, rank, separation, acting, kept,
            pivot, q_dot, s_ddot_tree, A, M, b, kappa):
    """The constrained s̈ of :class:`~projeq.constraints.partitioned.TangentSystem`: F = N N_ind⁻¹ with
    N the null space of A_s = U Σ Vᵀ continued along the branch (``kept``: the tangent kept last,
    n × n_s, NaN where none; overwritten where the null space is separated, its rule), f̄ =
    x₀ − F x₀[independent] with x₀ = A_s⁺(−γ) over the ``rank`` largest singular values above
    ``acting`` σ_max, and ṡ_tree = F ṡ + f with f the same particular solution of A_s f = b_s;
    otherwise as :func:`partitioned`; writes κ = 1/σ_min(N_ind) = ‖F‖₂ (N orthonormal; 1 without
    independent velocities) into ``kappa[0]``.
    DEGENERATE where N_ind is singular or A_s not finite."""
    _constraint_rows(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, A)
    U, sigma, Vt, count, F, s_dot_tree = _tangent_velocities(phi, pins, fields, pfaffian, joints, tree, q, s_dot, t,
                                                             m_h, independent, rank, separation, acting, kept, A,
                                                             kappa)
    if F.shape[0] == 0:
        return DEGENERATE
    q_dot[:] = s_dot_tree
    gamma = _constraint_gamma(phi, pins, fields, pfaffian, joints, tree, q, s_dot_tree, t, m_h, A.shape[0])
    f_bar = _particular(U, sigma, Vt, gamma, count, F, independent)
    given_motions(joints, q, s_dot_tree, t, tree[4])
    return _projected(tree, q, s_dot_tree, t, F, f_bar, pivot, M, b, s_ddot_tree)


def _tangent_velocities(phi, pins, fields, pfaffian, joints, tree, q, s_dot, t, m_h, independent, rank, separation,
                        acting, kept, A, kappa):
    """(U, σ, Vᵀ of A_s, the count of its singular values that act, F, ṡ_tree = F ṡ + f) of the null-space
    rule (:func:`tangent`) from A_s (``A``, at q, with the workspace :func:`_constraint_rows` leaves); the
    tangent ``kept`` continued and κ written as there; F empty (0 rows) where N_ind is singular or A_s
    not finite."""
    n, m, k = q.shape[0], A.shape[0], independent.shape[0]
    U, sigma, Vt = _svd(A)
    count = 0  # the singular values above acting σ_max, at most rank
    for value in sigma:
        count += value > acting * sigma[0]
    count = min(count, rank)
    b_s = _constraint_rates(pins, joints, fields, tree, q, m_h, m)  # from the workspace at q, before q*
    sigma_star, Vt_star = _on_manifold(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, U, sigma, Vt, count)
    if not np.all(np.isfinite(Vt_star)):  # A_s not finite: the numpy path names the cause
        return U, sigma, Vt, count, np.empty((0, k)), s_dot.copy()
    near = 0  # the singular values below separation σ_max, at least k
    for value in sigma_star:
        near += value < separation * sigma_star[0]
    near = max(k, near)
    if near == k or np.isnan(kept[0, 0]):
        N = Vt_star[n - k:].T.copy()
        kept[:, :] = N
    else:
        V_near = Vt_star[n - near:]  # the near-null space (rows)
        N = np.linalg.qr(_matmul(V_near.T, _matmul(V_near, kept)))[0]
    F = _scaled(N, independent)
    if F.shape[0] == 0:
        return U, sigma, Vt, count, F, s_dot.copy()
    # ‖F‖₂: a column's Euclidean norm (one free motion), else its largest singular value (1 without free motion)
    kappa[0] = np.sqrt(np.sum(F * F)) if k == 1 else np.linalg.svd(F)[1][0] if k else 1.0
    s_dot_tree = _matvec(F, s_dot)
    if b_s.shape[0]:  # ṡ_tree = F ṡ + f, A_s f = b_s with f[independent] = 0
        f = _particular(U, sigma, Vt, -b_s, count, F, independent)
        for i in range(n):
            s_dot_tree[i] += f[i]
    return U, sigma, Vt, count, F, s_dot_tree


def partitioned_state_derivative(phi, pins, fields, pfaffian, joints, tree, t, independent, dependent, x, n_q, m_h,
                                 bound, pivot, limit, q, s_dot, q_dot, s_ddot_tree, A, M, b, kappa, x_dot):
    """ẋ = (q̇, s̈_tree[independent]) of :func:`partitioned` at x = (q, ṡ) into ``x_dot``, as the compiled
    integration loop calls a model's ẋ (:mod:`projeq.simulation.loop`; ``q``, ``s_dot``: buffers of the
    state's parts): −1, or 0 where the kernel flags (``kappa[0]`` then ∞) or ẋ is not finite. Writes into
    ``kappa[0]`` the value of the ConstrainedSystem's event κ − limit plus its limit: the partition's
    condition κ = ‖A_s‖₂ ‖A_dep⁻¹‖₂ by two SVDs where the kernel's bound ‖A_s‖_F ‖A_dep⁻¹‖_F ≥ κ reaches
    :data:`EVENT_MARGIN` · ``limit``, the bound elsewhere (below the limit: the event's sign is right
    everywhere, its value exact near its root; the SVDs cost a third of the four-bar's evaluation)."""
    _split(x, n_q, q, s_dot)
    if partitioned(phi, pins, fields, pfaffian, joints, tree, q, s_dot, t, m_h, independent, dependent, bound, pivot,
                   q_dot, s_ddot_tree, A, M, b, kappa) != DONE:
        kappa[0] = np.inf
        return 0
    if not kappa[0] < EVENT_MARGIN * limit:  # near the event: κ itself
        A_dep = np.empty((dependent.shape[0], dependent.shape[0]))
        for r in range(dependent.shape[0]):
            for c in range(dependent.shape[0]):
                A_dep[r, c] = A[r, dependent[c]]
        kappa[0] = np.linalg.svd(A)[1][0] / np.linalg.svd(A_dep)[1][-1]
    return _state_rates(q_dot, s_ddot_tree, independent, n_q, x_dot)


def tangent_state_derivative(phi, pins, fields, pfaffian, joints, tree, t, independent, x, n_q, m_h, rank, separation,
                             acting, kept, pivot, q, s_dot, q_dot, s_ddot_tree, A, M, b, kappa, x_dot):
    """:func:`partitioned_state_derivative` for :func:`tangent` (the null-space form), its event's
    κ = 1/σ_min(N_ind) = ‖F‖₂ the kernel's own."""
    _split(x, n_q, q, s_dot)
    if tangent(phi, pins, fields, pfaffian, joints, tree, q, s_dot, t, m_h, independent, rank, separation, acting,
               kept, pivot, q_dot, s_ddot_tree, A, M, b, kappa) != DONE:
        kappa[0] = np.inf
        return 0
    return _state_rates(q_dot, s_ddot_tree, independent, n_q, x_dot)


def _split(x, n_q, q, s_dot):
    """q and ṡ ← the parts of x = (q, ṡ)."""
    for i in range(n_q):
        q[i] = x[i]
    for i in range(s_dot.shape[0]):
        s_dot[i] = x[n_q + i]


def _state_rates(q_dot, s_ddot_tree, independent, n_q, x_dot) -> int:
    """x_dot ← (q̇, s̈_tree[independent]): −1, or 0 where an entry is not finite."""
    for i in range(n_q):
        x_dot[i] = q_dot[i]
    for i in range(independent.shape[0]):
        x_dot[n_q + i] = s_ddot_tree[independent[i]]
    for i in range(x_dot.shape[0]):
        if not np.isfinite(x_dot[i]):
            return 0
    return -1


def _on_manifold(phi, pins, fields, pfaffian, joints, tree, q, t, m_h, U, sigma, Vt, count):
    """(σ, Vᵀ) of A_s at q* = q − A_s⁺ [Φ(q); 0], the point q moved onto the constraint manifold by one
    Gauss–Newton step (A_s = U Σ Vᵀ at q, its ``count`` largest singular values), whose null space is
    the motion's tangent (:meth:`projeq.constraints.tangent.NullSpaceForm._motion_tangent`); (σ, Vᵀ)
    of q itself where it lies on the manifold (Φ(q) = 0, or no Φ rows)."""
    n, m = Vt.shape[0], U.shape[0]
    values = np.zeros(m)
    _constraint_values(phi, pins, fields, tree, q, t, values[:m_h])
    moved = False
    for r in range(m_h):
        moved = moved or values[r] != 0.0
    if not moved:
        return sigma, Vt
    q_star = q.copy()
    for j in range(count):
        weight = 0.0
        for r in range(m):
            weight += U[r, j] * values[r]
        weight /= sigma[j]
        for i in range(n):
            q_star[i] -= Vt[j, i] * weight
    A_star = np.empty((m, n))
    _constraint_rows(phi, pins, fields, pfaffian, joints, tree, q_star, t, m_h, A_star)
    _, sigma_star, Vt_star = _svd(A_star)
    return sigma_star, Vt_star


def _constraint_values(phi, pins, fields, tree, q, t, values):
    """values ← Φ(q, t) of the closure callback. The kernels' variant for cut joints calls
    :func:`_pin_constraint_values` under this name instead."""
    x, value = np.empty(q.shape[0], np.complex128), np.empty(values.shape[0], np.complex128)
    for i in range(q.shape[0]):
        x[i] = q[i]
    phi_into(phi, x, t, value)
    for r in range(values.shape[0]):
        values[r] = value[r].real


def _pin_constraint_values(phi, pins, fields, tree, q, t, values):
    """:func:`_constraint_values` of cut joints, from the chain at q that :func:`_pin_constraint_rows`
    leaves in the workspace (:func:`_pin_values`)."""
    _pin_values(pins, fields, tree, q, values)


def _scaled(N: NDArray, independent: NDArray) -> NDArray:
    """F = N N_ind⁻¹ (F[independent] = E exactly) of the null-space basis N (n × k), N_ind its
    rows ``independent``; an empty F (0 × k) where N_ind is singular."""
    k = independent.shape[0]
    N_ind = np.empty((k, k))
    for r in range(k):
        for c in range(k):
            N_ind[r, c] = N[independent[r], c]
    inv = _inverse(N_ind)
    for r in range(k):
        for c in range(k):
            if not np.isfinite(inv[r, c]):
                return np.empty((0, k))
    F = _matmul(N, inv)
    for r in range(k):
        for c in range(k):
            F[independent[r], c] = 1.0 if r == c else 0.0
    return F


def _particular(U: NDArray, sigma: NDArray, Vt: NDArray, gamma: NDArray, count: int, F: NDArray,
                independent: NDArray) -> NDArray:
    """f̄ = x₀ − F x₀[independent] with x₀ = A_s⁺(−γ) = V_k Σ_k⁻¹ U_kᵀ (−γ) over the ``count``
    largest singular values of A_s = U Σ Vᵀ."""
    n, m, k = Vt.shape[0], U.shape[0], independent.shape[0]
    x0 = np.zeros(n)
    for j in range(count):
        weight = 0.0
        for r in range(m):
            weight -= U[r, j] * gamma[r]
        weight /= sigma[j]
        for i in range(n):
            x0[i] += Vt[j, i] * weight
    x0_ind = np.empty(k)
    for c in range(k):
        x0_ind[c] = x0[independent[c]]
    f_bar = x0  # in place
    for i in range(n):
        total = 0.0
        for c in range(k):
            total += F[i, c] * x0_ind[c]
        f_bar[i] = x0[i] - total
    return f_bar


def _svd(A: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """(U, σ, Vᵀ) of A (m × n) with all n singular values, descending (those beyond m zero), V n × n
    and U m × n (its first min(m, n) columns the left singular vectors): by LAPACK
    (:func:`_lapack_svd`) from LAPACK_SVD_SIZE entries on, below that by the hand-written
    :func:`_jacobi_svd`, which is faster there. benchmarks/closure_linalg.py times them alone
    (single-threaded BLAS, µs per SVD of an m × (m + 1) A_s, LAPACK's over Jacobi's): 7.4 / 4.7 at
    6 × 7, 15.1 / 11.6 at 10 × 11, 21.1 / 17.7 at 12 × 13, 26.8 / 28.3 at 14 × 15, 52 / 65 at
    20 × 21, 182 / 457 at 40 × 41, 690 / 3500 at 80 × 81 (the IFToMM A02 N-four-bar with N = 40)."""
    if A.shape[0] * A.shape[1] >= LAPACK_SVD_SIZE:
        return _lapack_svd(A)
    return _jacobi_svd(A)


def _lapack_svd(A: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """:func:`_svd` by LAPACK's gesdd (numba's ``np.linalg.svd``, as the numpy path's
    NullSpaceForm._decomposition); NaN where LAPACK refuses A (not finite, or no convergence: the
    kernel then flags it, as the hand-written SVD's NaN do). Its callers hold the BLAS threads to one
    (:func:`projeq.assembly.linalg.one_blas_thread`): with OpenBLAS's threads on a loaded two-core
    machine one 80 × 81 SVD took 6.4–6.9 ms against 0.87–0.91 ms single-threaded (two processes
    each timing it beside a third busy one)."""
    m, n = A.shape
    U, sigma = np.zeros((m, n)), np.zeros(n)
    if not np.all(np.isfinite(A)):
        return U + np.nan, sigma + np.nan, np.full((n, n), np.nan)
    try:
        U_full, values, Vt = np.linalg.svd(A)
    except Exception:  # noqa: BLE001 — numba raises LinAlgError, catchable only as Exception
        return U + np.nan, sigma + np.nan, np.full((n, n), np.nan)
    p = values.shape[0]
    sigma[:p] = values
    U[:, :p] = U_full[:, :p]
    return U, sigma, Vt


def _jacobi_svd(A: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """:func:`_svd` for the few rows and columns of a small loop's A_s, without LAPACK's calls and
    workspace (U's column j = A v_j / σ_j, zero where σ_j = 0): the QR decomposition with
    column pivoting of Aᵀ (:func:`_transposed_qr`, A[order] Q = [L 0]) as the preconditioner of
    Drmač & Veselić ("New fast and accurate Jacobi SVD algorithm I", SIAM J. Matrix Anal. Appl. 29,
    2008, §3: the one-sided Jacobi method on Rᵀ = L converges in fewer sweeps than on A), then
    one-sided Jacobi rotations of the columns of L (:func:`_jacobi` of [L; E]ᵀ): L W = Ũ Σ, so that
    V = Q diag(W, E) and U[order] = Ũ."""
    m, n = A.shape
    X, Qt, order = _transposed_qr(A)  # X = [L; E]ᵀ
    p = X.shape[0]
    _jacobi(X, m)  # X = [Ũ Σ; W]ᵀ
    norms = np.zeros(p)
    for j in range(p):
        norms[j] = _row_square(X, m, j)
    ranked = np.argsort(-norms)
    sigma, U, Vt = np.zeros(n), np.zeros((m, n)), np.zeros((n, n))
    for c in range(p):
        j = ranked[c]
        for l in range(p):  # v_c = Q₁ w_j: Vt[c] = Σ_l W[l, j] Qᵀ[l]
            for i in range(n):
                Vt[c, i] += X[j, m + l] * Qt[l, i]
        if norms[j] > 0.0:
            sigma[c] = np.sqrt(norms[j])
            for i in range(m):
                U[order[i], c] = X[j, i] / sigma[c]
    for c in range(p, n):  # the columns of Q beyond the rows of A: in its null space
        for i in range(n):
            Vt[c, i] = Qt[c, i]
    return U, sigma, Vt


def _transposed_qr(A: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """([L; E]ᵀ, Qᵀ, order): Householder QR with column pivoting of Aᵀ (m × n A), Aᵀ[:, order] = Q R
    (Golub & Van Loan, "Matrix Computations", 4th ed., 2013, Algorithm 5.4.1; Q n × n orthogonal,
    the product H_0 ⋯ H_{p−1} of p = min(m, n) reflectors accumulated backwards, §5.1.6), so that
    A[order] Q = Rᵀ = [L 0] with L = R[:p]ᵀ, m × p lower trapezoidal, above the p × p identity.
    The columns of Aᵀ are the rows of A: the reflectors act on rows (:func:`_reflect`)."""
    m, n = A.shape
    p = min(m, n)
    C, order = A.copy(), np.arange(m)  # C = Aᵀᵀ: row j is column j of Aᵀ, reflected in place
    reflectors, scales = np.zeros((p, n)), np.zeros(p)  # H_c = E − scales[c] v_c v_cᵀ, v_c zero before entry c
    for c in range(p):
        size, chosen = -1.0, c  # the column of largest norm below row c first
        for j in range(c, m):
            column = 0.0
            for i in range(c, n):
                column += C[j, i] * C[j, i]
            if column > size:
                size, chosen = column, j
        for i in range(n):
            C[c, i], C[chosen, i] = C[chosen, i], C[c, i]
        order[c], order[chosen] = order[chosen], order[c]
        if size == 0.0:  # the rest is zero: H_c = E
            continue
        head = -np.sqrt(size) if C[c, c] >= 0.0 else np.sqrt(size)  # R[c, c], of the sign that avoids cancellation
        for i in range(c, n):
            reflectors[c, i] = C[c, i]
        reflectors[c, c] -= head
        scales[c] = 2.0 / (size - C[c, c] * C[c, c] + reflectors[c, c] * reflectors[c, c])  # 2 / v_cᵀ v_c
        _reflect(reflectors, scales[c], c, C, c + 1, m)
        C[c, c] = head
    Qt = np.eye(n)
    for c in range(p - 1, -1, -1):  # Q = H_0 (H_1 (⋯ H_{p−1})): H_c touches rows and columns c… only
        _reflect(reflectors, scales[c], c, Qt, c, n)
    X = np.zeros((p, m + p))  # [L; E]ᵀ = [R[:p] E]
    for c in range(p):
        for i in range(c, m):
            X[c, i] = C[i, c]
        X[c, m + c] = 1.0
    return X, Qt, order


def _reflect(reflectors: NDArray, scale: float, c: int, X: NDArray, first: int, last: int) -> None:
    """Rows first … last − 1 of X ← X H_c (each the transpose of H_c times a column), H_c = E − scale v vᵀ,
    v = reflectors[c] (zero before entry c)."""
    if scale == 0.0:
        return
    for j in range(first, last):
        dot = 0.0
        for i in range(c, X.shape[1]):
            dot += reflectors[c, i] * X[j, i]
        dot *= scale
        for i in range(c, X.shape[1]):
            X[j, i] -= dot * reflectors[c, i]


#: an updated squared column norm that has dropped below this fraction of its value before the
#: rotation is computed anew (its update lost digits to cancellation)
DRIFT = 0.1


def _jacobi(X: NDArray, m: int) -> None:
    """Rotate the rows of X = [W; V]ᵀ (the columns of W their first ``m`` entries, those of V the
    others, rotated alike; rows, so that the loops run over contiguous entries) until the columns
    of W are orthogonal to round-off (one-sided Jacobi, Demmel & Veselić, "Jacobi's method is more
    accurate than QR", SIAM J. Matrix Anal. Appl. 13, 1992, Algorithm 4.1): a pair (a, r) whose
    cosine |γ| / √(α β) (α, β the squared norms of the columns of W, γ their dot product) is above
    1e-15 is rotated by the angle that makes it zero. The squared norms are taken at each sweep's
    start and updated by each rotation, α' = α − t γ, β' = β + t γ with t = tan of the angle (de
    Rijk, "A one-sided Jacobi algorithm for computing the singular value decomposition on a vector
    computer", SIAM J. Sci. Stat. Comput. 10, 1989), computed anew where one drops below DRIFT of
    its value; the last sweep rotates none, so that every pair's cosine is tested on norms taken
    afresh. A column below 1e-15 of ‖W‖_F is W v = 0 to round-off (in the null space): not rotated."""
    p = X.shape[0]
    squares, floor = np.zeros(p), 0.0
    for j in range(p):
        floor += 1e-30 * _row_square(X, m, j)
    for _ in range(100):  # sweeps; quadratic convergence takes a handful
        for j in range(p):
            squares[j] = 0.0
            for i in range(m):
                squares[j] += X[j, i] * X[j, i]
        rotated = False
        for a in range(p - 1):
            for r in range(a + 1, p):
                alpha, beta = squares[a], squares[r]
                if alpha <= floor or beta <= floor:
                    continue
                gamma = 0.0
                for i in range(m):
                    gamma += X[a, i] * X[r, i]
                if abs(gamma) <= 1e-15 * np.sqrt(alpha * beta):
                    continue  # orthogonal to round-off
                rotated = True
                if abs(beta - alpha) > 1e100 * abs(gamma):  # a tiny angle: tan = 1/(2ζ) to round-off
                    tan = gamma / (beta - alpha)
                else:
                    zeta = (beta - alpha) / (2.0 * gamma)
                    tan = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
                cos = 1.0 / np.sqrt(1.0 + tan * tan)
                sin = cos * tan
                for i in range(X.shape[1]):
                    x_a, x_r = X[a, i], X[r, i]
                    X[a, i], X[r, i] = cos * x_a - sin * x_r, sin * x_a + cos * x_r
                squares[a], squares[r] = alpha - tan * gamma, beta + tan * gamma
                if squares[a] < DRIFT * alpha:
                    squares[a] = _row_square(X, m, a)
                if squares[r] < DRIFT * beta:
                    squares[r] = _row_square(X, m, r)
        if not rotated:
            break


def _row_square(X: NDArray, m: int, j: int) -> float:
    """|X[j, :m]|²."""
    total = 0.0
    for i in range(m):
        total += X[j, i] * X[j, i]
    return total


# interpreted; _compiled holds the compiled ones
chain_terms, gauss_form, add_loads = kernels.chain_terms, kernels.gauss_form, loads.add_loads


def _inverse(A: NDArray) -> NDArray:
    """A⁻¹ by Gauss–Jordan elimination with partial pivoting (∞ entries for a singular A): faster than
    LAPACK's getrf/getri (numba's ``np.linalg.inv``) for a loop's A_dep and N_ind — LAPACK's time over
    this one's (benchmarks/closure_linalg.py): the partitioned kernel's s̈ 1.05 with the four-bar's
    A_dep 2 × 2, 1.14 with the Whipple bicycle's 5 × 5; the inverse alone 3.2 at 2 × 2, 2.1 at 5 × 5,
    1.2 at 12 × 12, 0.96 at 16 × 16."""
    m = A.shape[0]
    work, inv = A.copy(), np.eye(m)
    for c in range(m):
        p = c + np.argmax(np.abs(work[c:, c]))
        if work[p, c] == 0.0:
            return np.full((m, m), np.inf)
        for row in (work, inv):
            for j in range(m):
                row[c, j], row[p, j] = row[p, j], row[c, j]
        d = work[c, c]
        for j in range(m):
            work[c, j] /= d
            inv[c, j] /= d
        for r in range(m):
            if r != c and work[r, c] != 0.0:
                e = work[r, c]
                for j in range(m):
                    work[r, j] -= e * work[c, j]
                    inv[r, j] -= e * inv[c, j]
    return inv


_HELPERS = (_jacobian, _gamma, _constraint_rows, _constraint_gamma, _constraint_rates, _constraint_values,
            _pin_constraint_values, _on_manifold, _pin_constraint_rows,
            _pin_constraint_gamma, _pfaffian_rows, _pfaffian_gamma, _pin_frame, _port_chain, _pin_values, _pin_rates,
            _body_jacobians, _inertial_axis, _pin_jacobian, _pin_gamma, given_motions, _matvec, _matmul, _svd,
            _lapack_svd, _jacobi_svd,
            _transposed_qr, _reflect, _jacobi, _row_square, _scaled, _particular, _chain_terms, _projected,
            _inverse, _partition, _projected_onto, _tangent_velocities, _write_row)


def compiled_partition(system, bound: float) -> "CompiledClosure | None":
    """The :class:`CompiledClosure` of a ConstrainedSystem (partitioned) that :func:`unsupported`
    accepts (``bound``: the limit of ‖A_s‖_F ‖A_dep⁻¹‖_F above which the kernel flags the
    partition), or None (after one warning) where numba cannot compile its Φ or A."""
    return _closure(system, "partitioned", bound)


def compiled_tangent(system, acting: float) -> "CompiledClosure | None":
    """The :class:`CompiledClosure` of a TangentSystem that :func:`unsupported` accepts
    (``acting``: singular values below this fraction of the largest do not act in f̄), or None
    (after one warning) where numba cannot compile its Φ or A."""
    return _closure(system, "tangent", acting)


def _closure(system, rule: str, constant: float) -> "CompiledClosure | None":
    """The :class:`CompiledClosure` of ``system`` by the kernel ``rule`` with the C callbacks of Φ, of
    the Pfaffian rows A (if any) and of the UserJoints' relative motions, or None where numba cannot
    compile one of them (:func:`closure_callback`, :func:`joint_callback` warned, naming it; the
    system keeps the reason)."""
    tree = system.tree
    given = tree.evaluator("fast")._given
    phi = f"Φ ({getattr(system._phi, '__qualname__', repr(system._phi))})"
    pins = pin_table(system._phi, system.m_h)
    pieces = {phi: _NO_CALLBACK if pins[0].shape[0] else
              closure_callback(system._phi, system.n_q, system.m_h, system.q0)}
    if system.m_p:
        pieces["the Pfaffian rows A"] = closure_callback(system._A, system.n_q, (system.m_p, system.n_q), system.q0, "A")
    pieces.update({f"the relative motion of joint {tree.names[n]!r}": joint_callback(tree.joints[n]) for n in given})
    failed = [name for name, callback in pieces.items() if callback is None]
    if failed:
        system._uncompiled = f"numba cannot compile {', '.join(failed)}"
        return None
    return CompiledClosure(tree, system.n_c, pieces[phi], rule, (constant,), m_h=system.m_h,
                           pfaffian=pieces.get("the Pfaffian rows A"), pins=pins)


#: the arguments of the other rule in :func:`closure_rows` (unread): no dependent velocities, no kept tangent
_NO_INDICES, _NO_TANGENT = np.zeros(0, np.intp), np.zeros((1, 1))

#: the Φ "callback" of a closure made of cut joints: the kernels evaluate them themselves
#: (:func:`_pin_jacobian`, :func:`_pin_gamma`) and never call it
_NO_CALLBACK = types.SimpleNamespace(address=0)


def pin_table(phi, m_h: int) -> tuple[NDArray, NDArray]:
    """The rows of Φ that are cut joints (:meth:`~projeq.constraints.cut_joints.PinClosure.point_rows`)
    as the kernels read them, in two arrays (each array argument of a compiled call costs its
    unboxing, and every closure pays for these): ``pins[r]`` = (a, b, inertial axis, slot_a, slot_b,
    ρ_a, ρ_b) and ``fields[slot]`` the station of a point on a RitzBeam
    (:class:`~projeq.subsystems.beam.beam.BeamPort`; slot −1: a rigid body's point): rows 0–2 hold
    r₀, the offset c, Ψ (k columns) and the angles' rows (k columns), rows 3 … 2 + k hold Q (k = the
    largest n_e). Empty where Φ is a user's function (its rows by the complex step)."""
    rows = point_rows(phi) or []
    assert not rows or len(rows) == m_h
    stations = list({id(port): port for row in rows for port in row[5:] if port is not None}.values())
    slot = {id(port): i for i, port in enumerate(stations)}
    pins = np.array([[*row[:3], *(slot.get(id(port), -1) for port in row[5:]), *row[3], *row[4]] for row in rows],
                    dtype=float).reshape(len(rows), 11)
    k = max([port.beam.n_e for port in stations], default=1)
    fields = np.zeros((len(stations), 3 + k, 2 + 2 * k))
    for field, port in zip(fields, stations):
        n_e = port.beam.n_e
        r0, Psi, Q, angles = port.field
        field[:3, 0], field[:3, 1], field[:3, 2:2 + n_e], field[:3, 2 + k:2 + k + n_e] = r0, port.offset, Psi, angles
        field[3:3 + n_e, :n_e] = Q
    return pins, fields


def tree_arrays(ev, dtype) -> tuple:
    """The tree's packed arrays and the workspace of ``dtype`` (float; complex for the complex step) of
    its fast evaluator ``ev``, as the kernels read them (``tree``: those of
    :func:`projeq.assembly.kernels.chain_terms`, the force laws' rows last)."""
    ws = ev._real if dtype is float else ev._workspace(dtype)
    return (ev._index, ev._geometry, ev._inertia, ev._gravity, ws.given_values, ev._elastic, ev._ports,
            ws.T, ws.zeta, ws.F, ws.M_n, ws.h_hat, ws.R, ws.r, ws.twist, ev._laws, ev._law_constants)


def compiled_cut_joints(system) -> "CutJointRows | None":
    """The compiled rows of ``system``'s cut joints (:class:`CutJointRows`) where its Φ is made of them
    and the tree's kinematics compile — K = E, the tree's fast evaluator without
    coupled joints or joints that state their relative motion in Python, its UserJoints' relative
    motions compiled —, whether or not its constrained s̈ is one compiled call (an AugmentedSystem,
    a force law without compiled rows, Pfaffian rows with b ≠ 0); else None (the numpy path's
    complex steps through the poses)."""
    if point_rows(system._phi) is None or not system._identity or not system.compiled_tree():
        return None
    ev = system.tree.evaluator("fast")
    if ev._expansion is not None or ev._python_joints:
        return None
    callbacks = [joint_callback(system.tree.joints[n]) for n in ev._given]
    return None if None in callbacks else CutJointRows(ev, pin_table(system._phi, system.m_h), callbacks)


class Deferred:
    """The interpreted tier of a closed loop's kernels (:class:`projeq.assembly.auto.Tier`) while numba
    has not compiled them and the cold-start budget lasts (:mod:`projeq.assembly.compilation`): it
    flags NOT_COMPILED, so that the caller evaluates by the numpy path, and spends from the budget the
    CPU since the last call it answered — that evaluation and the integrator's work around it, less
    what compiling other kernels took meanwhile. A four-bar's first run, with an empty numba cache: a
    few seconds instead of about 90 s of compilation, which its kernels pay once the budget is spent.
    (The cut joints' rows, :class:`CutJointRows`, still compile at first use: without them the numpy
    path of an elastic loop takes ~5 ms per evaluation, and its budget would be spent at once — the
    flexible four-bar's first 0.05 s: 56 s of CPU so, 178 s with them deferred too, 137 s before.)"""

    def __init__(self):
        self.at = None  # (process CPU, compiling CPU) at the last call

    def __call__(self, *args) -> int:
        now = (time.process_time(), compilation.compiling_seconds())
        if self.at is not None:
            compilation.spend(max(0.0, (now[0] - self.at[0]) - (now[1] - self.at[1])), "the closed loop")
        self.at = now
        return NOT_COMPILED


#: the one stand-in of every closed loop's kernels (one clock: the CPU of a deferred evaluation is spent once)
DEFERRED = Deferred()


class CompiledClosure:
    """s̈_tree, A_s, M and b of a constrained model by one call of a compiled kernel
    (:func:`partitioned` or :func:`tangent`) with the C callbacks of Φ, of the Pfaffian rows A
    (``pfaffian``, rows m_h … m − 1 of A_s) and of the relative motions of the tree's UserJoints
    from sympy (:func:`joint_callback`), on the tree's fast evaluator's workspace;
    ``accelerations`` returns None where the kernel flags a degenerate partition or a
    singular FᵀMF (the caller repeats the evaluation on the numpy path, which names the cause).
    ``compiled=False`` runs the same kernel interpreted, with ``callback`` Φ itself, ``pfaffian``
    A itself and the joints' ``compiled_values`` functions (for testing)."""

    def __init__(self, tree, m: int, callback, rule: str, constants: tuple, compiled: bool = True,
                 m_h: int | None = None, pfaffian=None, pins=None):
        # the callbacks live as long as this object, which passes their addresses
        ev = self.fast = tree.evaluator("fast")
        self.callback, self.rule, self.constants, self.m_h = callback, rule, constants, m if m_h is None else m_h
        self.pins, self.fields = pin_table(None, 0) if pins is None else pins
        self._callbacks = [pfaffian] + [joint_callback(tree.joints[n]) if compiled else None for n in ev._given]
        if compiled:  # each kernel in tiers: the numpy path until numba has it or the budget is spent
            from projeq.assembly.auto import Tier  # (auto imports the package that imports this module)

            found = _compiled(ev._width > 6, bool(len(self.pins)))
            self.kernel, self.rows_kernel = (Tier(found[name], DEFERRED, "the closed loop", state=6)
                                             for name in (rule, "closure_rows"))
            self.phi, self.pfaffian = callback.address, 0 if pfaffian is None else pfaffian.address
        else:
            self.kernel, self.phi, self.pfaffian = _interpreted(rule, bool(len(self.pins))), callback, pfaffian
            self.rows_kernel = _interpreted("closure_rows", bool(len(self.pins)))
        self.joints = joint_table(ev._given_plan, self._callbacks[1:], compiled)
        self._workspace = ev._real
        self.tree = tree_arrays(ev, float)
        self._A, self._s_ddot_tree, self._q_dot = np.zeros((m, tree.n_s)), np.zeros(tree.n_s), np.zeros(tree.n_s)
        self.lapack = m * tree.n_s >= LAPACK_SVD_SIZE  # its calls hold BLAS to one thread (:func:`_lapack_svd`)
        self._kappa = np.zeros(1)  # κ (the tangent rule) or its bound (partitioning), written by the kernel
        self._kept = (None, None)  # (the system, the tangent it keeps) of the last call (_kept_tangent)

    def _call(self, system, q: NDArray, s_dot: NDArray, t: float) -> bool:
        """One kernel call for ``system`` (its partition; for a TangentSystem its kept tangent,
        which the call updates as the numpy path does) into the workspace; whether it is done."""
        M, b = self._workspace.M_all, self._workspace.b_all
        q, s_dot, t = kernels.kernel_array(q), kernels.kernel_array(s_dot), float(t)
        if not self.lapack:  # (no context per call of a small loop's s̈: about 1 µs)
            return self._kernel_call(system, q, s_dot, t, M, b) == DONE
        with one_blas_thread():
            return self._kernel_call(system, q, s_dot, t, M, b) == DONE

    def _kernel_call(self, system, q: NDArray, s_dot: NDArray, t: float, M: NDArray, b: NDArray) -> int:
        """The kernel's flag at (q, ṡ, t) (:meth:`_call`)."""
        if self.rule == "partitioned":
            return self.kernel(self.phi, self.pins, self.fields, self.pfaffian, self.joints, self.tree, q, s_dot, t,
                               self.m_h, system.independent, system.dependent,
                               self.constants[0], SINGULAR_PIVOT, self._q_dot, self._s_ddot_tree, self._A, M, b,
                               self._kappa)
        return self.kernel(self.phi, self.pins, self.fields, self.pfaffian, self.joints, self.tree, q, s_dot, t,
                           self.m_h, system.independent, system.tree.n_s - system.n_s,
                           system.separation, self.constants[0], self._kept_tangent(system), SINGULAR_PIVOT,
                           self._q_dot, self._s_ddot_tree, self._A, M, b, self._kappa)

    def _kept_tangent(self, system) -> NDArray:
        """The tangent ``system`` keeps (TangentSystem._tangent) as the array the kernel reads and
        overwrites: the one the last call wrote, where it is still the system's (no copy per call);
        else a copy of the one the numpy path (or the system this one was copied from) kept, NaN
        where none, which the system then keeps."""
        owner, kept = self._kept
        if kept is None or system._tangent is not kept or owner() is not system:
            kept = np.full((system.tree.n_s, system.n_s), np.nan) if system._tangent is None else \
                np.array(system._tangent, dtype=float)
            system._tangent, self._kept = kept, (weakref.ref(system), kept)
        return kept

    def accelerations(self, system, q: NDArray, s_dot: NDArray, t: float):
        """(s̈_tree, A_s, M, b) of ``system`` at (q, ṡ, t), or None (flagged)."""
        if not self._call(system, q, s_dot, t):
            return None
        return self._s_ddot_tree.copy(), self._A.copy(), self._workspace.M_all.copy(), self._workspace.b_all.copy()

    def minimal_accelerations(self, system, q: NDArray, s_dot: NDArray, t: float):
        """s̈ = s̈_tree[independent] of ``system`` at (q, ṡ, t) (the evaluator's s̈, without copies of
        A_s, M and b), or None (flagged)."""
        return self._s_ddot_tree[system.independent] if self._call(system, q, s_dot, t) else None

    def tree_velocities(self, system, q: NDArray, s_dot: NDArray, t: float) -> NDArray | None:
        """ṡ_tree = F ṡ + f of ``system`` at (q, ṡ, t) (q̇ = ṡ_tree: K = E) by one kernel call, or None
        (flagged, or complex arguments: the numpy path's)."""
        if np.iscomplexobj(q) or np.iscomplexobj(s_dot):
            return None
        return self._q_dot.copy() if self._call(system, q, s_dot, t) else None

    def rows(self, system, q_rows: NDArray, s_rows: NDArray, times: NDArray, tolerance: float,
             steps: int) -> tuple | None:
        """(q on Φ = 0, ṡ_tree, residuals, ranks of A_s) of ``system``'s output rows at the states
        (``q_rows``, ``s_rows``) and ``times`` by :func:`closure_rows` (the
        projection of ``normalized``, converged at |Φ| ≤ ``tolerance`` · max(1, |q|) within ``steps``
        evaluations, then ``output_row``'s pieces but the energy; the null-space rule continues the
        system's kept tangent through the rows, as the numpy path does), or None where the kernel does
        not finish a row (the numpy path names why)."""
        k, (m, n) = len(times), self._A.shape
        q_out, s_tree, residuals, ranks = np.empty((k, system.n_q)), np.empty((k, n)), np.empty((k, m)), \
            np.empty(k, np.intp)
        partitioned = self.rule == "partitioned"
        rule = (True, system.dependent, float(self.constants[0]), 0, 0.0, 0.0, _NO_TANGENT) if partitioned else \
            (False, _NO_INDICES, 0.0, system.tree.n_s - system.n_s, float(system.separation),
             float(self.constants[0]), self._kept_tangent(system))
        with one_blas_thread(self.lapack):
            done = self.rows_kernel(self.phi, self.pins, self.fields, self.pfaffian, self.joints, self.tree,
                                    kernels.kernel_array(q_rows), kernels.kernel_array(s_rows),
                                    kernels.kernel_array(times), self.m_h, system.independent, *rule, float(tolerance),
                                    RANK_TOLERANCE, int(steps), q_out, s_tree, residuals, ranks)
        return (q_out, s_tree, residuals, ranks) if done == k else None

    def loop_model(self, system):
        """``system`` (a ConstrainedSystem of this closure) as the compiled integration loop takes it
        (:class:`~projeq.assembly.fast.LoopModel`: ẋ by :func:`partitioned_state_derivative` or
        :func:`tangent_state_derivative`, which check the system's event themselves); None for an
        interpreted kernel."""
        from projeq.assembly.fast import LoopModel  # (fast imports the package that imports this module)

        if not isinstance(self.phi, int):
            return None
        pre = (self.phi, self.pins, self.fields, self.pfaffian, self.joints, self.tree)
        buffers = (np.zeros(system.n_q), np.zeros(system.n_s), self._q_dot, self._s_ddot_tree, self._A,
                   self._workspace.M_all, self._workspace.b_all)
        event = (self._kappa, float(system.limit))  # κ − limit, rising: the system's event
        if self.rule == "partitioned":
            return LoopModel(_compiled_adapter(self.kernel.compiled, self.rule), pre, (system.independent, system.dependent),
                             (self.m_h, float(self.constants[0]), float(SINGULAR_PIVOT), float(system.limit),
                              *buffers, self._kappa), event=event, lapack=self.lapack)
        kept = self._kept_tangent(system)
        return LoopModel(_compiled_adapter(self.kernel.compiled, self.rule), pre, (system.independent,),
                         (self.m_h, system.tree.n_s - system.n_s, float(system.separation), float(self.constants[0]),
                          kept, float(SINGULAR_PIVOT), *buffers, self._kappa),
                         event=event, before=lambda: self._keep_tangent(system, kept), lapack=self.lapack)

    def _keep_tangent(self, system, kept: NDArray) -> None:
        """The tangent ``system`` keeps, in the array ``kept`` the compiled loop's ẋ reads and writes
        (the numpy path between segments may have kept another)."""
        found = self._kept_tangent(system)
        if found is not kept:
            kept[:, :] = found
            system._tangent, self._kept = kept, (weakref.ref(system), kept)

    def state_derivative(self, system, x: NDArray, t: float):
        """ẋ = (q̇, s̈) = (ṡ_tree, s̈_tree[independent]) of ``system`` at x = (q, ṡ) (q̇ = ṡ_tree:
        K = E, and no Baumgarte term where the kernel applies), or None where the kernel flags
        or ẋ is not finite (the caller's checked path then names the cause)."""
        n_q = system.n_q
        if not self._call(system, x[:n_q], x[n_q:], t):
            return None
        x_dot = np.concatenate((self._q_dot, self._s_ddot_tree[system.independent]))
        return x_dot if np.isfinite(x_dot).all() else None


class CutJointRows:
    """Φ, Φ_x and Φ″(v, v) of a ConstrainedSystem whose Φ is made of cut joints (K = E; Φ depends on t
    where they close a loop across a joint prescribed in time) by the compiled :func:`cut_joint_rows` on the tree's fast evaluator's workspace
    (:func:`compiled_cut_joints`): what the numpy path asks for — projections, conditions, residuals,
    and the A_s, γ of its accelerations where they are not one compiled call — in place of its complex
    steps through the poses (one Python pass over the tree per point). The interface of
    :class:`~projeq.constraints.batched.BatchedClosure`, and Φ itself. ``complex_safe``: complex
    arguments too (an outer complex step: the exact Jacobians and the stiffness estimate of
    :mod:`projeq.analysis.jacobians`): the kernel is an analytic function of q and q̇, so at
    q = a + i b it gives f(a) + i f′(a) b exactly; not with joints of kind GIVEN, whose relative
    motions are real C callbacks."""

    def __init__(self, ev, pins: tuple, callbacks: list):
        self.fast, self.callbacks = ev, callbacks  # the callbacks live as long as this object
        self.pins, self.fields = pins
        self.joints = joint_table(ev._given_plan, callbacks, compiled=True)
        self.kernel = _compiled(ev._width > 6, True)["cut_joint_rows"]
        self.complex_safe = not callbacks
        self._trees = {}

    def _call(self, q: NDArray, q_dot: NDArray, t: float) -> tuple[NDArray, NDArray, NDArray, NDArray]:
        """(Φ, A_s, b_s = −∂Φ/∂t, γ) at (q, q̇, t), new arrays of the arguments' dtype."""
        dtype = np.result_type(q, q_dot, float)
        if dtype not in self._trees:
            self._trees[dtype] = tree_arrays(self.fast, dtype)
        m_h, n = self.pins.shape[0], len(q)
        values, A, b_s, gamma = np.zeros(m_h, dtype), np.zeros((m_h, n), dtype), np.zeros(m_h, dtype), \
            np.zeros(m_h, dtype)
        self.kernel(self.pins, self.fields, self.joints, self._trees[dtype], np.ascontiguousarray(q, dtype),
                    np.ascontiguousarray(q_dot, dtype), float(np.real(t)), values, A, b_s, gamma)
        return values, A, b_s, gamma

    def values(self, q: NDArray, t: float) -> NDArray:
        """Φ(q, t)."""
        return self._call(q, np.zeros(len(q)), t)[0]

    def jacobian(self, x: NDArray, columns: int) -> NDArray:
        """The first ``columns`` columns of Φ_x = [Φ_q, ∂Φ/∂t] at x = (q, t)."""
        _, A, b_s, _ = self._call(x[:-1], np.zeros(len(x) - 1), x[-1])
        return np.hstack((A, -b_s[:, None]))[:, :columns]

    def second(self, x: NDArray, q_dot: NDArray, rheonomic: bool) -> NDArray:
        """Φ̈ at s̈_tree = 0 along x = (q, t) moving at (q̇, 1): Φ″(v, v) with its rheonomic parts, exact,
        whether or not Φ depends on t (``rheonomic``)."""
        return self._call(x[:-1], q_dot, x[-1])[3]


#: the kernels' helpers for a Φ made of cut joints, under the names of the general ones
_PINNED = {"_constraint_rows": _pin_constraint_rows, "_constraint_gamma": _pin_constraint_gamma,
           "_constraint_rates": _pin_constraint_rates, "_constraint_values": _pin_constraint_values}


@functools.cache
def _compiled(elastic: bool = False, pinned: bool = False) -> dict:
    """{"partitioned": …, "tangent": …, "cut_joint_rows": …, "closure_rows": …}: the kernels compiled by numba (cached on
    disk) as :func:`projeq.assembly.kernels.jit` compiles another module's kernels, calling the
    compiled kernels of :mod:`projeq.assembly.kernels` (the Gauss form's rigid variant, n_y = 6 a
    constant, or for trees with ``elastic`` bodies the one that reads each body's n_y), the force
    laws' loop of :mod:`projeq.assembly.loads`, and Φ, A and the UserJoints' relative motions through
    their C callbacks' addresses by the intrinsics :func:`phi_into` and :func:`~projeq.assembly.given.given_into`. For a Φ
    made of cut joints (``pinned``) the same source with the helpers of :data:`_PINNED` under the
    names of :func:`_constraint_rows`, :func:`_constraint_gamma` and :func:`_constraint_rates` (as
    the rigid passes take ``_six`` for ``_rows``): the other closures' kernels hold no code of theirs."""
    rules = ("partitioned", "tangent", "cut_joint_rows", "closure_rows")
    prefix = ("elastic_" if elastic else "") + ("pinned_" if pinned else "")
    replaced = _PINNED if pinned else {}
    return dict(zip(rules, kernels.jit(partitioned, tangent, cut_joint_rows, closure_rows, callees=_HELPERS,
                                       kernels=_compiled_callees(elastic),
                                       names=tuple(prefix + rule for rule in rules), **replaced)))


@functools.cache
def _compiled_adapter(kernel, rule: str):
    """:func:`partitioned_state_derivative` or :func:`tangent_state_derivative` (``rule``) compiled by
    numba, calling the compiled ``kernel`` (one of :func:`_compiled`'s) by the rule's name."""
    adapter = partitioned_state_derivative if rule == "partitioned" else tangent_state_derivative
    return kernels.jit(adapter, callees=(_split, _state_rates), kernels={rule: kernel},
                       names=(f"{kernel.py_func.__name__}_state_derivative",))[0]


def _interpreted(rule: str, pinned: bool):
    """The kernel ``rule`` interpreted (``compiled=False``), with the cut joints' rows for a
    ``pinned`` Φ as :func:`_compiled` compiles them."""
    if not pinned:
        return globals()[rule]
    namespace = {**globals(), **_PINNED}
    return types.FunctionType(globals()[rule].__code__, namespace, rule)


def _compiled_callees(elastic: bool) -> dict:
    """The compiled functions the kernels call by name: the tree's kernels, the force laws' loop and
    the intrinsics that call the C callbacks."""
    return {"chain_terms": kernels.kernel(True)[0], "gauss_form": kernels.gauss_form_kernel(True, rigid=not elastic)[0],
            "add_loads": loads.kernel(True), **intrinsics()}

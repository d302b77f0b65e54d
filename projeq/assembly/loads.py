"""The force laws of a System in the fast evaluator's compiled code: one loop over a table of
bound laws that calls each law's own numeric statement (:mod:`projeq.forces`).

Each law with constant loads or stated terms gives its row by ``compiled_terms`` — (kind,
indices, constants) — which :func:`table` packs into two arrays (as the joints travel in
:mod:`projeq.assembly.kernels`); :func:`add_loads` adds the loads of every row to the
kernel's h_n, reading the poses, twists, F_n and T_np of its workspace, by the functions the
laws' ``add_to`` call for the reference evaluators (plain Python in the style numba
compiles; :func:`kernel` compiles it, ``compiled=False`` runs the same source interpreted).
The kinds and their rows (``laws``: kind, first, second, …; ``constants``):

- ``"wrench"`` (:class:`~projeq.Force`, :class:`~projeq.Torque`): body n, world frame (1) or
  body frame (0); (f, p, τ) — :func:`projeq.forces.body_wrench`;
- ``"spring_damper"``: bodies a and b (−1: the ground); (p_a, p_b, k, d, ℓ₀) —
  :func:`projeq.forces.spring_damper`;
- ``"joint_force"``: joint n and its parent p; τ — :func:`projeq.forces.joint_wrench`;
- ``"joint_spring"``: joint n and its parent p; (k, d, q_ref) — τ by
  :func:`projeq.forces.spring_force` of the joint's coordinates and velocities (read at
  its places in q and ṡ, ``index``), then :func:`projeq.forces.joint_wrench`;
- ``"stated"`` (a :class:`~projeq.forces.BodyLoad`: a law that states its body wrench once as
  scalar code): body n; its parameters' values — the wrench by the C callback of its printed
  statement (:func:`projeq.assembly.generated.law_callback`, float64 and complex128: the
  callbacks' addresses in the columns CALLBACK, COMPLEX_CALLBACK), :func:`wrench_into`, at time t.

A load given as a callable (t, q, ṡ) (a :class:`~projeq.Force`, :class:`~projeq.Torque` or
:class:`~projeq.JointForce` whose ``compiled_load`` names it) runs in the loop too: compiled by
numba (:func:`projeq.assembly.generated.load_callbacks`), its callbacks' addresses in those
columns, it writes the load into the row's constants from column ``AT`` on at each evaluation
(:func:`loaded`); one numba refuses leaves its law on its own ``add_to`` (:func:`compiled_rows`
says why). The loop takes t as a number, so time-dependent loads stay compiled.

On an elastic body (a RitzBeam) the loads act on its reference frame (the first six rows of
h_n, as its S = [E; 0] selects them in the reference); a joint's pair takes the n_y rows of
F_n and T_np, so the reaction reaches an elastic parent's q̇_e rows.
Loads land in the spatial h_n of the kernel, also on bodies with a selection S (which the
kernel evaluates by their spatial terms, :mod:`projeq.assembly.fast`): the reference adds
Sᵀ S w, whose difference (E − SᵀS) w, out of the body's plane, no joint velocity that keeps
the body in its plane sees, so s̈ is the same. Index −1 (the ground) is the workspace's last
row (R = E, r = 0, twist = 0; reactions land there and are not read).
"""

from __future__ import annotations

import functools

import numpy as np

from projeq.assembly import kernels
from projeq.assembly.generated import intrinsics, law_callback, load_callbacks
from projeq.assembly.kernels import N_COLS, N_Y, Q_INDEX, S_INDEX
from projeq.forces import body_wrench, joint_wrench, spring_damper, spring_end, spring_force

WRENCH, SPRING_DAMPER, JOINT_FORCE, JOINT_SPRING, STATED = range(5)
KINDS = {"wrench": WRENCH, "spring_damper": SPRING_DAMPER, "joint_force": JOINT_FORCE, "joint_spring": JOINT_SPRING,
         "stated": STATED}
#: the columns of ``laws``: the kind, its two indices, the addresses of a stated law's callbacks or of a
#: load's callable (0: none), where that load goes in the row's constants and where the callable's
#: numbers (its data p) start there
KIND, FIRST, SECOND, CALLBACK, COMPLEX_CALLBACK, AT, PARAMETERS = range(7)
#: an "address" in the interpreted loop -> a stated law's printed wrench, or (callable, size) of a load
_INTERPRETED: dict = {}


def compiled_rows(system, compiled: bool) -> tuple[np.ndarray, np.ndarray, list]:
    """(laws, constants, python): the rows of ``system``'s force laws that run in the loop
    (:func:`table`; a stated law with its printed wrench's callbacks, :func:`stated_addresses`; a law
    with a load given as a callable with the callable's, :func:`load_addresses`) and the
    (law, why) of those that run their own ``add_to``: no row, or a piece numba cannot compile."""
    rows, python = [], []
    for law in system.forces:
        row, addresses, at, why = law.compiled_terms(), None, (0, 0), "its own add_to"
        if row is not None and row[0] == "stated":
            addresses = stated_addresses(law.compiled_wrench(), compiled)
            why = "" if addresses else "numba cannot compile its wrench"
        elif row is not None and law.compiled_load() is not None:
            function, load_at, size = law.compiled_load()
            addresses, p, why = load_addresses(function, size, system.n_q, system.n_s, compiled)
            at = load_at, len(row[2])  # the load's place, and the callable's numbers after the row's own
            row = (*row[:2], np.concatenate((row[2], p)))
        elif row is not None:
            why = ""
        if why:
            python.append((law, why))
        else:
            rows.append((row, addresses, at))
    return (*table(rows), python)


def table(rows) -> tuple[np.ndarray, np.ndarray]:
    """(laws, constants): the ``compiled_terms`` rows (kind, indices, constants), each with the two
    addresses of its callbacks (None: none) and where a load's callable writes in its constants and
    where its numbers start there, as an int array (L × 7: the columns KIND ... PARAMETERS) and a
    float array (L × the most constants, zero-padded)."""
    laws = np.zeros((len(rows), 7), dtype=np.int64)
    for i, ((kind, indices, _), addresses, at) in enumerate(rows):
        laws[i, :1 + len(indices)] = (KINDS[kind], *indices)
        if addresses is not None:
            laws[i, CALLBACK:COMPLEX_CALLBACK + 1] = addresses
        laws[i, AT:] = at
    constants = np.zeros((len(rows), max((len(c) for (_, _, c), _, _ in rows), default=0)))
    for i, ((_, _, c), _, _) in enumerate(rows):
        constants[i, :len(c)] = c
    return laws, constants


def stated_addresses(values, compiled: bool) -> tuple[int, int] | None:
    """The addresses of the float64 and complex128 C callbacks of a stated law's printed wrench
    ``values`` (:func:`projeq.assembly.generated.law_callback`; None where one does not compile);
    interpreted, a key of the printed function itself (:func:`wrench_into` looks it up)."""
    if not compiled:
        _INTERPRETED[id(values)] = values
        return id(values), id(values)
    callbacks = [law_callback(values, dtype) for dtype in (float, complex)]
    return None if None in callbacks else tuple(back.address for back in callbacks)


def load_addresses(function, size: int, n_q: int, n_s: int, compiled: bool) -> tuple:
    """((float64, complex128) addresses, p, "") of the C callbacks of a load given as a callable
    ``function(t, q, s_dot)`` of ``size`` entries and the numbers p they read
    (:func:`projeq.assembly.generated.load_callbacks`), or (None, p, why numba cannot compile it);
    interpreted, a key of the callable itself (:func:`load_into` looks it up)."""
    if not compiled:
        _INTERPRETED[id(function)] = function, size
        return (id(function), id(function)), np.zeros(0), ""
    callbacks, p = load_callbacks(function, size, n_q, n_s)
    if callbacks is None:
        name = getattr(function, "__qualname__", type(function).__name__)
        return None, np.zeros(0), f"numba cannot compile its callable {name} ({p})"
    return tuple(back.address for back in callbacks), p, ""


def wrench_into(address, complex_address, R, r, w, t, p, wrench):
    """wrench ← the body wrench (f; M_O) of a stated law at the body's pose R, r and twist w: in the
    compiled loop, by the C callback at ``address`` (``complex_address`` under the complex step;
    an intrinsic, :func:`projeq.assembly.generated.intrinsics`) with the law's parameters p;
    interpreted, by its printed function (its parameters in its closure)."""
    wrench[:] = _INTERPRETED[address](R.ravel(), r, w, t)


def load_into(address, complex_address, t, q, n_q, s_dot, n_s, p, load):
    """load ← a law's load given as a callable at (t, q, ṡ) (NaN where it returns another number of
    entries than the law's): in the compiled loop, by the C callback at ``address``
    (``complex_address`` under the complex step; an intrinsic,
    :func:`projeq.assembly.generated.intrinsics`) with the callable's numbers p; interpreted, by the
    callable itself."""
    function, size = _INTERPRETED[address]
    found = np.ravel(function(t, q[:n_q], s_dot[:n_s]))
    load[:size] = found if found.size == size else np.nan


def loaded(laws, i, c, t, q, s_dot, row) -> bool:
    """row ← the constants c of the law in row i of ``laws``, its load given as a callable (if any,
    :func:`load_into`) written from column ``AT`` on at (t, q, ṡ); False where that load is not finite."""
    for j in range(c.shape[0]):
        row[j] = c[j]
    if laws[i, CALLBACK] == 0:
        return True
    load_into(laws[i, CALLBACK], laws[i, COMPLEX_CALLBACK], t, q, q.shape[0], s_dot, s_dot.shape[0],
              c[laws[i, PARAMETERS]:], row[laws[i, AT]:])
    for j in range(row.shape[0]):
        if not (np.isfinite(row[j].real) and np.isfinite(row[j].imag)):
            return False
    return True


def add_loads(laws, constants, index, t, q, s_dot, q_all, s_all, R, r, twist, F, T, h):
    """h_n += the loads of every row of ``laws`` at time t and the kernel's kinematics (poses R, r,
    twists, F_n of ``index[n, N_COLS]`` columns, T_np: :func:`projeq.assembly.kernels.chain_terms`;
    q_all and ṡ_all: every joint's own coordinates and velocities; q and ṡ: the System's, which
    a load given as a callable reads — the same unless joints are coupled). Returns −1, or the row of
    a spring-damper whose two points coincide (no direction) or of a load that is not finite (its
    ``add_to`` says so)."""
    work, L = np.empty((4, 6), dtype=h.dtype), np.empty((6, 6), dtype=F.dtype)
    row = np.empty(constants.shape[1], dtype=h.dtype)
    wrench_a, wrench_b, tau, y = work[0], work[1], work[2], work[3]
    for i in range(laws.shape[0]):
        kind, a, b, c = laws[i, KIND], laws[i, FIRST], laws[i, SECOND], constants[i]
        if kind == WRENCH:
            if not loaded(laws, i, c, t, q, s_dot, row):
                return i
            body_wrench(R[a], row[0:3], row[3:6], row[6:9], b == 1, wrench_a)
            for j in range(6):
                h[a, j] += wrench_a[j]
        elif kind == STATED:
            wrench_into(laws[i, CALLBACK], laws[i, COMPLEX_CALLBACK], R[a], r[a], twist[a], t, c, wrench_a)
            for j in range(6):
                h[a, j] += wrench_a[j]
        elif kind == SPRING_DAMPER:
            if not spring_damper(R[a], r[a], twist[a], c[0:3], R[b], r[b], twist[b], c[3:6], c[6], c[7], c[8],
                                 wrench_a, wrench_b):
                return i
            for j in range(6):
                h[a, j] += wrench_a[j]
                h[b, j] += wrench_b[j]
        else:  # F_n, T_np of n_y rows; k = the joint's own columns of F_n (an elastic body's q̇_e follow)
            n_y, n_y_p = index[a, N_Y], index[b, N_Y] if b >= 0 else 6
            k = index[a, N_COLS] - n_y + 6
            if kind == JOINT_SPRING:
                q0, s0 = index[a, Q_INDEX], index[a, S_INDEX]
                spring_force(c[0], c[1], q_all[q0 : q0 + k], c[2 : 2 + k], s_all[s0 : s0 + k], tau[:k])
            elif loaded(laws, i, c, t, q, s_dot, row):
                tau[:k] = row[:k]
            else:
                return i
            joint_wrench(F[a, :n_y, :k], T[a, :n_y, :n_y_p], tau[:k], L, y, h[a, :n_y], h[b, :n_y_p])
    return -1


def kernel(compiled: bool = True):
    """:func:`add_loads`, compiled by numba (as :func:`projeq.assembly.kernels.kernel`;
    ValueError without it) or with ``compiled=False`` the interpreted function."""
    if not compiled:
        return add_loads
    kernels.kernel(True)  # the same refusal without numba
    return _compiled()[0]


#: the statements the loop calls (compiled with it)
CALLEES = (body_wrench, spring_end, spring_damper, spring_force, joint_wrench, loaded)


@functools.cache
def _compiled():
    intrinsic = intrinsics()
    return kernels.jit(add_loads, callees=CALLEES,
                       kernels={"wrench_into": intrinsic["wrench_into"], "load_into": intrinsic["load_into"]})

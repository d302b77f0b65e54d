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
(:func:`given_motions`, one row per joint of :func:`joint_table`). The fast evaluator's one-call
kernels (:func:`given_state_derivative`, :func:`given_jacobian`) then take such trees: ẋ = (q̇, s̈)
with q̇ of those joints from their rows (:func:`given_rates`), and ∂ẋ/∂x, ∂q̇/∂x included, by the
complex step (Squire & Trapp, "Using complex variables to estimate derivatives of real functions",
SIAM Review 40, 1998); the closure kernels of :mod:`projeq.constraints.compiled` call the same
callbacks.
"""

from __future__ import annotations

import functools
import hashlib
import os
import sys
import tempfile
import types
import warnings
from pathlib import Path

import numpy as np

from projeq.assembly import kernels, loads
from projeq.assembly.kernels import (
    GIVEN,
    GIVEN_F,
    KIND,
    N_COLS,
    Q_INDEX,
    S_INDEX,
    tree_accelerations,
    tree_state_derivative,
)


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

_CALLBACKS: dict = {}  # (source, dtype) -> its C callback, or None where numba cannot compile it
_PARAMETERS: dict = {}  # compiled_values -> the values of its constants (float64), which its callback reads
_DTYPES = {np.dtype(float): "float64", np.dtype(complex): "complex128"}


def row_width(joint) -> int:
    """The entries of a joint's compiled row: A, r, w, ζ, F⁶ (:data:`projeq.assembly.kernels.GIVEN_F`
    + 6 n_s), then q̇ (n_q)."""
    return GIVEN_F + 6 * joint.n_s + joint.n_q


def joint_callback(joint, dtype=float):
    """The joint's ``compiled_values()`` (its row, :func:`row_width` entries) compiled as a C callback
    ``into(q_n, ṡ_n, t, p, row)`` at q_n, ṡ_n and row of ``dtype`` (float or complex), t float64 and
    the values p of its constants (:func:`parameters`: data, not code, so joints that differ only in
    their parameters' values share one callback), built once per printed source and dtype in a process
    and cached on disk (:func:`generated_module`); None for a joint without compiled values, or (after
    one :class:`UncompiledJointWarning`) where numba cannot compile them."""
    values = joint.compiled_values()
    if values is None:
        return None
    key = (values.source, values.constants, joint.n_q, joint.n_s, np.dtype(dtype))
    if key not in _CALLBACKS:
        into = JOINT_INTO.format(dtype=_DTYPES[np.dtype(dtype)], n_q=joint.n_q, n_s=joint.n_s, width=row_width(joint),
                                 n_p=len(values.constants))
        try:
            _CALLBACKS[key] = generated_module(values, into, parameters=True).into
        except Exception as exc:  # noqa: BLE001 — numba's typing and lowering errors have no common base
            warnings.warn(f"joint: numba cannot compile the relative motion of {joint!r} for {np.dtype(dtype)} "
                          f"({type(exc).__name__}); it is stated in Python at every evaluation",
                          UncompiledJointWarning, stacklevel=3)
            _CALLBACKS[key] = None
    return _CALLBACKS[key]


def parameters(f) -> np.ndarray:
    """The values of the constants (``f.constants``) that the printed function ``f`` of
    :mod:`projeq.symbolic.codegen` holds in its closure, in their order, as float64 (kept alive here
    while the process runs: the compiled kernels read them through their address)."""
    if f not in _PARAMETERS:
        held = dict(zip(f.__code__.co_freevars, (c.cell_contents for c in f.__closure__ or ())))
        _PARAMETERS[f] = np.array([float(held[name]) for name in f.constants], dtype=float)
    return _PARAMETERS[f]


def generated_module(f, into: str, parameters: bool = False):
    """A module of ``f``'s printed source (``f.source``) compiled by ``numba.njit(cache=True)`` as
    ``function``, and the C callback ``into`` (``cache=True``): written once to a file named by its
    digest in numba's cache directory (or ~/.cache/projeq) and imported, so that numba's disk cache,
    which needs a file, keeps both across processes (a temporary directory where that is not
    writable: compiled anew each process). ``f``'s constants (``f.constants``) are, with
    ``parameters``, the entries of a last argument p of ``function`` (one module for all their
    values), else module globals holding the values its closure holds."""
    import importlib.util

    numba = kernels.numba_module()
    header = f.source.split("\n", 1)
    if parameters:
        signature = header[0].replace(f"def {f.__name__}(", "def function(", 1).replace("):", ", p):", 1)
        unpacked = [f"    {name} = p[{i}]" for i, name in enumerate(f.constants)]
        constants, body = [], "\n".join([signature, *unpacked, header[1]])
    else:
        held = dict(zip(f.__code__.co_freevars, (c.cell_contents for c in f.__closure__ or ())))
        constants = [f"{name} = {float(value)!r}" for name, value in sorted(held.items())]
        body = f.source.replace(f"def {f.__name__}(", "def function(", 1)
    source = "\n".join(["import numba", "import numpy", "from numba import types as nb", "", *constants, "",
                        "@numba.njit(cache=True)", body, into])
    digest = hashlib.sha1((source + numba.__version__).encode()).hexdigest()[:20]
    module_name = f"projeq_generated_{digest}"
    if module_name not in sys.modules:
        path = write_once(module_name + ".py", source)
        spec = importlib.util.spec_from_file_location(module_name, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[module_name] = module  # numba's cache finds the module by its name
        try:
            spec.loader.exec_module(module)
        except Exception:
            del sys.modules[module_name]
            raise
    return sys.modules[module_name]


def write_once(filename: str, source: str) -> Path:
    """The path of ``filename`` holding ``source`` in the cache directory (written atomically if absent)."""
    import numba

    for folder in (numba.config.CACHE_DIR or os.path.join(os.environ.get("XDG_CACHE_HOME") or
                                                           os.path.expanduser("~/.cache"), "projeq"), None):
        try:
            folder = Path(folder or tempfile.mkdtemp(prefix="projeq-generated-")) / "generated"
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / filename
            if not path.is_file() or path.read_text() != source:
                part = folder / f"{filename}.{os.getpid()}.part"
                part.write_text(source)
                os.replace(part, path)
            return path
        except OSError:
            continue
    raise OSError(f"cannot write the generated module {filename} to a cache or a temporary directory")


def joint_table(plan, callbacks, compiled: bool = True) -> np.ndarray:
    """One row (n, first coordinate, n_q, first velocity, n_s, callback, parameters) per joint of kind
    GIVEN of a fast evaluator's ``plan`` (its (n, joint, q slice, ṡ slice, width) rows), as
    :func:`given_motions` reads them: its C callback's address (``callbacks``) and that of its
    parameters' values (:func:`parameters`), or interpreted (``compiled=False``) its
    ``compiled_values`` function (its constants in its closure) and None."""
    rows = []
    for (n, joint, q_n, s_n, _), back in zip(plan, callbacks):
        values = joint.compiled_values()
        rows.append([n, q_n.start, joint.n_q, s_n.start, joint.n_s, back.address, parameters(values).ctypes.data]
                    if compiled else [n, q_n.start, joint.n_q, s_n.start, joint.n_s, values, None])
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
    return tree_state_derivative(index, geometry, inertia, gravity, laws, constants, x, n_q, given, elastic, port, T,
                                 zeta, F, M_n, M_hat, h_hat, R, r_O, twist, pivot_min, x_dot)


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


@functools.cache
def motions_kernel():
    """:func:`given_motions` compiled alone (the fast evaluator's s̈, whose force laws may run in Python;
    ValueError without numba, as :func:`projeq.assembly.kernels.kernel`)."""
    kernels.kernel(True)
    return kernels.jit(given_motions, kernels=intrinsics())[0]


@functools.cache
def intrinsics() -> dict:
    """The compiled :func:`given_into` and ``phi_into`` (Φ's values of :mod:`projeq.constraints.compiled`):
    each calls the C function at the address its first argument holds with the data pointers of its
    arrays (numba's own layout of complex128 and float64, that of the C callbacks) and its scalars
    as they are."""
    import numba
    from llvmlite import ir
    from numba.extending import intrinsic

    def caller(signature, args, context, builder, pointers=()):
        """Call the C function at the address ``args[0]`` with the arrays' data pointers, the
        arguments at the positions ``pointers`` (addresses, int64) as float64 pointers and the other
        scalars as they are."""
        address, values = args[0], []
        for i, (kind, value) in enumerate(zip(signature.args[1:], args[1:]), start=1):
            if isinstance(kind, numba.types.Array):
                values.append(context.make_array(kind)(context, builder, value).data)
            else:
                values.append(builder.inttoptr(value, ir.PointerType(ir.DoubleType())) if i in pointers else value)
        function = ir.FunctionType(ir.VoidType(), [v.type for v in values])
        builder.call(builder.inttoptr(address, function.as_pointer()), values)
        return context.get_dummy_value()

    @intrinsic
    def phi_into(typingctx, phi, x, t, value):
        return numba.types.void(phi, x, t, value), lambda context, builder, signature, args: caller(
            signature, args, context, builder)

    @intrinsic
    def given_into(typingctx, values, p, q_n, s_n, t, row):  # the C callback's order: q_n, ṡ_n, t, p, row
        def call(context, builder, signature, args):
            values_, p_, q_, s_, t_, row_ = args
            kinds = signature.args
            reordered = numba.types.void(kinds[0], kinds[2], kinds[3], kinds[4], kinds[1], kinds[5])
            return caller(reordered, (values_, q_, s_, t_, p_, row_), context, builder, pointers=(4,))

        return numba.types.void(values, p, q_n, s_n, t, row), call

    return {"phi_into": phi_into, "given_into": given_into}

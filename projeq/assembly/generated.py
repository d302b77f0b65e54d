"""Code projeq generates at run time and the compiled kernels call through addresses (docs/theory.md §4).

A plug-in's statement, traced with sympy and printed as scalar code (:mod:`projeq.symbolic.codegen`),
is compiled by numba into a C callback — a joint's relative motion (:mod:`projeq.assembly.given`), a
force law's body wrench (:func:`law_callback`), a constraint Φ (:mod:`projeq.constraints.compiled`) —
in a module written once per printed source (:func:`generated_module`) and cached on disk; a load
given as a callable of (t, q, ṡ) is compiled by ``numba.njit`` in memory (:func:`load_callbacks`); the
numbers of the plug-in (its parameters) are data, passed by the address of an array
(:func:`parameters`); the compiled kernels call the callbacks through their addresses by the
intrinsics of :func:`intrinsics`.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import sys
import tempfile
import warnings
from pathlib import Path

import numpy as np

from projeq.assembly import kernels

_PARAMETERS: dict = {}  # printed function -> the values of its constants (float64), which its callback reads
DTYPES = {np.dtype(float): "float64", np.dtype(complex): "complex128"}


class UncompiledLawWarning(UserWarning):
    """numba could not compile a force law's printed wrench: it is stated in Python."""


def parameters(f) -> np.ndarray:
    """The values of the constants (``f.constants``) of the printed function ``f`` of
    :mod:`projeq.symbolic.codegen` (``f.values``) as float64, kept alive here while the process runs:
    the compiled kernels read them through their address."""
    if f not in _PARAMETERS:
        _PARAMETERS[f] = np.array(f.values, dtype=float)
    return _PARAMETERS[f]


def generated_module(f, into: str, parameters: bool = False):
    """A module of ``f``'s printed source (``f.source``) compiled by ``numba.njit(cache=True)`` as
    ``function``, and the C callback ``into`` (``cache=True``): written once to a file named by its
    digest in numba's cache directory (or ~/.cache/projeq) and imported, so that numba's disk cache,
    which needs a file, keeps both across processes (a temporary directory where that is not
    writable: compiled anew each process). ``f``'s constants (``f.constants``) are, with
    ``parameters``, the entries of a last argument p of ``function`` (one module for all their
    values), else module globals holding their values (``f.values``)."""
    import importlib.util

    numba = kernels.numba_module()
    header = f.source.split("\n", 1)
    if parameters:
        signature = header[0].replace(f"def {f.__name__}(", "def function(", 1).replace("):", ", p):", 1)
        unpacked = [f"    {name} = p[{i}]" for i, name in enumerate(f.constants)]
        constants, body = [], "\n".join([signature, *unpacked, header[1]])
    else:
        constants = [f"{name} = {float(value)!r}" for name, value in sorted(zip(f.constants, f.values))]
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



#: the C callback of a force law's printed body wrench (:func:`law_callback`): at the body's pose R
#: (row by row), r and twist (v, ω) of one dtype, t float64 and the law's parameters p (float64)
LAW_INTO = """
@numba.cfunc(nb.void(nb.CPointer(nb.{dtype}), nb.CPointer(nb.{dtype}), nb.CPointer(nb.{dtype}), nb.float64,
                     nb.CPointer(nb.float64), nb.CPointer(nb.{dtype})), cache=True)
def into(R_pointer, r_pointer, w_pointer, t, p_pointer, wrench_pointer):
    R, r, w = numba.carray(R_pointer, (9,)), numba.carray(r_pointer, (3,)), numba.carray(w_pointer, (6,))
    found = function(R, r, w, t, numba.carray(p_pointer, ({n_p},)))
    wrench = numba.carray(wrench_pointer, (6,))
    for i in range(6):
        wrench[i] = found[i]
"""

_CALLBACKS: dict = {}  # (source, constants, into) -> the C callback, or None where numba cannot compile it


def callback(values, into: str, what: str, category):
    """``into`` of :func:`generated_module` (the printed function ``values``, its constants passed as
    data, :func:`parameters`): one per printed source and callback in a process, cached on disk;
    None where numba cannot compile it, after one warning of ``category`` naming ``what``."""
    key = (values.source, values.constants, into)
    if key not in _CALLBACKS:
        try:
            _CALLBACKS[key] = generated_module(values, into, parameters=True).into
        except Exception as exc:  # noqa: BLE001 — numba's typing and lowering errors have no common base
            warnings.warn(f"{what} ({type(exc).__name__}); it is stated in Python at every evaluation", category,
                          stacklevel=4)
            _CALLBACKS[key] = None
    return _CALLBACKS[key]


def law_callback(values, dtype=float):
    """The printed body wrench ``values(R, r, w, t)`` of a force law (:meth:`projeq.forces.BodyLoad.compiled_wrench`)
    compiled as a C callback ``into(R, r, w, t, p, wrench)`` of ``dtype`` (float, or complex for the
    complex step), its constants p passed as data (:func:`callback`); None (after one
    :class:`UncompiledLawWarning`) where numba cannot compile it."""
    into = LAW_INTO.format(dtype=DTYPES[np.dtype(dtype)], n_p=len(values.constants))
    return callback(values, into, f"forces: numba cannot compile a force law's wrench for {np.dtype(dtype)}",
                    UncompiledLawWarning)


_LOADS: dict = {}  # (load_key(function), size, n_q, n_s) -> (its float64 and complex128 C callbacks, why not)


def load_key(function):
    """A hashable key of a callable's code and captured values (its closure's cells, arrays by their
    bytes, and its defaults): one compiled callback for closures of the same source and numbers (a
    scene built twice); the callable itself where they do not hash."""
    try:
        cells = tuple(_frozen(c.cell_contents) for c in (function.__closure__ or ()))
        key = (function.__code__, cells, function.__defaults__)
        hash(key)
    except (AttributeError, TypeError, ValueError):
        return function
    return key


def _frozen(value):
    """An array as (dtype, shape, bytes), hashable; anything else as it is."""
    return (value.dtype.str, value.shape, value.tobytes()) if isinstance(value, np.ndarray) else value


def load_callbacks(function, size: int, n_q: int, n_s: int) -> tuple[tuple | None, str]:
    """((float64, complex128) C callbacks ``into(t, q, n_q, s_dot, n_s, load)``, "") of a load given as a
    callable ``function(t, q, s_dot)`` of ``size`` entries (a scalar where ``size`` is 1), compiled by
    ``numba.njit`` — once per source and captured numbers in a process (:func:`load_key`), in memory:
    a user's function has no file for numba's disk cache — and checked against the callable's own
    values, real and imaginary parts (a complex step) each to 1e-13 relative, at three states of
    n_q coordinates and n_s velocities; (None, why) where numba cannot compile it or its values
    differ. A returned load of another size writes NaN (the loop of laws then names the law,
    :func:`projeq.assembly.loads.add_loads`). numba takes the numbers a callable reads from its
    module's globals as constants when it compiles them, as ``numba.njit`` does."""
    key = (load_key(function), size, n_q, n_s)
    if key not in _LOADS:
        try:
            _LOADS[key] = _compiled_load(function, size, n_q, n_s), ""
        except Exception as exc:  # noqa: BLE001 — numba's typing and lowering errors have no common base
            lines = [line.strip() for line in re.sub(r"\x1b\[[0-9;]*m", "", str(exc)).splitlines() if line.strip()]
            _LOADS[key] = None, f"{type(exc).__name__}: {' '.join(lines[:2])[:200]}"
    return _LOADS[key]


def _compiled_load(function, size: int, n_q: int, n_s: int) -> tuple:
    """:func:`load_callbacks`' callbacks; raises where numba refuses the callable or its values differ."""
    numba = kernels.numba_module()
    from numba import types as nb

    jitted = function if isinstance(function, numba.core.dispatcher.Dispatcher) else numba.njit(function)
    rng = np.random.default_rng(7)
    for t in (0.0, 0.37, 1.9):
        q, s_dot = (rng.uniform(-1, 1, n) + 1j * 1e-30 * rng.standard_normal(n) for n in (n_q, n_s))
        want = np.ravel(np.asarray(function(t, q, s_dot), dtype=complex))
        got = np.ravel(np.asarray(jitted(t, q, s_dot), dtype=complex))
        scale, rate = max(1.0, np.abs(want.real).max(initial=0.0)), max(1.0, np.abs(want.imag / 1e-30).max(initial=0.0))
        if not (got.shape == want.shape == (size,) and np.all(np.abs(got.real - want.real) <= 1e-13 * scale)
                and np.all(np.abs(got.imag - want.imag) / 1e-30 <= 1e-13 * rate)):
            raise ValueError(f"its compiled values {got} differ from its own {want} at t = {t}")

    def into(t, q_pointer, n_q, s_pointer, n_s, load_pointer):
        q, s_dot = numba.carray(q_pointer, (n_q,)), numba.carray(s_pointer, (n_s,))
        found, load = np.asarray(jitted(t, q, s_dot)).ravel(), numba.carray(load_pointer, (size,))
        for i in range(size):
            load[i] = found[i] if found.shape[0] == size else np.nan

    return tuple(numba.cfunc(nb.void(nb.float64, nb.CPointer(kind), nb.int64, nb.CPointer(kind), nb.int64,
                                     nb.CPointer(kind)))(into) for kind in (nb.float64, nb.complex128))


@functools.cache
def intrinsics() -> dict:
    """The compiled :func:`projeq.assembly.given.given_into`, ``phi_into`` (Φ's values of
    :mod:`projeq.constraints.compiled`), :func:`projeq.assembly.loads.wrench_into` and
    :func:`projeq.assembly.loads.load_into`:
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


    @intrinsic
    def wrench_into(typingctx, address, complex_address, R, r, w, t, p, wrench):
        # the callback of the arrays' dtype: complex128 under the complex step, else float64
        def call(context, builder, signature, args):
            kinds = signature.args
            chosen = 1 if isinstance(kinds[2].dtype, numba.types.Complex) else 0
            reordered = numba.types.void(kinds[chosen], *kinds[2:])
            return caller(reordered, (args[chosen], *args[2:]), context, builder)

        return numba.types.void(address, complex_address, R, r, w, t, p, wrench), call

    @intrinsic
    def load_into(typingctx, address, complex_address, t, q, n_q, s_dot, n_s, load):
        # the callback of the arrays' dtype (:func:`load_callbacks`): complex128 under the complex step
        if not q.dtype == s_dot.dtype == load.dtype:
            return None

        def call(context, builder, signature, args):
            kinds = signature.args
            chosen = 1 if isinstance(kinds[3].dtype, numba.types.Complex) else 0
            return caller(numba.types.void(kinds[chosen], *kinds[2:]), (args[chosen], *args[2:]), context, builder)

        return numba.types.void(address, complex_address, t, q, n_q, s_dot, n_s, load), call

    return {"phi_into": phi_into, "given_into": given_into, "wrench_into": wrench_into, "load_into": load_into}

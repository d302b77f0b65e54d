"""Code projeq generates at run time and the compiled kernels call through addresses (docs/theory.md §4).

A plug-in's statement, traced with sympy and printed as scalar code (:mod:`projeq.symbolic.codegen`),
is compiled by numba into a C callback — a joint's relative motion (:mod:`projeq.assembly.given`), a
force law's body wrench (:func:`law_callback`), a constraint Φ (:mod:`projeq.constraints.compiled`) —
in a module written once per printed source (:func:`generated_module`) and cached on disk; a
plug-in given as a Python callable — a load of (t, q, ṡ) (:func:`load_callbacks`), a prescribed
motion t ↦ (θ, θ̇, θ̈) (:func:`projeq.assembly.given.motion_callbacks`) — is printed from its source
with the numbers it reads as data, or compiled by ``numba.njit`` in memory with them frozen, and
its compiled values checked against its own (:func:`callable_callbacks`); the numbers of the
plug-in (its parameters) are data, passed by the address of an array (:func:`parameters`); the
compiled kernels call the callbacks through their addresses by the intrinsics of
:func:`intrinsics`.
"""

from __future__ import annotations

import functools
import hashlib
import os
import re
import sys
import tempfile
import types
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


#: the imports every generated module starts with
HEADER = "import numba\nimport numpy\nfrom numba import types as nb\n"


def generated_module(f, into: str, parameters: bool = False):
    """A module of ``f``'s printed source (``f.source``) compiled by ``numba.njit(cache=True)`` as
    ``function`` (:func:`printed_source`), and the C callback ``into`` (``cache=True``): written once to
    a file named by its digest in numba's cache directory (or ~/.cache/projeq) and imported, so that
    numba's disk cache, which needs a file, keeps both across processes (a temporary directory where
    that is not writable: compiled anew each process)."""
    return source_module("\n".join([HEADER, printed_source(f, "function", parameters), into]))


def printed_source(f, name: str, parameters: bool = False) -> str:
    """The source of ``f``'s printed function (``f.source``) as ``name``, under ``numba.njit(cache=True)``:
    ``f``'s constants (``f.constants``) are, with ``parameters``, the entries of a last argument p
    (one module for all their values), else module globals holding their values (``f.values``)."""
    header = f.source.split("\n", 1)
    if parameters:
        signature = header[0].replace(f"def {f.__name__}(", f"def {name}(", 1).replace("):", ", p):", 1)
        unpacked = [f"    {constant} = p[{i}]" for i, constant in enumerate(f.constants)]
        constants, body = [], "\n".join([signature, *unpacked, header[1]])
    else:
        constants = [f"{constant} = {float(value)!r}" for constant, value in sorted(zip(f.constants, f.values))]
        body = f.source.replace(f"def {f.__name__}(", f"def {name}(", 1)
    return "\n".join([*constants, "", "@numba.njit(cache=True)", body])


def source_module(source: str):
    """The module of ``source`` (:func:`generated_module`), written once to a file named by its digest
    and imported, once per process."""
    import importlib.util

    numba = kernels.numba_module()
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


_CALLABLES: dict = {}  # (callable_key(function), *key) -> (callbacks, parameters), or (None, why not)


def callable_key(function):
    """A hashable key of a callable's code and the values it reads (its closure's cells, the numbers
    of its module it names, arrays by their bytes, and its defaults): one check of closures of the
    same source and numbers (a scene built twice); the callable itself where they do not hash."""
    try:
        cells = tuple(_frozen(c.cell_contents) for c in (function.__closure__ or ()))
        numbers = tuple((name, _frozen(function.__globals__[name])) for name in sorted(_names(function.__code__))
                        if isinstance(function.__globals__.get(name), (int, float, np.number, np.ndarray)))
        key = (function.__code__, cells, numbers, function.__defaults__)
        hash(key)
    except (AttributeError, TypeError, ValueError):
        return function
    return key


def _names(code) -> set:
    """The names a code object and its nested ones (comprehensions, inner functions) read."""
    names, codes = set(), [code]
    while codes:
        c = codes.pop()
        names.update(c.co_names)
        codes.extend(k for k in c.co_consts if isinstance(k, types.CodeType))
    return names


def _frozen(value):
    """An array as (dtype, shape, bytes), hashable; anything else as it is."""
    return (value.dtype.str, value.shape, value.tobytes()) if isinstance(value, np.ndarray) else value


def callable_callbacks(function, key: tuple, samples: list, size: int, stated_into, frozen_into) -> tuple:
    """((float64, complex128) C callbacks, parameters p) of a plug-in given as a Python callable
    ``function`` (a load of (t, q, ṡ), :func:`load_callbacks`; a prescribed motion of t,
    :func:`projeq.assembly.given.motion_callbacks`), or (None, why) where numba cannot compile it or
    its compiled values differ from its own at the arguments ``samples`` (:func:`check_values`, ``size``
    entries). A lambda or function whose source reads numbers (scalars, real arrays) from its closure
    or module is printed as ``function(*arguments, p)`` with those numbers as the data p
    (:func:`stated_callable`), followed by the callbacks' source ``stated_into(len(p))`` (defining
    ``into`` and ``complex_into``): one compiled module per source, cached on disk, for every value of
    its numbers; any other is compiled by ``numba.njit`` in memory with its captured values frozen
    and its callbacks are ``frozen_into(jitted)`` (p empty). One attempt per callable's code, numbers
    and ``key`` in a process."""
    key = (callable_key(function), *key)
    if key not in _CALLABLES:
        try:
            _CALLABLES[key] = _compiled_callable(function, samples, size, stated_into, frozen_into)
        except Exception as exc:  # noqa: BLE001 — numba's typing and lowering errors have no common base
            lines = [line.strip() for line in re.sub(r"\x1b\[[0-9;]*m", "", str(exc)).splitlines()]
            _CALLABLES[key] = None, f"{type(exc).__name__}: {' '.join(filter(None, lines))[:200]}"
    return _CALLABLES[key]


def _compiled_callable(function, samples: list, size: int, stated_into, frozen_into) -> tuple:
    """:func:`callable_callbacks`' (callbacks, parameters); raises where numba refuses the callable or
    its values differ."""
    stated = stated_callable(function, len(samples[0]))
    if stated is not None:
        try:
            source, p = stated
            module = source_module(source + stated_into(len(p)))
            check_values(function, lambda *arguments: module.function(*arguments, p), samples, size)
            return (module.into, module.complex_into), p
        except Exception:  # noqa: BLE001 — compiled with its numbers frozen instead
            pass
    numba = kernels.numba_module()
    jitted = function if isinstance(function, numba.core.dispatcher.Dispatcher) else numba.njit(function)
    check_values(function, jitted, samples, size)
    return frozen_into(jitted), np.zeros(0)


def check_values(function, jitted, samples: list, size: int) -> None:
    """ValueError unless the compiled ``jitted`` gives ``function``'s values at each argument tuple of
    ``samples`` (t first): ``size`` entries, their real and imaginary parts (a complex step) each to
    1e-13 relative, NaN where its own are NaN."""
    for arguments in samples:
        t = arguments[0]
        try:
            want = np.ravel(np.asarray(function(*arguments), dtype=complex))
        except Exception as exc:  # noqa: BLE001 — a user's callable raises what it raises
            raise ValueError(f"calling it at t = {t} raised {type(exc).__name__}: {exc}") from exc
        got = np.ravel(np.asarray(jitted(*arguments), dtype=complex))
        if got.shape != want.shape or not np.array_equal(np.isnan(got), np.isnan(want)):
            raise ValueError(f"its compiled values {got} differ from its own {want} at t = {t}")
        got, want = np.nan_to_num(got), np.nan_to_num(want)  # a NaN where its own is NaN: the loop names it
        scale = max(1.0, np.abs(want.real).max(initial=0.0))
        rate = max(1.0, np.abs(want.imag / 1e-30).max(initial=0.0))
        if not (want.shape == (size,) and np.all(np.abs(got.real - want.real) <= 1e-13 * scale)
                and np.all(np.abs(got.imag - want.imag) / 1e-30 <= 1e-13 * rate)):
            raise ValueError(f"its compiled values {got} differ from its own {want} at t = {t}")


def frozen_callbacks(into, signature) -> tuple:
    """The C callbacks of float64 and complex128 (``signature(kind)``, the kind of their arrays) of
    ``into``, compiled by ``numba.cfunc`` in memory, the numbers it reads frozen
    (:func:`callable_callbacks`)."""
    numba = kernels.numba_module()
    from numba import types as nb

    return tuple(numba.cfunc(signature(kind))(into) for kind in (nb.float64, nb.complex128))


def load_callbacks(function, size: int, n_q: int, n_s: int) -> tuple:
    """((float64, complex128) C callbacks ``into(t, q, n_q, s_dot, n_s, p, load)``, parameters p) of a
    load given as a callable ``function(t, q, s_dot)`` of ``size`` entries (a scalar where ``size``
    is 1), or (None, why) where numba cannot compile it or its compiled values differ from its own
    at three states of n_q coordinates and n_s velocities (real and imaginary parts, a complex step):
    :func:`callable_callbacks`. A load of another size is written as NaN (the loop then names the
    law, :func:`projeq.assembly.loads.add_loads`)."""
    rng = np.random.default_rng(7)
    samples = [(t, *(rng.uniform(-1, 1, n) + 1j * 1e-30 * rng.standard_normal(n) for n in (n_q, n_s)))
               for t in (0.0, 0.37, 1.9)]
    return callable_callbacks(
        function, ("load", size, n_q, n_s), samples, size,
        lambda n_p: "".join(LOAD_INTO.format(n_p=n_p, size=size, dtype=dtype, name=name)
                            for dtype, name in (("float64", "into"), ("complex128", "complex_into"))),
        lambda jitted: _frozen_load(jitted, size))


#: a C callback of a stated load (:func:`stated_callable`) of one dtype
LOAD_INTO = """
@numba.cfunc(nb.void(nb.float64, nb.CPointer(nb.{dtype}), nb.int64, nb.CPointer(nb.{dtype}), nb.int64,
                     nb.CPointer(nb.float64), nb.CPointer(nb.{dtype})), cache=True)
def {name}(t, q_pointer, n_q, s_pointer, n_s, p_pointer, load_pointer):
    q, s_dot = numba.carray(q_pointer, (n_q,)), numba.carray(s_pointer, (n_s,))
    p = numba.carray(p_pointer, ({n_p},))
    found, load = numpy.asarray(function(t, q, s_dot, p)).ravel(), numba.carray(load_pointer, ({size},))
    for i in range({size}):
        load[i] = found[i] if found.shape[0] == {size} else numpy.nan
"""


def _frozen_load(jitted, size: int) -> tuple:
    """The C callbacks of :func:`load_callbacks` around a compiled callable (its numbers frozen, p unread)."""
    numba = kernels.numba_module()
    from numba import types as nb

    def into(t, q_pointer, n_q, s_pointer, n_s, p_pointer, load_pointer):
        q, s_dot = numba.carray(q_pointer, (n_q,)), numba.carray(s_pointer, (n_s,))
        found, load = np.asarray(jitted(t, q, s_dot)).ravel(), numba.carray(load_pointer, (size,))
        for i in range(size):
            load[i] = found[i] if found.shape[0] == size else np.nan

    return frozen_callbacks(into, lambda kind: nb.void(nb.float64, nb.CPointer(kind), nb.int64, nb.CPointer(kind),
                                                       nb.int64, nb.CPointer(nb.float64), nb.CPointer(kind)))


def stated_callable(function, n_arguments: int) -> tuple[str, np.ndarray] | None:
    """(source, p): a lambda or function of ``n_arguments`` positional arguments (a load's t, q,
    s_dot; a motion's t) printed as ``function(*arguments, p)``, the numbers it reads from its
    closure and its module (scalars and real arrays) unpacked from p at its start and the modules it
    reads imported by their names; None where its source cannot be found (one lambda or def of its
    arguments on its first line) or it reads anything else."""
    import ast
    import inspect
    import linecache

    code = getattr(function, "__code__", None)
    if code is None or code.co_argcount != n_arguments or function.__defaults__ or code.co_kwonlyargcount:
        return None
    try:
        tree = ast.parse("".join(linecache.getlines(inspect.getsourcefile(function))))
    except (OSError, TypeError, SyntaxError):
        return None
    arguments = list(code.co_varnames[:n_arguments])
    found = [node for node in ast.walk(tree) if isinstance(node, (ast.Lambda, ast.FunctionDef))
             and min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])]) == code.co_firstlineno
             and [a.arg for a in node.args.args] == arguments
             and not (node.args.vararg or node.args.kwarg)]
    if len(found) != 1:
        return None
    values = dict(zip(code.co_freevars, (cell.cell_contents for cell in function.__closure__ or ())))
    imports = []
    for name in sorted(_names(code)):
        value = function.__globals__.get(name)
        if isinstance(value, types.ModuleType):
            imports.append(f"import {value.__name__} as {name}")
        elif name in function.__globals__:
            values[name] = value
    lines, p = [], []
    for name, value in values.items():
        if isinstance(value, bool) or not (isinstance(value, (int, float, np.integer, np.floating)) or
                                           isinstance(value, np.ndarray) and value.dtype.kind == "f"):
            return None  # anything else (a function, an object): compiled with it frozen
        value = np.asarray(value, dtype=float)
        at = sum(len(v) for v in p)
        p.append(value.ravel())
        entries = f"projeq_p[{at}:{at + value.size}]"
        unpacked = f"projeq_p[{at}]" if value.ndim == 0 else entries if value.ndim == 1 else \
            f"{entries}.reshape({value.shape})"
        lines.append(f"    {name} = {unpacked}")
    node = found[0]
    body = [f"    return {ast.unparse(node.body)}"] if isinstance(node, ast.Lambda) else \
        [f"    {line}" for statement in node.body for line in ast.unparse(statement).splitlines()]
    signature = f"def function({', '.join(arguments)}, projeq_p):"
    source = "\n".join([*imports, "", "", "@numba.njit(cache=True)", signature, *lines, *body, ""])
    return HEADER + source, np.concatenate(p) if p else np.zeros(0)


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
    def load_into(typingctx, address, complex_address, t, q, n_q, s_dot, n_s, p, load):
        # the callback of the arrays' dtype (:func:`load_callbacks`): complex128 under the complex step
        if not q.dtype == s_dot.dtype == load.dtype or p.dtype != numba.types.float64:
            return None

        def call(context, builder, signature, args):
            kinds = signature.args
            chosen = 1 if isinstance(kinds[3].dtype, numba.types.Complex) else 0
            chosen_kinds = numba.types.void(kinds[chosen], *kinds[2:])
            return caller(chosen_kinds, (args[chosen], *args[2:]), context, builder)

        return numba.types.void(address, complex_address, t, q, n_q, s_dot, n_s, p, load), call

    return {"phi_into": phi_into, "given_into": given_into, "wrench_into": wrench_into,
            "load_into": load_into}

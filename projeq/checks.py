"""Input checks used where input enters projeq (constructors and ``simulate``).

Each check raises ``ValueError`` whose message starts with the parameter's name and says
what is wrong, so that bad input never reaches the numeric kernels.
"""

from __future__ import annotations

import difflib
import math

import numpy as np
from numpy.typing import NDArray


_FLOAT, _COMPLEX = np.dtype(float), np.dtype(complex)  # the kernels' dtypes: native float64, complex128


def closest(name: str, known) -> str:
    """`` (did you mean 'x'?)`` for the closest known name, or an empty string."""
    match = difflib.get_close_matches(name, list(known), n=1)
    return f" (did you mean {match[0]!r}?)" if match else ""


def callable_name(function) -> str:
    """How a user's function is named in messages: its qualified name (or its type's)."""
    return getattr(function, "__qualname__", type(function).__name__)


def all_finite(a: NDArray) -> bool:
    """Whether every entry of the float array ``a`` is finite: its sum is finite only then (a NaN or
    an infinity makes it NaN or infinite), found in one pass — Python's sum of a short state vector
    (≤ 32 entries, 13× faster than ``np.all(np.isfinite(a))`` at 7), numpy's reduction of a longer
    one (3×); only a sum that overflows from finite entries takes the entry-wise test."""
    if a.size > 32:
        total = np.add.reduce(a, axis=None)
    else:  # a state vector's own list (no ravel: half the cost of this check at 10 entries)
        total = sum(a.tolist() if a.ndim == 1 else a.ravel().tolist())
    return math.isfinite(total) or bool(np.isfinite(a).all())


def finite_array(name: str, value, shape: tuple | None = None) -> NDArray:
    """``value`` as a float array (a copy) of the given shape with finite entries."""
    # a float64 array, as the integrators hold a state, copied; anything else converted
    a = value.copy() if type(value) is np.ndarray and value.dtype is _FLOAT else _float_array(name, value)
    if shape is not None and a.shape != shape:
        raise ValueError(f"{name}: expected shape {shape}, got {a.shape}")
    if not all_finite(a):
        bad = np.flatnonzero(~np.isfinite(a.ravel()))
        raise ValueError(f"{name}: non-finite entries (NaN or inf) at flat index {bad.tolist()}")
    return a


def _float_array(name: str, value) -> NDArray:
    """``value`` (numbers, a list of them, an array of another dtype) as a new float array; a complex
    one refused by name, not cast (numpy would drop its imaginary part with a mere ComplexWarning)."""
    try:
        a = value if isinstance(value, np.ndarray) else np.array(value)  # its own dtype: complex stays
    except (TypeError, ValueError) as exc:  # a ragged list
        raise ValueError(f"{name}: expected numbers, got {value!r}") from exc
    if a.dtype.kind == "c":
        raise ValueError(f"{name}: expected real numbers, got complex ones ({_first_complex(a)}); a complex "
                         "value is refused, not cast")
    try:
        return np.array(a, dtype=float)
    except (TypeError, ValueError) as exc:  # strings, objects
        raise ValueError(f"{name}: expected numbers, got {value!r}") from exc


def _first_complex(a: NDArray) -> str:
    """The first entry of the complex array ``a`` with an imaginary part, for messages."""
    flat = a.ravel()
    imaginary = np.flatnonzero(flat.imag)
    i = int(imaginary[0]) if imaginary.size else 0
    return f"entry {i} is {complex(flat[i])}" if flat.size else "empty"


def kernel_state(name: str, value, length: int) -> NDArray:
    """``value`` as an evaluator reads it (a state, q or ṡ, passed straight to compiled code):
    a one-dimensional array of ``length`` float or complex entries (complex for the complex step
    of :mod:`projeq.analysis.jacobians`), C-contiguous and writeable (a strided or read-only view,
    such as a row of a frozen Result, is copied: numba would compile the kernels again for its
    layout, 10–30 s cold). Type, dtype and
    shape are checked, not finiteness (an evaluator returns what the state gives): a kernel never
    reads past the array."""
    if not (isinstance(value, np.ndarray) and (value.dtype is _FLOAT or value.dtype is _COMPLEX)):
        value = _numbers(name, value)  # float32, a file's big-endian float64, integers, lists: converted
    if value.shape != (length,):
        raise ValueError(f"{name}: expected {length} entries, got shape {value.shape}")
    flags = value.flags  # numba compiles a kernel again for each layout and mutability: one kind only
    return value if flags.c_contiguous and flags.writeable else np.array(value, order="C")


def _numbers(name: str, value) -> NDArray:
    """``value`` (a list, or an array of integers, ...) as a float or complex array; ValueError naming
    ``name`` for anything else (strings, objects, booleans)."""
    try:
        a = np.asarray(value)
    except ValueError as exc:  # a ragged list
        raise ValueError(f"{name}: expected an array of numbers, got {value!r:.60}") from exc
    if a.dtype.kind not in "iufc":
        raise ValueError(f"{name}: expected an array of numbers, got {type(value).__name__} {value!r:.60}")
    return np.asarray(a, dtype=_COMPLEX if a.dtype.kind == "c" else _FLOAT)


def finite_result(what: str, value, **state):
    """``value`` (a result computed at ``state``, its arguments by name; an array or a tuple of them)
    if every entry is finite; else :func:`not_finite`'s ValueError, raised."""
    if all(all_finite(np.asarray(part)) for part in (value if isinstance(value, tuple) else (value,))):
        return value
    raise not_finite(what, **state)


def not_finite(what: str, **state) -> ValueError:
    """The ValueError for a result ``what`` that is not finite at ``state`` (arguments by name): it names
    the argument with the largest entry, a finite state whose products overflow (|ṡ| = 1e200 squared
    in the velocity terms) or a non-finite one."""
    magnitudes = {name: np.abs(np.asarray(x)).max(initial=0.0) for name, x in state.items()}
    culprit = max(magnitudes, key=lambda name: np.nan_to_num(magnitudes[name], nan=np.inf))
    return ValueError(f"{culprit}: {what} is not finite at this state (largest |{culprit}| = "
                      f"{magnitudes[culprit]:.3g}): an entry overflowed to inf or NaN; the state is outside "
                      "any range a model describes")


def check_rotation(name: str, A, where: str = "", tol: float = 1e-9) -> NDArray:
    """A proper rotation matrix: AᵀA = I to ``tol`` and det A = +1."""
    A = finite_array(name, A, (3, 3))
    error = np.abs(A.T @ A - np.eye(3)).max()
    if error > tol or np.linalg.det(A) < 0.0:
        raise ValueError(f"{name}: is not a rotation matrix {where} (|AᵀA − I| = {error:.3g}, det A = "
                         f"{np.linalg.det(A):.3g}); it must be orthonormal with det A = +1")
    return A


def positive(name: str, value) -> float:
    """A finite, strictly positive float."""
    x = float(finite_array(name, value, ()))
    if x <= 0.0:
        raise ValueError(f"{name}: must be positive, got {x}")
    return x


def positives(**values) -> tuple[float, ...]:
    """Each keyword's value checked by :func:`positive` under the keyword's name, in order:
    ``m, l = positives(m=m, l=l)``."""
    return tuple(positive(name, value) for name, value in values.items())


def non_negative(name: str, value) -> float:
    """A finite float ≥ 0."""
    x = float(finite_array(name, value, ()))
    if x < 0.0:
        raise ValueError(f"{name}: must not be negative, got {x}")
    return x


def flag(name: str, value) -> bool:
    """A switch given as True or False: a string such as "False" (from a settings file) would be
    truthy and silently switch it on."""
    if not isinstance(value, (bool, np.bool_)):
        raise ValueError(f"{name}: expected True or False, got {value!r}")
    return bool(value)


def count(name: str, value, minimum: int = 1) -> int:
    """An integer ≥ ``minimum`` (a number of points, segments, ...)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name}: expected an integer >= {minimum}, got {value!r}")
    return int(value)


def state_vector(name: str, value, length: int) -> NDArray:
    """A state (q or ṡ) of the right length with finite entries."""
    a = finite_array(name, value)
    if a.shape != (length,):
        raise ValueError(f"{name}: expected {length} entries, got shape {a.shape}")
    return a


def inertia_tensor(name: str, I_c, allow_zero: bool = False) -> NDArray:
    """A symmetric 3×3 inertia tensor: positive definite (semi-definite with ``allow_zero``)
    with principal moments that satisfy the triangle inequality A + B ≥ C."""
    I_c = finite_array(name, I_c, (3, 3))
    scale = max(np.abs(I_c).max(), 1e-300)
    if np.abs(I_c - I_c.T).max() > 1e-12 * scale:
        raise ValueError(f"{name}: inertia tensor is not symmetric:\n{I_c}")
    moments = np.linalg.eigvalsh(I_c)
    tol = 1e-12 * scale
    if allow_zero and np.all(np.abs(moments) <= tol):
        return I_c
    if moments[0] <= (-tol if allow_zero else 0.0):
        raise ValueError(
            f"{name}: inertia tensor is not positive definite (principal moments {moments})"
        )
    if moments[0] + moments[1] < moments[2] - tol:
        raise ValueError(
            f"{name}: principal moments {moments} violate the triangle inequality "
            "A + B >= C (no mass distribution has them)"
        )
    return I_c


def drop_inherited_twins(cls, base, numeric: tuple, twins: tuple) -> None:
    """The plug-in contracts' override rule, for ``__init_subclass__``: a subclass ``cls`` that
    restates one of the ``numeric`` members loses the ``twins`` it inherits (symbolic, compiled
    or batched forms of the inherited numbers) unless it restates them too; they fall back to
    ``base``'s defaults, so an evaluator never bypasses an override."""
    if any(member in vars(cls) for member in numeric):
        for twin in twins:
            if twin not in vars(cls):  # the inherited twin states another plug-in's terms
                setattr(cls, twin, vars(base)[twin])


def depends_on_t(f, q0: NDArray) -> bool:
    """Whether the constraint function f(q, t) (Φ, or the Pfaffian rows A) changes with t, at q0
    or at three points around it (q0 moved by 0.1 (1 + |q0|) along seeded random directions): a
    dependence that vanishes at q0 alone, Φ = Φ₀(q) + t (q₁ − q0₁), is seen too. Values compared
    at t = 0.37 and 1.9 against t = 0 to 1e-14 (relative and absolute); a point where f is not
    defined (an exception, or values not finite) is skipped."""
    rng = np.random.default_rng(0)
    q0 = np.asarray(q0, dtype=float)
    for q in [q0] + [q0 + 0.1 * (1.0 + np.abs(q0)) * rng.standard_normal(q0.size) for _ in range(3)]:
        try:
            with np.errstate(all="ignore"):
                values = [np.asarray(f(q, t), dtype=float) for t in (0.0, 0.37, 1.9)]
        except (ArithmeticError, ValueError):
            continue
        if all(np.all(np.isfinite(v)) for v in values) and any(
                not np.allclose(v, values[0], rtol=1e-14, atol=1e-14) for v in values[1:]):
            return True
    return False

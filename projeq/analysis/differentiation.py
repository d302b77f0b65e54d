"""Numerical differentiation: every finite-difference stencil and the complex step projeq uses.

Each rule differentiates a function f of one real variable ε at ε = 0 — a directional
derivative when f(ε) = g(x + ε v) — element-wise for array values. With ε_m ≈ 2.2e-16
and |f| the size of the values, the errors of a step h are (Taylor expansion; e.g.
Fornberg, "Generation of finite difference formulas on arbitrarily spaced grids",
Math. Comp. 51, 1988; Martins, Sturdza & Alonso, "The complex-step derivative
approximation", ACM TOMS 29, 2003):

- :func:`central`, (f(h) − f(−h)) / 2h: truncation h²/6 |f‴|, round-off ε_m |f| / h;
- :func:`richardson`, (−f(2h) + 8 f(h) − 8 f(−h) + f(−2h)) / 12h: truncation h⁴/30 |f⁽⁵⁾|,
  round-off 1.5 ε_m |f| / h;
- :func:`sixth_order`, the seven-point stencil: truncation h⁶/140 |f⁽⁷⁾|, round-off 1.8 ε_m |f| / h;
- :func:`second` (the second derivative), (−f(2h) + 16 f(h) − 30 f(0) + 16 f(−h) − f(−2h)) / 12h²:
  truncation h⁴/90 |f⁽⁶⁾|, round-off 5.3 ε_m |f| / h²;
- :func:`forward`, (f(h) − f(0)) / h: truncation h/2 |f″|, round-off 2 ε_m |f| / h;
- :func:`complex_step`, Im f(ih) / h: truncation h²/6 |f‴|, round-off ε_m |f′|.

The complex step subtracts nothing, so h can be tiny (:data:`COMPLEX_STEP` = 1e-30) and the
derivative is exact to round-off; it needs f to accept complex arguments (numpy ufuncs and
:mod:`projeq.spatial` do). The steps are the callers' choice, stated where they are chosen;
:func:`jacobian` and :func:`gradient` state their own step rules.
"""

from __future__ import annotations

import os
import traceback
import warnings

import numpy as np
from numpy.typing import NDArray

COMPLEX_STEP = 1e-30  # Im f(ih)/h: truncation h²/6 |f‴| ≈ 1e-61, far below round-off
JACOBIAN_STEP = 1e-4  # relative step of the coarser central difference in :func:`jacobian`
GRADIENT_STEP = 1e-6  # relative step of :func:`gradient`


class DifferencesWarning(UserWarning):
    """A derivative that would be exact by the complex step falls back to finite differences
    because a user's callable cannot take complex arguments (issue 16: differences only on
    request, a fall-back says so once, naming the callable)."""


_WARNED: set = set()  # (piece, callable) pairs already warned about: one warning each per process


def warn_differences(piece: str, culprit: str, reason: str, stacklevel: int = 3) -> None:
    """One :class:`DifferencesWarning` per ``piece`` (the parameter or quantity) and ``culprit``
    (the callable): its derivatives come from differences because the callable cannot take
    complex arguments (``reason``)."""
    if (piece, culprit) in _WARNED:
        return
    _WARNED.add((piece, culprit))
    warnings.warn(
        f"{piece}: {culprit} cannot take complex arguments ({reason}); derivatives through it come from "
        "finite differences (~1e-10 relative), not exactly by the complex step: write it with numpy "
        "operations (no float(), math.*, dtype=float) for exact derivatives",
        DifferencesWarning, stacklevel=stacklevel + 1,
    )


def raised_by(exc: BaseException) -> str:
    """The innermost function outside projeq in the traceback of ``exc`` (the user's callable
    that failed on a complex argument), else the innermost one, as "name (file:line)"."""
    frames = list(traceback.walk_tb(exc.__traceback__))
    package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    outside = [frame for frame, _ in frames if not os.path.abspath(frame.f_code.co_filename).startswith(package)]
    frame = (outside or [frame for frame, _ in frames])[-1]
    return f"{frame.f_code.co_qualname} ({os.path.basename(frame.f_code.co_filename)}:{frame.f_code.co_firstlineno})"


def central(f, h: float):
    """df/dε at 0 by the central difference (f(h) − f(−h)) / 2h: truncation O(h²),
    h²/6 |f‴|; round-off ε_m |f| / h (balanced at h ≈ ε_m^(1/3) ≈ 6e-6 relative)."""
    return (f(h) - f(-h)) / (2 * h)


def richardson(f, h: float):
    """df/dε at 0 by the five-point stencil (−f(2h) + 8 f(h) − 8 f(−h) + f(−2h)) / 12h:
    Richardson's extrapolation (4 D(h) − D(2h))/3 of two central differences D. Truncation
    O(h⁴), h⁴/30 |f⁽⁵⁾|; round-off 1.5 ε_m |f| / h (balanced at h ≈ ε_m^(1/5) ≈ 7e-4 relative)."""
    return (-f(2 * h) + 8 * f(h) - 8 * f(-h) + f(-2 * h)) / (12 * h)


def sixth_order(f, h: float):
    """df/dε at 0 by the seven-point stencil (f(3h) − 9 f(2h) + 45 f(h) − 45 f(−h) + 9 f(−2h)
    − f(−3h)) / 60h: truncation O(h⁶), h⁶/140 |f⁽⁷⁾|; round-off 1.8 ε_m |f| / h."""
    return (f(3 * h) - 9 * f(2 * h) + 45 * f(h) - 45 * f(-h) + 9 * f(-2 * h) - f(-3 * h)) / (60 * h)


def second(f, h: float):
    """d²f/dε² at 0 by the five-point stencil (−f(2h) + 16 f(h) − 30 f(0) + 16 f(−h) − f(−2h)) / 12h²:
    truncation O(h⁴), h⁴/90 |f⁽⁶⁾|; round-off 5.3 ε_m |f| / h² (balanced at h ≈ ε_m^(1/6) ≈ 2.5e-3
    relative)."""
    return (-f(2 * h) + 16 * f(h) - 30 * f(0.0) + 16 * f(-h) - f(-2 * h)) / (12 * h * h)


def forward(f, h: float, f0=None):
    """df/dε at 0 by the forward difference (f(h) − f(0)) / h, with ``f0`` = f(0) when it is
    known (one evaluation instead of two): truncation O(h), h/2 |f″|; round-off 2 ε_m |f| / h
    (balanced at h ≈ √ε_m ≈ 1.5e-8 relative)."""
    return (f(h) - (f(0.0) if f0 is None else f0)) / h


def complex_step(f, h: float = COMPLEX_STEP):
    """df/dε at 0 as Im f(ih) / h for an f that is real on the real axis and accepts complex
    arguments: truncation O(h²), h²/6 |f‴|, and no subtractive cancellation, so with the
    default h = 1e-30 it is exact to round-off."""
    return np.imag(f(1j * h)) / h


def jacobian(f, z0: NDArray, step: float = JACOBIAN_STEP) -> NDArray:
    """∂f/∂z at z0, column i by :func:`richardson` along e_i with h = step · max(1, |z0_i|) / 2
    (the coarser central difference spans step · max(1, |z0_i|)): truncation O(h⁴).

    >>> J = jacobian(lambda z: np.array([np.sin(z[0]) * z[1]]), np.array([0.5, 2.0]))
    >>> bool(np.allclose(J, [[2 * np.cos(0.5), np.sin(0.5)]], rtol=1e-11, atol=0))
    True
    """
    z0 = np.asarray(z0, dtype=float)
    n_f = len(f(z0))
    columns = []
    for i in range(len(z0)):
        e = np.zeros_like(z0)
        e[i] = 1.0
        columns.append(richardson(lambda eps, e=e: f(z0 + eps * e), step * max(1.0, abs(z0[i])) / 2))
    return np.array(columns).T.reshape(n_f, len(z0))


def gradient(f, x: NDArray, f0: float | None = None, step: float = GRADIENT_STEP) -> NDArray:
    """∇f(x) of a scalar function, component i with h = step · (1 + |x_i|): by :func:`central`
    (truncation O(h²)), or, given ``f0`` = f(x), by :func:`forward` (O(h), half the evaluations)."""
    out = np.empty_like(x)
    for i in range(len(x)):
        e = np.zeros_like(x)
        e[i] = 1.0
        along = lambda eps, e=e: f(x + eps * e)  # noqa: E731
        h = step * (1.0 + abs(x[i]))
        out[i] = central(along, h) if f0 is None else forward(along, h, f0)
    return out


# -- derivatives that compose with an outer complex step ----------------------------------------
# Jacobians of a model are taken by the complex step (``exact_jacobian``) through evaluators that
# themselves differentiate (a user joint's Ḟ, a constraint's Φ_q and γ). A complex step cannot be
# nested in another (there is one imaginary unit), so these inner derivatives take a point
# x = a + i b whose imaginary part b is an outer complex step's (|b| ~ 1e-30) and return, to
# first order in b, f′(x) v = f′(a) v + i [f″(a)(b, v) + ...]: the real part by the complex step
# (exact), the imaginary part by the complex step along one direction inside the sixth-order
# stencil along the other, g(e) = Im f(a + e û + i h ŵ)/h on unit directions, g′(0) by
# :func:`sixth_order` with step MIXED_STEP: truncation h⁶/140 |g⁽⁷⁾|, round-off 1.8 ε_m |g| / h.
# Measured (largest relative error; the Whipple bicycle's eigenvalues against Meijaard et al.
# (2007) Table 2, sympy's four-bar accelerations against Kane's equations at 40 digits):
# h = 1e-3: 3e-14, 5e-12; 4e-3: 3e-14, 8e-13; 8e-3: 3e-14, 5e-14; 1.5e-2: 9e-13, 3e-13 (truncation).
MIXED_STEP = 8e-3
SECOND_MIXED_STEP = 3e-3  # two real stencils (third derivatives): round-off ≈ ε_m / h², truncation ≈ h⁴


def _unit(v: NDArray) -> tuple[NDArray, float]:
    n = float(np.linalg.norm(v))
    return (v / n if n else v), n


def _mixed(f, a: NDArray, u: NDArray, w: NDArray, step: float = MIXED_STEP) -> NDArray:
    """f″(a)(u, w) for real a, u, w: the complex step along w (exact) inside the sixth-order
    stencil along u with ``step``, both directions normalised, so the error is relative to
    |f″| whatever the sizes of u and w."""
    (u_hat, nu), (w_hat, nw) = _unit(u), _unit(w)
    if not nu or not nw:
        return np.zeros_like(np.real(f(a)))
    return nu * nw * sixth_order(lambda e: complex_step(lambda s: f(a + e * u_hat + s * w_hat)), step)


def _third(f, a: NDArray, b: NDArray, u: NDArray, w: NDArray) -> NDArray:
    """f‴(a)(b, u, w) for real arguments: the complex step along b inside Richardson's stencil
    along u and along w (each direction normalised)."""
    (b_hat, nb), (u_hat, nu), (w_hat, nw) = _unit(b), _unit(u), _unit(w)
    if not nb or not nu or not nw:
        return np.zeros_like(np.real(f(a)))
    h = SECOND_MIXED_STEP
    return nb * nu * nw * richardson(lambda e: richardson(
        lambda g: complex_step(lambda s: f(a + e * u_hat + g * w_hat + s * b_hat)), h), h)


def derivative_along(f, x: NDArray, v: NDArray) -> NDArray:
    """f′(x) v, exact to round-off by the complex step for real x and v; for x = a + i b and
    v = c + i d carrying an outer complex step (see above), f′(a) c + i [f″(a)(b, c) + f′(a) d].

    >>> f = lambda x: np.array([np.sin(x[0]) * x[1]])
    >>> bool(np.isclose(derivative_along(f, np.array([0.5, 2.0]), np.array([1.0, 0.0]))[0], 2 * np.cos(0.5),
    ...                 rtol=1e-15))
    True
    """
    x, v = np.asarray(x), np.asarray(v)
    a, b, c, d = np.real(x), np.imag(x), np.real(v), np.imag(v)
    value = complex_step(lambda s: f(a + s * c))
    if not (b.any() or d.any()):
        return value
    return value + 1j * (_mixed(f, a, b, c) + (complex_step(lambda s: f(a + s * d)) if d.any() else 0.0))


def second_derivative_along(f, x: NDArray, u: NDArray, w: NDArray, step: float = MIXED_STEP) -> NDArray:
    """f″(x)(u, w) to ≈ 1e-14 relative for real arguments (:func:`_mixed`; ``step`` of its
    stencil on unit directions, default MIXED_STEP, smaller for an f whose higher derivatives
    are large); for x, u, w carrying an outer complex step, its first-order imaginary part
    f‴(a)(b, Re u, Re w) + f″(a)(Im u, Re w) + f″(a)(Re u, Im w) by two real stencils around
    the complex step (≈ 1e-10 relative)."""
    x, u, w = np.asarray(x), np.asarray(u), np.asarray(w)
    a, b = np.real(x), np.imag(x)
    value = _mixed(f, a, np.real(u), np.real(w), step)
    if not (b.any() or np.imag(u).any() or np.imag(w).any()):
        return value
    outer = _third(f, a, b, np.real(u), np.real(w)) + _mixed(f, a, np.imag(u), np.real(w)) \
        + _mixed(f, a, np.real(u), np.imag(w))
    return value + 1j * outer


def exact_jacobian(f, z0: NDArray) -> NDArray:
    """∂f/∂z at real z0 by the complex step, column i = Im f(z0 + i h e_i) / h: exact to
    round-off for an f that is complex-safe (evaluated in complex arithmetic; inner derivatives
    by :func:`derivative_along` and :func:`second_derivative_along`). Raises TypeError or
    ``numpy.exceptions.ComplexWarning`` (as an error) where f is not complex-safe.

    >>> J = exact_jacobian(lambda z: np.array([np.sin(z[0]) * z[1]]), np.array([0.5, 2.0]))
    >>> bool(np.allclose(J, [[2 * np.cos(0.5), np.sin(0.5)]], rtol=1e-15, atol=0))
    True
    """
    z0 = np.asarray(z0, dtype=float)
    unit = np.eye(len(z0))
    with warnings.catch_warnings():  # a cast that drops the imaginary part must not pass silently
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        columns = [complex_step(lambda s, e=e: f(z0 + s * e)) for e in unit]
    n_f = np.size(columns[0]) if columns else len(np.atleast_1d(np.real(f(z0))))  # f(z0) only for its size
    return np.array(columns).T.reshape(n_f, len(z0))


def derivative_along_differences(f, x: NDArray, v: NDArray) -> NDArray:
    """f′(x) v by :func:`sixth_order` along v/|v| with :data:`MIXED_STEP`: for an f that
    cannot take complex arguments."""
    x, v = np.asarray(x, dtype=float), np.asarray(v, dtype=float)
    v_hat, n = _unit(v)
    return n * sixth_order(lambda e: f(x + e * v_hat), MIXED_STEP) if n else np.zeros_like(f(x))


def second_derivative_along_differences(f, x: NDArray, u: NDArray, w: NDArray) -> NDArray:
    """f″(x)(u, w) by Richardson's stencil along each of the normalised directions, or
    :func:`second` along u = w (round-off ≈ ε_m |f| / h²): for an f that cannot take
    complex arguments."""
    x = np.asarray(x, dtype=float)
    (u_hat, nu), (w_hat, nw) = _unit(np.asarray(u, dtype=float)), _unit(np.asarray(w, dtype=float))
    if not nu or not nw:
        return np.zeros_like(f(x))
    h = SECOND_MIXED_STEP
    if np.array_equal(u_hat, w_hat):
        return nu * nw * second(lambda e: f(x + e * u_hat), h)
    return nu * nw * richardson(lambda e: richardson(lambda g: f(x + e * u_hat + g * w_hat), h), h)


def attempt_complex(run):
    """(run(), None), or (None, the exception) where ``run`` — a computation at complex
    arguments — raises TypeError or ValueError or casts a complex value to float (numpy's
    ComplexWarning, raised as an error): the signs of a callable that cannot take complex
    arguments, the one test of it that :func:`complex_failure` and the callers that fall back to
    differences share."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        try:
            return run(), None
        except (TypeError, ValueError, np.exceptions.ComplexWarning) as exc:
            return None, exc


def is_complex_safe(f, x: NDArray) -> bool:
    """Whether f, evaluated at x + i 1e-30 (1, …, 1), returns complex values without an
    error or a cast that discards the imaginary part (then the complex step applies)."""
    return complex_failure(f, x) is None


def complex_failure(f, x: NDArray) -> str | None:
    """None if f is complex-safe at x (:func:`is_complex_safe`), else why not (the error and
    the function that raised it, :func:`raised_by`)."""
    value, exc = attempt_complex(lambda: np.asarray(f(np.asarray(x) + 1j * COMPLEX_STEP * np.ones(len(x)))))
    if exc is not None:
        return f"{type(exc).__name__}: {exc}, in {raised_by(exc)}"
    if not np.iscomplexobj(value):
        return "it returns real values for a complex argument"
    if not np.all(np.isfinite(value)):
        return "it returns non-finite values for a complex argument"
    return None

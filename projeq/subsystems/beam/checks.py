"""Checks of RitzBeam input (issue 6, "Bad input"): per-length properties and Ritz
families are refused with a ``ValueError`` that names the parameter, the deformation and
the function, before they reach the quadrature.

A family is a callable ``family(n, L)`` returning ``shapes(x) -> (Φ, Φ′, Φ″[, Φ‴])``
(:mod:`projeq.subsystems.beam.shapes`); a user family is evaluated once at probe stations and
each array must have one row per function and one column per station, finite.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import richardson
from projeq.checks import finite_array

_DERIVATIVES = ("Φ", "Φ′", "Φ″", "Φ‴")


def per_length(name: str, value, x: NDArray) -> NDArray:
    """A per-length property (a number or a function of x; a function may return one
    number) at the stations x: finite and positive at each station.

    >>> per_length("rho_A", lambda x: 2.0 - x, np.array([0.5, 1.0]))
    array([1.5, 1. ])
    """
    if callable(value):
        try:
            values = np.asarray(value(x), dtype=float)
            values = np.full_like(x, values) if values.shape == () else values  # a constant
        except (TypeError, ValueError) as exc:
            raise ValueError(f"{name}: the function of x failed at the stations: {exc}") from exc
    else:
        values = np.full_like(x, float(finite_array(name, value, ())))
    if values.shape != x.shape or not np.all(np.isfinite(values)):
        raise ValueError(f"{name}: must give a finite value at each station x (an array like x)")
    if np.any(values <= 0):
        raise ValueError(f"{name}: must be positive along the beam, got min {values.min():.3g}")
    return values


def family_shapes(family, table: dict, n: int, L: float, key: str):
    """The shapes callable of ``n`` Ritz functions of deformation ``key`` ("u", "v", "w",
    "beta") from a family name in ``table`` or a callable ``(n, L) -> shapes``; None for
    n = 0. A user family's output is checked (see the module docstring)."""
    if n == 0:
        return None
    if not callable(family):
        if not isinstance(family, str) or family not in table:
            known = sorted(table)
            raise ValueError(f"family: unknown Ritz family {family!r}; use one of {known} or a callable")
        return table[family](n, L)
    try:
        shapes = family(n, L)
        probe = np.linspace(0.0, L, 5)
        arrays = shapes(probe)
    except Exception as exc:  # noqa: BLE001 - any failure of user code, reported by name
        message = f"family: the Ritz family for {key} failed as family(n, L)(x): {exc!r}"
        raise ValueError(message) from exc
    _check_arrays(arrays, n, len(probe), key)
    _check_derivatives(shapes, n, L, key)
    return shapes


def _check_derivatives(shapes, n: int, L: float, key: str, tol: float = 1e-5) -> None:
    """Φ′ and Φ″ of a user family must be the derivatives of Φ and Φ′: compared with
    :func:`~projeq.analysis.differentiation.richardson` differences (step 1e-3 L, truncation
    ~1e-12 relative for smooth shapes) at interior stations."""
    x = np.linspace(0.2, 0.9, 4) * L
    h = 1e-3 * L
    for k, (what, derivative) in enumerate(zip(_DERIVATIVES, _DERIVATIVES[1:3])):
        given = np.asarray(shapes(x)[k + 1], dtype=float)
        estimate = richardson(lambda e: np.asarray(shapes(x + e)[k], dtype=float), h)
        error = np.abs(given - estimate).max(axis=1)
        bad = np.flatnonzero(error > tol * (np.abs(estimate).max(axis=1) + np.abs(given).max(axis=1) + 1e-300))
        if bad.size:
            raise ValueError(
                f"family: {derivative} of the Ritz functions {bad.tolist()} for {key} is not the derivative of "
                f"{what} (differs by up to {error[bad].max():.3g} from a finite difference): the shapes' "
                "derivatives must be consistent with their values"
            )


def beam_memory(n_y: int, limit: float = 2.0**30) -> None:
    """Refuse a beam whose (n_y × n_y) matrices would not fit: each takes 8 n_y² bytes, and the
    beam keeps several (mass, stiffness, Gram matrix, integrals)."""
    need = 8.0 * n_y * n_y
    if need > limit:
        raise ValueError(
            f"n_v, n_w, n_u, n_beta: {n_y - 6} Ritz functions make each n_y × n_y matrix of the beam "
            f"{need / 2**30:.3g} GiB (8 n_y² bytes, n_y = {n_y}), and the beam keeps several: more memory than "
            f"sensible (limit {limit / 2**30:.3g} GiB per matrix); a few dozen functions converge (use "
            "family='clamped_free')"
        )


def _check_arrays(arrays, n: int, n_x: int, key: str) -> None:
    """(Φ, Φ′, Φ″[, Φ‴]) of a user family, each (n, n_x) and finite."""
    if not isinstance(arrays, (tuple, list)) or not 3 <= len(arrays) <= 4:
        got = type(arrays).__name__
        raise ValueError(f"family: shapes(x) for {key} must return (Φ, Φ′, Φ″[, Φ‴]), got {got}")
    for what, array in zip(_DERIVATIVES, arrays):
        array = np.asarray(array, dtype=float)
        if array.shape != (n, n_x):
            raise ValueError(
                f"family: {what} for {key} has shape {array.shape}, expected ({n}, {n_x}): "
                f"one row per Ritz function ({n} asked for) and one column per station"
            )
        bad = np.flatnonzero(~np.all(np.isfinite(array), axis=1))
        if bad.size:
            functions = bad.tolist()
            raise ValueError(f"family: {what} of the Ritz functions {functions} for {key} is not finite on the beam")

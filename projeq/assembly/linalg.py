"""Small symmetric positive definite solves with errors that say which matrix failed."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

SINGULAR_PIVOT = 1e-13  # pivots below this fraction of the system's mass scale count as zero


class SingularMassError(ValueError):
    """A mass matrix (system M or a recursive pivot D_n) is singular or indefinite."""


def mass_scale(system) -> float:
    """The largest diagonal entry of the subsystems' M_n at rest in q0: the yardstick for
    calling a pivot zero."""
    diagonals = [
        np.abs(np.diagonal(sub.gauss_terms(np.zeros(sub.n_y), np.eye(3), system.gravity, np.zeros(sub.n_e))[0])).max()
        for sub in system.subsystems
    ]
    return max(diagonals + [1e-300])


def solve_spd(D: NDArray, B: NDArray, what: str, scale: float) -> NDArray:
    """D⁻¹ B for a symmetric positive definite D (k×k, k ≥ 0), by Cholesky.

    A 1×1 D (every one-dof joint in the recursive pass) is a division; 0×0 (fixed and
    prescribed joints) returns B unchanged. Raises :class:`SingularMassError` naming
    ``what`` when a pivot is below ``1e-13 · scale``.
    """
    k = D.shape[0]
    if np.iscomplexobj(D) or np.iscomplexobj(B):  # a complex step: Cholesky would conjugate
        _check_pivots(np.real(D), what, scale)
        return np.linalg.solve(D, B) if k else B
    if k == 1:
        if D[0, 0] > SINGULAR_PIVOT * scale:
            return B / D[0, 0]
        raise SingularMassError(f"{_name(what)} is singular (pivot {D[0, 0]:.3g}): it moves no mass or inertia")
    if k == 0:
        return B
    try:
        L = np.linalg.cholesky(D)
    except np.linalg.LinAlgError as exc:
        raise SingularMassError(f"{_name(what)} is not positive definite: {exc}") from exc
    if np.diagonal(L).min() ** 2 <= SINGULAR_PIVOT * scale:
        raise SingularMassError(f"{_name(what)} is singular (smallest pivot {np.diagonal(L).min() ** 2:.3g})")
    return np.linalg.solve(L.T, np.linalg.solve(L, B))


def _check_pivots(D: NDArray, what: str, scale: float) -> None:
    """The checks of :func:`solve_spd` on a real D."""
    solve_spd(D, np.zeros((D.shape[0], 0)), what, scale)


def _name(what: str) -> str:
    return what if " " in what else f"D_n = F_nᵀ M̂_n F_n of joint {what!r}"

"""Small symmetric positive definite solves with errors that say which matrix failed, and BLAS held to
one thread around the compiled calls of LAPACK."""

from __future__ import annotations

import contextlib
import functools
import warnings

import numpy as np
from numpy.typing import NDArray

SINGULAR_PIVOT = 1e-13  # pivots below this fraction of the mass scale they carry count as zero
ACCURACY = 1e-5  # relative error bound ε κ(M) of a solve above which an evaluator warns


class AccuracyWarning(UserWarning):
    """An evaluator's result is less accurate than the others' (an ill-conditioned solve)."""


class SingularMassError(ValueError):
    """A mass matrix (system M or a recursive pivot D_n) is singular or indefinite."""


@contextlib.contextmanager
def one_blas_thread(needed: bool = True):
    """BLAS held to one thread while the block runs (where ``needed``; threadpoolctl's limit, process-wide,
    restored after): the compiled closures call LAPACK's SVD on matrices of at most a few hundred rows,
    where OpenBLAS's threads only contend — an 80 × 81 SVD 6.4–6.9 ms with them against 0.87–0.91 ms
    without, two processes timing it beside a third busy one on two cores
    (:func:`projeq.constraints.compiled._lapack_svd`). Entering costs about 20 µs."""
    if not needed:
        yield
        return
    with _blas_controller().limit(limits=1, user_api="blas"):
        yield


@functools.cache
def _blas_controller():
    """threadpoolctl's controller of the BLAS libraries loaded (scipy's, which numba's LAPACK calls, and
    numpy's), found once."""
    import scipy.linalg  # noqa: F401 - its BLAS loaded before the controller looks for it
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def mass_scale(system) -> float:
    """The largest diagonal entry of the subsystems' M_n at rest: the yardstick for calling a pivot
    zero where one number serves the whole system (one body, or the mass matrix of coupled joints)."""
    return float(mass_scales(system).max(initial=1e-300))


def mass_scales(system) -> NDArray:
    """For each joint n, the largest diagonal entry of M_k at rest over the bodies k it carries (its
    own subsystem and every descendant): the yardstick for calling its pivot D_n = F_nᵀ M̂_n F_n zero.
    Relative to the mass it moves, not to the system's heaviest body: a bob 1e-16 times lighter than
    the one it hangs from has a pivot of its own scale, exact to round-off, while a pivot that
    cancels to round-off (a massless link between two joints on one axis) is at ε times the
    scale of the bodies it carries, and one of a truly massless leaf is 0 (floor 1e-300)."""
    own = [
        np.abs(np.diagonal(sub.gauss_terms(np.zeros(sub.n_y), np.eye(3), system.gravity, np.zeros(sub.n_e))[0])).max()
        for sub in system.subsystems
    ]
    scales = np.maximum(np.array(own, dtype=float).reshape(len(own)), 1e-300)
    for n in range(len(scales) - 1, -1, -1):  # leaves → root (parent[n] < n)
        if system.parent[n] >= 0:
            scales[system.parent[n]] = max(scales[system.parent[n]], scales[n])
    return scales


def column_scales(system) -> NDArray:
    """For each minimal velocity, the largest :func:`mass_scales` entry of the joints that move with it
    (one joint's, or those of the coupled joints sharing it): the pivots of M's Cholesky factor, in
    the order of the velocities, compared with these."""
    joint_scales, scales = mass_scales(system), np.full(system.n_s, 1e-300)
    for n in range(len(system.joints)):
        columns = system.joint_s_columns(n)[0]
        scales[columns] = np.maximum(scales[columns], joint_scales[n])
    return scales


def solve_spd(D: NDArray, B: NDArray, what: str, scale: float) -> NDArray:
    """D⁻¹ B for a symmetric positive definite D (k×k, k ≥ 0), by Cholesky.

    A 1×1 D (every one-dof joint in the recursive pass) is a division; 0×0 (fixed and
    prescribed joints) returns B unchanged. Raises :class:`SingularMassError` naming
    ``what`` when a pivot is below ``1e-13 · scale``, ``scale`` one number or one per pivot
    (:func:`column_scales`).
    """
    k = D.shape[0]
    if not np.all(np.isfinite(D)):
        raise FloatingPointError(f"{_name(what)} is not finite ({D.ravel()[:4]}...): the state or the model's data "
                                 "is NaN or overflowed, which no mass matrix explains")
    if np.iscomplexobj(D) or np.iscomplexobj(B):  # a complex step: Cholesky would conjugate
        _check_pivots(np.real(D), what, scale)
        return np.linalg.solve(D, B) if k else B
    if k == 1:
        scale = np.max(scale)
        if D[0, 0] > SINGULAR_PIVOT * scale:
            return B / D[0, 0]
        raise SingularMassError(_negative(D, what) if D[0, 0] < -SINGULAR_PIVOT * scale else
                                f"{_name(what)} is singular (pivot {D[0, 0]:.3g}): it moves no mass or inertia")
    if k == 0:
        return B
    try:
        L = np.linalg.cholesky(D)
    except np.linalg.LinAlgError as exc:
        raise SingularMassError(_massless(D, what)) from exc
    if np.any(np.diagonal(L) ** 2 <= SINGULAR_PIVOT * scale):
        raise SingularMassError(_massless(D, what))
    return np.linalg.solve(L.T, np.linalg.solve(L, B))


def _check_pivots(D: NDArray, what: str, scale: float) -> None:
    """The checks of :func:`solve_spd` on a real D."""
    solve_spd(D, np.zeros((D.shape[0], 0)), what, scale)


def warn_if_ill_conditioned(M: NDArray, what: str) -> None:
    """Warn (:class:`AccuracyWarning`) when solving with ``M`` may lose more than
    :data:`ACCURACY` relative accuracy: the bound ε κ(M) of a backward-stable solve (Golub &
    Van Loan, *Matrix Computations*, 4th ed., 2013, §3.5). The Gauss form of a long chain has
    κ(M) growing like n⁴ (chain(500): 2.4e11), the recursive pass factors 6×6 blocks only."""
    if not M.size:  # no minimal velocities: nothing to solve
        return
    bound = np.finfo(float).eps * np.linalg.cond(M)
    if bound > ACCURACY:
        warnings.warn(f"{what} ({M.shape[0]}×{M.shape[0]}) has condition number {bound / np.finfo(float).eps:.3g}: "
                      f"its accelerations may be off by up to {bound:.2g} relative; use evaluator='recursive' "
                      "or 'fast' (order n, accurate to round-off at any size)", AccuracyWarning, stacklevel=4)


def _massless(D: NDArray, what: str) -> str:
    """The message for a singular or indefinite D: its smallest eigenvalue and the direction
    of the minimal velocities that moves (almost) no mass or inertia."""
    eigenvalues, vectors = np.linalg.eigh(D)
    if eigenvalues[0] < -SINGULAR_PIVOT * max(abs(eigenvalues[-1]), 1e-300):
        return _negative(D, what)
    return (f"{_name(what)} is singular or indefinite (smallest eigenvalue {eigenvalues[0]:.3g} of "
            f"{eigenvalues[-1]:.3g}): the motion along its minimal velocities {np.round(vectors[:, 0], 3).tolist()} "
            "moves no mass or inertia (a joint axis along which the body has none, such as a rotation "
            "about a beam's own axis without rotary inertia rho_I)")


def _negative(D: NDArray, what: str) -> str:
    """The message for a D with a clearly negative eigenvalue: no mass distribution gives one,
    so the state (or the data) has left the model's range."""
    return (f"{_name(what)} is indefinite (smallest eigenvalue {np.linalg.eigvalsh(D)[0]:.3g}), which no mass "
            "distribution gives: the state has left the range the model describes (for example a beam deflected "
            "far beyond its moderate-deflection theory after the integrator lost stability: tighten rtol or "
            "use an implicit method) or the inertia data are inconsistent")


def _name(what: str) -> str:
    return what if " " in what else f"D_n = F_nᵀ M̂_n F_n of joint {what!r}"

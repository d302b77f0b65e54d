"""The linear algebra of a constraint matrix A_s (docs/theory.md §7): its numerical rank, the
minimum-norm solution A_s⁺ c (complex-safe, for the complex step), and the choice of the
velocities it leaves free by column-pivoted QR. Shared by both forms of a
:class:`~projeq.constraints.partitioned.ConstrainedSystem` (partitioned and null space)."""

from __future__ import annotations

import numpy as np
import scipy.linalg
from numpy.typing import NDArray

# singular values of A_s below this fraction of the largest count as zero (rank, mobility): the
# differences' errors (~1e-10 relative) lie below, a constraint that still acts far above
RANK_TOLERANCE = 1e-7
# re-pivot when κ exceeds this (or 10 × its value where the partition was chosen): up to
# there ‖F‖ ≤ κ amplifies the constraint terms' round-off at most ~κ-fold, and the integrator
# has not met the ∞ · 0 of ṡ_tree = F ṡ at the degeneracy
REPIVOT_CONDITION = 1e2


def independent_indices(independent, count: int, n_tree: int, why: str) -> NDArray:
    """``independent`` as sorted indices of ṡ_tree: ``count`` distinct integers in 0..n_tree − 1
    (ValueError naming the parameter and ``why`` that many otherwise)."""
    chosen = np.asarray(independent)
    if chosen.ndim != 1 or not np.issubdtype(chosen.dtype, np.integer) or len(chosen) != count \
            or len(set(chosen.tolist())) != count or np.any((chosen < 0) | (chosen >= n_tree)):
        raise ValueError(f"independent: expected {count} distinct indices of ṡ_tree in 0..{n_tree - 1} "
                         f"({why}), got {independent!r}")
    return np.sort(chosen)


def minimum_norm_solution(A: NDArray, c: NDArray, rcond: float = RANK_TOLERANCE, rank: int | None = None) -> NDArray:
    """A⁺ c, the minimum-norm least-squares solution, with A⁺ over the singular values of A above
    ``rcond`` σ_max (at most ``rank`` of them). Complex-safe: for A = A₀ + i A₁, c carrying a
    complex step (|A₁| ~ 1e-30) it is (A₀⁺ + i dA⁺) c with the derivative of a pseudo-inverse
    of constant rank (Golub & Pereyra, "The differentiation of pseudo-inverses and nonlinear
    least squares problems whose variables separate", SIAM J. Numer. Anal. 10, 1973, Theorem 4.3)

        dA⁺ = −A⁺ dA A⁺ + A⁺A⁺ᵀ dAᵀ (E − A A⁺) + (E − A⁺A) dAᵀ A⁺ᵀA⁺,

    transposes, not conjugates (``np.linalg.lstsq`` conjugates: the complex step through it
    would be silently wrong), so that the complex step gives the exact derivative."""
    A0 = np.real(A)
    if not A0.size:
        return np.zeros(A0.shape[1:] + np.shape(c)[1:], dtype=np.result_type(A, c))
    P = _pseudo_inverse(A0, rcond, rank)
    if not (np.iscomplexobj(A) or np.iscomplexobj(c)):
        return P @ c
    dA = A - A0
    dP = -P @ dA @ P + P @ P.T @ dA.T @ (np.eye(len(A0)) - A0 @ P) + (np.eye(A0.shape[1]) - P @ A0) @ dA.T @ P.T @ P
    return (P + dP) @ c


_LATEST_PSEUDO_INVERSE = (None, None)  # (key, A₀⁺) of the latest _pseudo_inverse: f and f̄ of one state share A_s



def _pseudo_inverse(A0: NDArray, rcond: float, rank: int | None) -> NDArray:
    """A₀⁺ over the singular values of the real A₀ above ``rcond`` σ_max (at most ``rank`` of
    them), kept for the latest (A₀, rcond, rank)."""
    global _LATEST_PSEUDO_INVERSE
    key = (A0.shape, A0.tobytes(), rcond, rank)
    latest = _LATEST_PSEUDO_INVERSE  # one read: another thread may replace it
    if latest[0] == key:
        return latest[1]
    U, sigma, Vt = np.linalg.svd(A0, full_matrices=False)
    k = min(int(np.count_nonzero(sigma > rcond * sigma[0])), len(sigma) if rank is None else rank)
    P = Vt[:k].T @ (U[:, :k].T / sigma[:k, None])
    _LATEST_PSEUDO_INVERSE = (key, P)
    return P


def numerical_rank(A: NDArray) -> int:
    """The number of singular values of A above RANK_TOLERANCE times the largest (0 for no rows)."""
    if not A.size:
        return 0
    sigma = np.linalg.svd(A, compute_uv=False)
    return int(np.count_nonzero(sigma > RANK_TOLERANCE * sigma[0]))


def pivoted_columns(A: NDArray, k: int) -> NDArray:
    """The k columns of A that column-pivoted QR takes first, sorted: those with the
    best-conditioned block (a ConstrainedSystem's dependent velocities, columns of A_s; a
    TangentSystem's independent ones, columns of Nᵀ). In numpy's index type: LAPACK's pivots are
    int32, which cost a conversion at every indexing and a second compilation of the closure kernel."""
    return np.sort(scipy.linalg.qr(A, pivoting=True)[2][:k]).astype(np.intp)

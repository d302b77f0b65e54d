"""The derivatives of loop closures Φ(q, t) from one call at a batch of points (docs/theory.md §7).

:class:`~projeq.constraints.partitioned.ConstrainedSystem` needs, at every evaluation, the
Jacobian Φ_x = [∂Φ/∂q, ∂Φ/∂t] and the second derivative Φ″(v, v) along the motion x = (q, t),
v = (q̇, 1) (γ of A_s s̈_tree = −γ). Both are exact to round-off by the complex step
(Martins, Sturdza & Alonso, "The complex-step derivative approximation", ACM TOMS 29, 2003):

    Φ_x e_j = Im Φ(x + i h e_j) / h,
    Φ″(u, w) = |u| |w| Σ_k c_k Im Φ(x + ε_k û + i h ŵ) / h,

the second the complex step along ŵ inside the sixth-order central stencil (nodes ε_k, weights
c_k) along û, on unit directions (:data:`projeq.analysis.differentiation.MIXED_STEP`: ≈ 1e-14
relative at any speed). These are the stencils of :mod:`projeq.analysis.differentiation`; the
nodes and weights are read off :func:`~projeq.analysis.differentiation.sixth_order` itself, so the
two cannot differ. What differs is the evaluation: the n_q + 1 points of Φ_x go to Φ in one call,
and the 18 of Φ″(v_q, v_q) + 2 Φ″(v_q, v_t) + Φ″(v_t, v_t) in another, as the columns of
q (n_q × B) and t (B,) — a user's Φ written with numpy operations on q[i] (the scenes' closures
are) evaluates them column by column in one pass of its Python code instead of 25.

Whether Φ takes such a batch is checked once (:func:`takes_batches`: the batch's values equal the
point-by-point ones at complex points near q0); where it does not, the point-by-point evaluation of
:mod:`projeq.analysis.differentiation` is used, after one :class:`PointwiseWarning` naming Φ.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.typing import NDArray

from projeq.analysis.differentiation import COMPLEX_STEP, MIXED_STEP, sixth_order


class PointwiseWarning(UserWarning):
    """A constraint function does not take a batch of points: its derivatives call it once per
    stencil point (about 25 calls per s̈ instead of 2)."""


def _stencil(rule, h: float) -> tuple[NDArray, NDArray]:
    """(nodes ε_k, weights c_k) of a linear stencil ``rule(f, h)`` = Σ_k c_k f(ε_k): the nodes
    where it evaluates f, the weight of each its value for f = 1 at that node and 0 elsewhere."""
    nodes: list = []
    rule(lambda e: nodes.append(e) or 0.0, h)
    weights = [rule(lambda e, node=node: float(e == node), h) for node in nodes]
    return np.array(nodes), np.array(weights)


NODES, WEIGHTS = _stencil(sixth_order, MIXED_STEP)


def takes_batches(f, n: int, x0: NDArray, m: int) -> bool:
    """Whether ``f(q, t)`` (n coordinates, m values) evaluates the columns of q (n × B), t (B,)
    as B points: at three complex points about x0 = (q0, t0) its (m × B) values equal, real and
    imaginary parts each to 1e-13 relative, those of one call per point."""
    rng = np.random.default_rng(7)
    X = x0[:, None] + 1e-2 * rng.standard_normal((n + 1, 3)) + 1j * COMPLEX_STEP * rng.standard_normal((n + 1, 3))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            batch = np.asarray(f(X[:-1], X[-1]), dtype=complex)
            points = np.array([np.asarray(f(x[:-1], x[-1]), dtype=complex) for x in X.T]).T
        except Exception:  # noqa: BLE001 — any failure on a batch means: one point at a time
            return False
    if batch.shape != (m, 3) or points.shape != (m, 3):
        return False
    scale = max(1.0, np.abs(points.real).max(initial=0.0))
    rate = max(1.0, np.abs(points.imag / COMPLEX_STEP).max(initial=0.0))
    return bool(np.all(np.abs(batch.real - points.real) <= 1e-13 * scale)
                and np.all(np.abs(batch.imag - points.imag) / COMPLEX_STEP <= 1e-13 * rate))


class BatchedClosure:
    """Φ_x and Φ″(v, v) of ``phi(q, t)`` (n coordinates) by the complex step on batches of points
    (module docstring); real arguments only."""

    complex_safe = False  # real arguments only

    def __init__(self, phi, n: int, m: int):
        self.phi, self.n, self.m = phi, n, m
        self._unit = np.eye(n + 1)

    def _im(self, X: NDArray) -> NDArray:
        """Im Φ / h at the columns of X ((n + 1) × B complex)."""
        return np.imag(np.asarray(self.phi(X[:-1], X[-1]))) / COMPLEX_STEP

    def jacobian(self, x: NDArray, columns: int) -> NDArray:
        """The first ``columns`` columns of Φ_x = [∂Φ/∂q, ∂Φ/∂t] at x = (q, t): one call at the
        points x + i h e_j."""
        return self._im(x[:, None] + 1j * COMPLEX_STEP * self._unit[:, :columns])

    def second(self, x: NDArray, q_dot: NDArray, rheonomic: bool) -> NDArray:
        """Φ″(v, v) = Φ″(v_q, v_q) + 2 Φ″(v_q, v_t) + Φ″(v_t, v_t), v_q = (q̇, 0), v_t = (0, 1)
        (the rheonomic parts only if ``rheonomic``): each part keeps its own relative accuracy
        (the first ∝ |q̇|², the rheonomic ones not; along t the stencil steps 1/σ as far,
        :func:`time_rate`); one call at the 6 stencil points of each part."""
        rate = time_rate(self.jacobian(x, len(x))) if rheonomic else 1.0
        v_q, v_t = np.append(q_dot, 0.0), self._unit[-1] / rate
        speed = float(np.linalg.norm(v_q))
        pairs = ([(v_t, v_t, rate * rate)] if rheonomic else []) + (
            [(v_q / speed, v_q / speed, speed * speed)] + ([(v_q / speed, v_t, 2 * speed * rate)] if rheonomic else [])
            if speed else [])
        if not pairs:
            return np.zeros(self.m)
        X = np.concatenate([x[:, None] + np.outer(u, NODES) + 1j * COMPLEX_STEP * w[:, None] for u, w, _ in pairs],
                           axis=1)
        im = self._im(X).reshape(-1, len(pairs), len(NODES))
        return im @ WEIGHTS @ np.array([factor for *_, factor in pairs])


def time_rate(Phi_x: NDArray) -> float:
    """σ = max(1, ‖∂Φ/∂t‖ / max_j ‖∂Φ/∂q_j‖) of Φ_x = [Φ_q, ∂Φ/∂t]: how many unit steps of a
    coordinate change Φ as much as a unit of time (about a driven crank's rate, in rad/s). The
    stencils of Φ″'s rheonomic parts step 1/σ as far along t, so that they see the variation of Φ a
    unit step of q shows: their truncation error grows as σ⁶ h⁶ otherwise (a four-bar driven at
    2–4 rad/s: 1.4e-10 relative in s̈, 1.4e-12 with the scaled step; tests/constraints/test_driven.py)."""
    column = np.linalg.norm(Phi_x[:, :-1], axis=0).max(initial=0.0)  # the fastest coordinate's
    return max(1.0, float(np.linalg.norm(Phi_x[:, -1]) / max(column, np.finfo(float).tiny)))


def batched_closure(phi, n: int, x0: NDArray, m: int) -> BatchedClosure | None:
    """A :class:`BatchedClosure` of ``phi`` if it takes batches (:func:`takes_batches`), else
    None after one :class:`PointwiseWarning` naming it."""
    if takes_batches(phi, n, x0, m):
        return BatchedClosure(phi, n, m)
    warnings.warn(
        f"phi: {getattr(phi, '__qualname__', repr(phi))} does not evaluate a batch of points (q of shape "
        "(n_q, B), t of shape (B,), values (m, B)); its derivatives take one call per stencil point "
        "(~25 per s̈): write it with numpy operations on the rows q[i] for the batched path",
        PointwiseWarning, stacklevel=4,
    )
    return None

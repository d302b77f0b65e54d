"""Linearisation of the equations of motion about a state: ẋ ≈ A δx + B δu.

The state is x = (q, ṡ) with ẋ = (K(q) ṡ + k, s̈(q, ṡ, t)). A and B are central-difference
Jacobians (relative step 1e-6, so their entries carry about ten correct digits). This is
the first version: perturbations of all of q and ṡ (for non-holonomic systems the ṡ are
already minimal, so the linearisation is in minimal velocities by construction).

Caution: with body-fixed quasi-velocities a steady motion is often not an equilibrium of
(q, ṡ) (the speeds rotate with the configuration, as Barhorst's u1, u3 of the rolling disk
do with its roll angle); linearise in speeds for which the steady motion is one (the
knife-edge disc's Euler rates), or the eigenvalues mislead.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

_STEP = 1e-6


def state_derivative(system, x: NDArray, t: float, tau: NDArray | None = None, inputs=()) -> NDArray:
    """ẋ = (q̇, s̈) at x = (q, ṡ); ``tau`` are generalized forces on the joints ``inputs``."""
    q, s_dot = x[: system.n_q], x[system.n_q :]
    ev = system.evaluator()
    if tau is None or not len(inputs):
        s_ddot = ev.accelerations(q, s_dot, t)
    else:
        M, b = system.gauss_form(q, s_dot, t)
        Q = np.zeros(system.n_s)
        for name, tau_n in zip(inputs, np.split(tau, np.cumsum([system.joint(j).n_s for j in inputs])[:-1])):
            Q[system.s_slice[system.index(name)]] += tau_n
        s_ddot = np.linalg.solve(M, Q - b)
    return np.concatenate((system.q_dot(q, s_dot, t), s_ddot))


def linearize(system, q=None, s_dot=None, t: float = 0.0, inputs=None) -> tuple[NDArray, NDArray]:
    """(A, B) with δẋ = A δx + B δτ about (q, ṡ, t).

    Parameters
    ----------
    system : System
    q, s_dot : arrays, optional
        The state to linearise about (default: the system's q0, ṡ0).
    t : float
        Time (for rheonomic systems, e.g. a prescribed steady spin).
    inputs : sequence of joint names, optional
        Joints whose generalized forces τ are the inputs (columns of B).
    """
    q = system.q0 if q is None else q
    s_dot = system.s_dot0 if s_dot is None else s_dot
    q, s_dot = system.check_state(q, s_dot)
    inputs = tuple(inputs or ())
    x0 = np.concatenate((q, s_dot))
    n_u = sum(system.joint(name).n_s for name in inputs)

    def jacobian(f, z0):
        columns = []
        for i in range(len(z0)):
            h = _STEP * max(1.0, abs(z0[i]))
            dz = np.zeros_like(z0)
            dz[i] = h
            columns.append((f(z0 + dz) - f(z0 - dz)) / (2 * h))
        return np.array(columns).T.reshape(len(x0), len(z0))

    A = jacobian(lambda x: state_derivative(system, x, t), x0)
    B = jacobian(lambda u: state_derivative(system, x0, t, u, inputs), np.zeros(n_u))
    return A, B

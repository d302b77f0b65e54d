"""Helpers shared by the classical validation cases: linearisation about an equilibrium
and errors in units of the integrator's request.

The stiffness matrix of a conservative system is K = ∂b/∂q at (q_eq, ṡ = 0), where
M(q) s̈ + b(q, ṡ) = 0 is projeq's Gauss form; with q̇ = ṡ (revolute and prismatic joints)
the small oscillations obey M s̈ + K s = 0 and ω² are the eigenvalues of K x = ω² M x.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import eigh

# Central differences with a step h have a truncation error O(h²·|b'''|) and a round-off
# error O(eps·|b|/h). For the gravity and spring systems of these tests (|b| ≲ 100 in SI
# units, derivatives of order 1 per unit length or angle) h = 1e-5 balances both at
# about 1e-10 relative.
FD_STEP = 1e-5


def stiffness(system, q_eq, h: float = FD_STEP) -> np.ndarray:
    """K_ij = ∂b_i/∂q_j at (q_eq, ṡ = 0) by central differences (joints with q̇ = ṡ)."""
    q_eq = np.asarray(q_eq, dtype=float)
    zero = np.zeros(system.n_s)
    K = np.empty((system.n_s, system.n_q))
    for j in range(system.n_q):
        dq = np.zeros(system.n_q)
        dq[j] = h
        K[:, j] = (system.gauss_form(q_eq + dq, zero)[1] - system.gauss_form(q_eq - dq, zero)[1]) / (2 * h)
    return K


def normal_modes(system, q_eq, h: float = FD_STEP):
    """(ω², modes as columns, M, K) of the linearisation about the equilibrium q_eq."""
    M = system.mass_matrix(q_eq)
    K = stiffness(system, q_eq, h)
    omega2, modes = eigh(0.5 * (K + K.T), M)
    return omega2, modes, M, K


def in_request_units(value, ref, rtol: float, atol: float) -> np.ndarray:
    """|value − ref| / (atol + rtol·|ref|): an integration error measured in units of what
    was asked of the integrator (scipy's ``compute_error`` habit, STYLE §4.8 item 8)."""
    value, ref = np.asarray(value, dtype=float), np.asarray(ref, dtype=float)
    return np.abs(value - ref) / (atol + rtol * np.abs(ref))

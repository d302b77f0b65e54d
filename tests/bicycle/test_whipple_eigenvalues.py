"""Eigenvalues of the Whipple bicycle's upright straight running (issue 4, item 5):
projeq (Projection Equation of a tree + constraint equations by coordinate partitioning,
``projeq.scenes.whipple_eigenvalues``) against an independent derivation with
sympy.physics.mechanics.KanesMethod (``tests/bicycle/kane_whipple.py``: vectors and the
two-point formula for the kinematics, Kane's partial velocities for the dynamics, Kane's
nonholonomic generalized forces for the front no-slip constraint).

Tolerance. The KanesMethod model is lambdified exactly; its Jacobian by extrapolated
central differences is accurate to ~1e-10. projeq's Jacobians are exact (complex step,
issue 16; its eigenvalues match Meijaard et al.'s Table 2 to 3e-14 in
``test_whipple_table2.py``); the bound |Δλ| ≤ 1e-6 max(1, |λ|) dates from projeq's
finite-difference Jacobians (~1e-7) and is kept.
"""

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from projeq.scenes.bicycle import BENCHMARK, whipple_eigenvalues
from tests.bicycle import kane_whipple

TOL = 1e-6  # see the module docstring


@pytest.fixture(scope="module")
def kane():
    """The KanesMethod derivation with MJPR's benchmark parameters, once per module."""
    return kane_whipple.derive(BENCHMARK)


def _matched_error(a: np.ndarray, b: np.ndarray) -> float:
    """Largest |a_i − b_j|/max(1, |b_j|) over the pairing that minimises the total distance."""
    rows, cols = linear_sum_assignment(np.abs(a[:, None] - b[None, :]))
    return float(np.max(np.abs(a[rows] - b[cols]) / np.maximum(1.0, np.abs(b[cols]))))


@pytest.mark.parametrize("speed", [0.0, 2.0, 5.0, 8.0], ids=lambda v: f"{v:g}m/s")
def test_eigenvalues_agree_with_kanes_method(kane, speed):
    """Four eigenvalues at speeds in each regime: 0 (two real pairs ±), 2 (unstable weave
    pair), 5 (self-stable), 8 (capsize unstable)."""
    projeq_lam = whipple_eigenvalues(speed)
    kane_lam = kane_whipple.eigenvalues(kane, speed, BENCHMARK["r_R"])
    assert projeq_lam.shape == (4,)
    assert _matched_error(projeq_lam, kane_lam) < TOL, (projeq_lam, kane_lam)


def test_weave_and_capsize_speeds_agree_with_kanes_method(kane):
    """At the weave and capsize speeds of the KanesMethod model (roots of the real parts,
    found by Brent's method to 1e-10 m/s), projeq's weave pair and capsize eigenvalue have
    zero real part to the eigenvalue tolerance. Since dRe λ/dv ≈ −1 (weave) and ≈ +0.1
    s⁻¹ per m/s (capsize), this pins projeq's speeds to the Kane ones within ~1e-5 m/s.
    For orientation only (not asserted): MJPR (2007) report 4.29 and 6.02 m/s."""
    v_weave, v_capsize = kane_whipple.stability_limits(
        lambda v: kane_whipple.eigenvalues(kane, v, BENCHMARK["r_R"]))
    weave = whipple_eigenvalues(v_weave)
    oscillatory = weave[np.abs(weave.imag) > 1e-6]
    assert len(oscillatory) == 2 and np.abs(oscillatory.real).max() < TOL * np.abs(oscillatory).max()
    capsize = whipple_eigenvalues(v_capsize)
    real = capsize[np.abs(capsize.imag) <= 1e-6]
    assert np.abs(real).min() < TOL
    assert 4.0 < v_weave < 4.5 and 5.8 < v_capsize < 6.2  # the expected regime (the orientation above)


def test_speed_must_be_a_number():
    with pytest.raises(ValueError, match="speed"):
        whipple_eigenvalues("fast")

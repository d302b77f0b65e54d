"""Eigenvalues of the Whipple bicycle's upright straight running (issue 4, item 5):
projeq (Projection Equation of a tree + constraint equations by coordinate partitioning,
``projeq.scenes.whipple_eigenvalues``) against an independent derivation with
sympy.physics.mechanics.KanesMethod (``tests/bicycle/kane_whipple.py``: vectors and the
two-point formula for the kinematics, Kane's partial velocities for the dynamics, Kane's
nonholonomic generalized forces for the front no-slip constraint).

Tolerance. The KanesMethod model is lambdified exactly; its Jacobian by extrapolated
central differences is accurate to ~1e-10. projeq's Jacobians are exact (complex step,
issue 16; its eigenvalues match Meijaard et al.'s Table 2 to 3e-14 in
``test_whipple_table2.py``). Measured |Δλ|/max(1, |λ|) ≤ 1.4e-14 at the four speeds (and
1.0e-14 and 6.4e-15 at the weave and capsize speeds): the bound is 1.4e-13 (was 1e-6, from projeq's
finite-difference Jacobians of ~1e-7).
"""

import numpy as np
import pytest
from scipy.optimize import linear_sum_assignment

from projeq.scenes.bicycle import BENCHMARK, whipple_eigenvalues
from tests.bicycle import kane_whipple

TOL = 1.4e-13  # 10 × the largest measured |Δλ|/max(1, |λ|) (module docstring)


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
    found by Brent's method to 1e-10 m/s), projeq's eigenvalues are Kane's to TOL, so its weave
    pair and capsize eigenvalue have zero real part up to where Brent stopped: Kane's own |Re λ|
    there (measured 1.2e-12 and 6.3e-13 s⁻¹; projeq's differ by 3e-14 and 6e-15) plus TOL. Since
    dRe λ/dv ≈ −1.3 (weave) and ≈ +0.1 s⁻¹ per m/s (capsize), this pins projeq's speeds to the
    Kane ones within ~1e-11 m/s. For orientation only (not asserted): MJPR (2007) report 4.29 and
    6.02 m/s."""
    v_weave, v_capsize = kane_whipple.stability_limits(
        lambda v: kane_whipple.eigenvalues(kane, v, BENCHMARK["r_R"]))
    weave, kane_weave = whipple_eigenvalues(v_weave), kane_whipple.eigenvalues(kane, v_weave, BENCHMARK["r_R"])
    assert _matched_error(weave, kane_weave) < TOL
    oscillatory = weave[np.abs(weave.imag) > 1e-6]
    brent = np.abs(kane_weave[np.abs(kane_weave.imag) > 1e-6].real).max()
    assert len(oscillatory) == 2 and np.abs(oscillatory.real).max() < brent + TOL * np.abs(oscillatory).max()
    capsize, kane_capsize = (whipple_eigenvalues(v_capsize),
                             kane_whipple.eigenvalues(kane, v_capsize, BENCHMARK["r_R"]))
    assert _matched_error(capsize, kane_capsize) < TOL
    real = capsize[np.abs(capsize.imag) <= 1e-6]
    brent = np.abs(kane_capsize[np.abs(kane_capsize.imag) <= 1e-6].real).min()
    assert np.abs(real).min() < brent + TOL
    assert 4.0 < v_weave < 4.5 and 5.8 < v_capsize < 6.2  # the expected regime (the orientation above)


def test_speed_must_be_a_number():
    with pytest.raises(ValueError, match="speed"):
        whipple_eigenvalues("fast")

"""Radau IIA of order 5 in the compiled integration loop (projeq/simulation/loop.py, ``radau_segment``):
scipy 1.17's algorithm step by step, with ∂ẋ/∂x by forward differences of the compiled ẋ where scipy's
Radau in projeq takes the exact one (complex step): the step sequences differ slightly, so the loop is
checked against closed forms and converged runs, and its counts against scipy's Radau on the same
problem. Each bound is 10× the error measured, stated beside it.
"""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg

import projeq as pq
from projeq.simulation import loop


@pytest.fixture
def calls(monkeypatch):
    """The number of compiled Radau segments run, counted."""
    counted = {"segments": 0}
    run = loop.CompiledLoop.run

    def counting(self, *args):
        counted["segments"] += self.implicit
        return run(self, *args)

    monkeypatch.setattr(loop.CompiledLoop, "run", counting)
    return counted


K_SLOW, K_FAST = 1.0, 1e6  # N/m: the two springs of the stiff two-mass oscillator


def two_masses() -> pq.System:
    """Two unit masses on a line: the first on a spring K_SLOW to the ground (its prismatic joint's q₁), the
    second on a spring K_FAST to the first (q₂ relative to it), at rest in the slow mode's shape (the fast
    mode, ω ≈ 1.4e3 1/s, unexcited: a stiff problem)."""
    x = (1.0, 0.0, 0.0)
    q0 = _modes()[1][:, 0] * 0.1 / _modes()[1][0, 0]
    return pq.System({"first": pq.PointMass(1.0), "second": pq.PointMass(1.0)},
                     {"first": pq.Prismatic(axis=x), "second": pq.Prismatic(parent="first", axis=x)},
                     forces=[pq.JointSpring("first", K_SLOW), pq.JointSpring("second", K_FAST)], q0=q0)


def _modes():
    """(ω², Φ) of M q̈ + K q = 0 in the joint coordinates: T = ½ (q̇₁² + (q̇₁ + q̇₂)²) gives M = [[2, 1], [1, 1]],
    V = ½ (K_SLOW q₁² + K_FAST q₂²) gives K = diag(K_SLOW, K_FAST)."""
    return scipy.linalg.eigh(np.diag([K_SLOW, K_FAST]), np.array([[2.0, 1.0], [1.0, 1.0]]))


def closed_form(t: np.ndarray, q0: np.ndarray) -> np.ndarray:
    """q(t) of the undamped linear system from rest: q = Φ diag(cos ω_i t) Φ⁻¹ q₀, the modal solution
    (Géradin & Rixen, *Mechanical Vibrations*, 3rd ed., 2015, §2.3)."""
    omega2, Phi = _modes()
    return (Phi @ (np.cos(np.sqrt(omega2)[:, None] * t[None, :]) * np.linalg.solve(Phi, q0)[:, None])).T


def test_a_stiff_linear_oscillator_against_its_closed_form(calls):
    """The stiff two-mass oscillator over 5 s at rtol 1e-6: rows at irregular output times (inside steps:
    the collocation polynomial) against the modal closed form: measured 1.5e-7 of the 0.1 amplitude, in 595 evaluations (40 Jacobians) where
    an explicit method's stability alone would ask for ω_fast T / 3.3 ≈ 2,100 steps."""
    system = two_masses()
    t_eval = np.sort(np.random.default_rng(1).uniform(0.0, 5.0, 37))
    result = pq.simulate(system, 5.0, method="Radau", rtol=1e-6, atol=1e-9, t_eval=t_eval)
    assert calls["segments"] == 2  # the first of its 20 segments, then the rest joined (driver.CHUNK_EVALUATIONS)
    np.testing.assert_array_equal(result.t, t_eval)
    error = np.abs(result.q - closed_form(t_eval, system.q0)).max() / 0.1
    assert error <= 1.5e-6, error
    assert result.nfev < 0.1 * 5.0 * np.sqrt(_modes()[0][1])  # 595 evaluations, ω_fast T / 10 = 707


def test_the_flyball_governor_against_a_converged_run(calls):
    """The flyball governor (stiff: ρ ≈ 8e3 1/s) over 0.2 s at rtol 1e-6 against DOP853 at rtol 1e-12: q
    within 10× the measured 9.4e-9 (relative to its largest entry; 1.9e-10 when each of the 20 segments
    cut its last step short). The compiled loop runs the 20 segments in three calls (the first, then as
    many as driver.CHUNK_EVALUATIONS joins)."""
    system = pq.scenes.flyball_governor()
    result = pq.simulate(system, 0.2, method="Radau", rtol=1e-6, n_points=21)
    assert calls["segments"] == 3
    reference = pq.simulate(system, 0.2, method="DOP853", rtol=1e-12, atol=1e-13, n_points=21)
    error = np.abs(result.q - reference.q).max() / np.abs(reference.q).max()
    assert error <= 9.4e-8, error


def test_counts_close_to_scipys_radau(calls):
    """The same problem by scipy's Radau with the exact Jacobian (the user's ``jac``: solve_ivp steps,
    :func:`projeq.analysis.jacobians.state_jacobian`, the complex step) in one segment (the compiled loop's
    20 segments take one segment's steps): evaluations besides the Jacobians' columns within 2 % (measured:
    449 vs 449), Jacobians within 20 % (measured 10 vs 10; 39 and 611 evaluations when each segment cut
    its last step short and formed a Jacobian at its start)."""
    system = pq.scenes.flyball_governor()
    compiled = pq.simulate(system, 0.2, method="Radau", rtol=1e-6, n_points=21)
    jacobians = []

    def exact(t, x):
        jacobians.append(t)
        return pq.analysis.jacobians.state_jacobian(system, x, t)[0]

    reference = pq.simulate(system, 0.2, method="Radau", jac=exact, rtol=1e-6, n_points=21, n_segments=1)
    assert calls["segments"] == 3  # the user's jac: solve_ivp stepped the reference
    own = compiled.nfev - (system.n_q + system.n_s) * compiled.njev
    assert abs(own - reference.nfev) <= 0.02 * reference.nfev, (own, reference.nfev)
    assert abs(compiled.njev - len(jacobians)) <= 0.2 * len(jacobians), (compiled.njev, len(jacobians))


def test_pauses_take_the_same_steps():
    """``loop.loop(model, "Radau")`` run straight through and paused every 10 evaluations (where simulate
    checks a coordinate singularity and Ctrl-C takes effect): the Radau memory (J, the factorisations,
    the last interpolant, Gustafsson's previous step) is kept over the pauses, so the steps, the
    evaluations and the rows are the same, bit for bit; the monitor sees every pause."""
    system = two_masses()
    evaluator, x0, t_eval = system.evaluator(), np.concatenate((system.q0, system.s_dot0)), np.linspace(0.0, 1.0, 11)
    evaluator.state_derivative(0.0, x0)  # the default evaluator's compiled tier, as simulate reaches it
    compiled = loop.loop(evaluator.loop_model(), "Radau")
    straight = compiled.run(system.n_q, 0.0, x0, 1.0, 0.0, np.inf, 1e-6, 1e-9, t_eval)
    seen = []
    paused = compiled.run(system.n_q, 0.0, x0, 1.0, 0.0, np.inf, 1e-6, 1e-9, t_eval,
                          monitor=lambda t, x: seen.append(t), every=10)
    assert straight.status == paused.status == loop.FINISHED
    assert (paused.nfev, paused.steps, paused.njev) == (straight.nfev, straight.steps, straight.njev)
    assert len(seen) >= straight.steps // 2  # 79 evaluations in 9 steps: 8 pauses
    np.testing.assert_array_equal(paused.rows, straight.rows)

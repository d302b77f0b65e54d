"""A run says when it leaves the range its model describes, and its failures are failures
(issue 20, items 2 and 3): validity of beams, stiffness over the whole run, the accuracy of the
dense evaluator, NaN in the right-hand side, and the measures a Result reports."""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.assembly.linalg import AccuracyWarning
from projeq.simulation.driver import ValidityWarning
from projeq.simulation.integrators import StiffnessWarning
from projeq.simulation.result import Result

from tests.simulation.test_extremes import axially_stiff_beam


def sagging_cantilever(g: float):
    """A 1 m cantilever (EI = 1 N m², ρA = 1 kg/m, v only, 3 polynomials) released from rest
    under gravity g along −y: its static tip deflection is g L⁴ / (8 EI) = g/8 m (Euler–Bernoulli
    cantilever under a uniform load, Timoshenko & Gere, *Mechanics of Materials*, 1972, Table
    G-1), and released from straight it swings to about twice that."""
    beam = pq.RitzBeam(1.0, 1.0, 1.0, n_v=3, n_w=0)
    return pq.System({"beam": beam}, {"beam": pq.Fixed()}, gravity=(0.0, -g, 0.0))


def test_beam_beyond_moderate_deflection_warns_and_within_does_not():
    """Passes if a cantilever swinging to ≈ 2 g/8 = 0.5 L (g = 2) gets a ValidityWarning naming
    the beam and the remedies, and one swinging to ≈ 0.025 L (g = 0.1, slope ≈ 0.033 rad) none;
    the measured peaks confirm the closed form's factor 2 within 10 %."""
    with pytest.warns(ValidityWarning, match=r"'beam' by t = .*lateral deflection 0\.\d+ L.*more Ritz functions, "
                                             r"a slower manoeuvre, or a finer model"):
        large = pq.simulate(sagging_cantilever(2.0), 2.0, n_points=201, out_of_range="warn")  # the whole swing
    with warnings.catch_warnings():
        warnings.simplefilter("error", ValidityWarning)
        small = pq.simulate(sagging_cantilever(0.1), 2.0, n_points=201)
    for result, g in ((large, 2.0), (small, 0.1)):
        beam = result.system.subsystem("beam")
        peak = np.abs(beam.displacement(result.q, [1.0])[:, 0, 1]).max()
        assert peak == pytest.approx(2 * g / 8, rel=0.1)


def test_beam_range_closed_form():
    """Passes if out_of_range reports a tip deflection of exactly 0.2 L for q_v = (0.2, 0, 0) of the
    polynomial family (Φ₁ = (x/L)², tip value 1) and slope 2 · 0.2 / L = 0.4 rad there, and
    nothing for a tenth of it."""
    beam = pq.RitzBeam(1.0, 1.0, 1.0, n_v=3, n_w=0)
    assert "lateral deflection 0.2 L" in beam.out_of_range(np.array([0.2, 0.0, 0.0]))
    assert "rotation 0.39" in beam.out_of_range(np.array([0.2, 0.0, 0.0]))  # the last segment's mean slope
    assert beam.out_of_range(np.array([0.02, 0.0, 0.0])) is None


@pytest.mark.parametrize("n_segments", [20, 100])
def test_stiffness_is_judged_over_the_run_whatever_the_segmenting(n_segments):
    """Passes if the axially stiff beam (ρh ≥ 1 at RK45's steps, see test_extremes) warns also when
    the run is cut into 20 or 100 segments of fewer than 50 steps each (issue 20: the default
    segmenting hid it)."""
    with pytest.warns(StiffnessWarning, match="try method='Radau' or 'BDF'"):
        pq.simulate(axially_stiff_beam(), 0.1, method="RK45", rtol=1e-8, atol=1e-10, n_points=3,
                    n_segments=n_segments)


def light_tip_pendulum(ratio: float):
    """A double pendulum whose second rod has ``ratio`` times the first one's mass and inertia:
    the Gauss form's M has condition number ≈ 1/ratio."""
    rod = {"r_c": (0, 0, -0.5), "I_c": np.diag([0.1, 0.1, 0.01])}
    return pq.System({"a": pq.RigidBody(1.0, **rod), "b": pq.RigidBody(ratio, rod["r_c"], ratio * rod["I_c"])},
                     {"a": pq.Revolute(axis="y"), "b": pq.Revolute("a", "y", r_pn=(0, 0, -1))},
                     gravity=(0, 0, -9.81), q0=(0.3, -0.2))


def test_dense_evaluator_warns_when_its_mass_matrix_is_ill_conditioned():
    """Passes if the error bound ε κ(M) of the dense solve (Golub & Van Loan 2013, §3.5) covers the
    measured deviation from the recursive pass (round-off at any n) on chain(40) and on a double
    pendulum with a 1e-11 light second rod, and the dense evaluator warns for the latter
    (bound above 1e-5) and not for the former (κ ≈ 1e7)."""
    for system, warns in ((pq.scenes.chain(40), False), (light_tip_pendulum(1e-11), True)):
        q, s_dot = system.q0 + 0.1, np.ones(system.n_s)
        dense = system.evaluator("dense")
        M, _ = dense.gauss_form(q, s_dot, 0.0)
        bound = np.finfo(float).eps * np.linalg.cond(M)
        exact = system.evaluator("recursive").accelerations(q, s_dot, 0.0)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            deviation = np.abs(system.evaluator("dense").accelerations(q, s_dot, 0.0) - exact).max()
        assert deviation <= bound * np.abs(exact).max()
        assert [issubclass(w.category, AccuracyWarning) for w in caught] == ([True] if warns else [])
    assert bound > 1e-5


class _NaNAfter:
    """An evaluator whose accelerations become NaN after t = 0.3 (a broken user model)."""

    def __init__(self, system):
        self.system = system

    def accelerations(self, q, s_dot, t):
        s_ddot = self.system.accelerations(q, s_dot, t)
        return s_ddot * np.nan if t > 0.3 else s_ddot


def test_nan_derivative_stops_the_run_and_keeps_the_trajectory():
    """Passes if a right-hand side turning NaN after t = 0.3 s ends the run with a SimulationError
    naming the non-finite derivative and its time, its .result holding the rows up to the last
    finished segment (t ≤ 0.3 s) and not one NaN."""
    system = pq.scenes.double_pendulum()
    with pytest.raises(pq.SimulationError, match=r"failed at t = 0.3\d* s .*non-finite state derivative at t = 0.3") as info:
        pq.simulate(system, 1.0, evaluator=_NaNAfter(system), n_segments=10, n_points=101)
    kept = info.value.result
    assert 0.2 <= kept.t[-1] <= 0.3 + 1e-12 and np.all(np.isfinite(kept.q))


def test_energy_drift_is_the_largest_change_over_the_energy_scale():
    """Passes if energy_drift is max |E − E₀| / max(|T|, |V|) on hand-made rows: E = (1, 3, 0) with
    T = (1, 2, 0), V = (0, 1, 0): max |E − E₀| = 2, scale 2, drift 1."""
    result = Result(t=np.arange(3.0), q=np.zeros((3, 1)), s_dot=np.zeros((3, 1)), kinetic=np.array([1.0, 2.0, 0.0]),
                    potential=np.array([0.0, 1.0, 0.0]), constraint_residual=np.zeros((3, 0)))
    assert result.energy_drift == 1.0


def test_fast_spin_up_warns_beyond_moderate_deflection():
    """Passes if the spin-up to 6 rad/s in t_s = 2 s (issue 20: `projeq run spin_up_beam --set t_s=2
    --t-end 3` ended with a 42 m tip deflection on the 10 m beam, exit 0) warns once the tip
    passes 0.1 L, before t = 0.7 s, and names the beam and what to do."""
    with pytest.warns(ValidityWarning, match=r"^'beam' by t = 0\.[56]\d* s: lateral deflection 0\.1\d* L.*more Ritz functions"):
        pq.simulate(pq.scenes.spin_up_beam(t_s=2.0), 0.7, method="DOP853", rtol=1e-9)

"""Physics out of range stops the run or is recorded, never reported as success (issue 37, item 4).

Before, ``spin_up_beam(omega_s=200, t_s=2)`` ran to t = 3 s with status 0 ("finished"), a final
q of about 1e88 m and a NaN energy; with ``t_s=2`` alone the tip of the 10 m beam moved 3.8 km,
and only a ValidityWarning said so."""

import re
import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.simulation.driver import ValidityWarning
from projeq.simulation.result import NON_FINITE, OUT_OF_RANGE

from tests.simulation.test_monitors import _NaNAfter, sagging_cantilever


def test_leaving_the_beam_range_ends_the_run_with_status_out_of_range():
    """Passes if the sagging cantilever (g = 2: it swings to ≈ 0.5 L, far past the 0.1 L of the
    moderate-deflection range) stops with status 3 at the end of the segment (0.1 s each; the end of
    the integrator's first step past it, 0.305 s) where its rows first pass 0.1 L with
    out_of_range="stop" (projeq run's choice): its first mode (ω₁ = 3.516 √(EI/ρA L⁴) rad/s,
    Timoshenko & Gere 1972) gives a tip at (1 − cos ω₁t) g/8, 0.1 L at t = 0.264 s and 0.127 L at
    0.3 s (0.131 L measured at 0.305 s), so by t = 0.305 s; warned once, its 31 rows up to then kept;
    the default, out_of_range="warn", runs on to t_end with status 0, for studies beyond the range."""
    with pytest.warns(ValidityWarning, match=r"^'beam' by t = 0\.30\d* s: lateral deflection 0\.1[23]\d L"):
        stopped = pq.simulate(sagging_cantilever(2.0), 2.0, n_points=201, out_of_range="stop")
    assert stopped.status == OUT_OF_RANGE and not stopped.success
    assert stopped.t[-1] == pytest.approx(0.3) and len(stopped.t) == 31
    assert re.match(r"stopped at t = 0\.30\d* s: a subsystem left the range its model describes", stopped.message)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ValidityWarning)
        on = pq.simulate(sagging_cantilever(2.0), 2.0, n_points=201)
    assert on.status == 0 and on.t[-1] == 2.0
    with pytest.raises(ValueError, match=r"^out_of_range: expected 'stop' or 'warn', got 'ignore'"):
        pq.simulate(sagging_cantilever(2.0), 2.0, out_of_range="ignore")


def test_a_state_beyond_floating_point_range_is_status_non_finite():
    """Passes if the spin-up beam driven to 200 rad/s in 2 s, let go on past its range
    (out_of_range="warn"), ends with SimulationError and status 4 where its energy overflows
    (q ≈ 1e77 m there, T NaN or inf by where scipy's Radau steps: inf with scipy 1.17; the run
    reported "finished" with q ≈ 1e88 and a NaN energy before), its
    .result holding only finite rows and energies."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(pq.SimulationError, match=r"the energy \(T, V\) = \((nan|inf), .*\) is not finite at t = "
                                                     r"2\.\d+ \(largest \|q\| \d\.\d+e\+\d+\): the state is beyond "
                                                     r"floating-point range") as info:
            pq.simulate(pq.scenes.spin_up_beam(omega_s=200.0, t_s=2.0), 3.0, method="Radau", rtol=1e-4, atol=1e-6,
                        out_of_range="warn")
    kept = info.value.result
    assert kept.status == NON_FINITE and 2.0 < kept.t[-1] < 3.0
    assert np.isfinite(kept.energy).all() and np.isfinite(kept.q).all()


def test_a_nan_right_hand_side_is_status_non_finite():
    """Passes if a right-hand side turning NaN after t = 0.3 s (test_monitors' _NaNAfter) ends the
    run with status 4 (it was −1, "failed", indistinguishable from an integrator's failure)."""
    system = pq.scenes.double_pendulum()
    with pytest.raises(pq.SimulationError, match="non-finite state derivative") as info:
        pq.simulate(system, 1.0, evaluator=_NaNAfter(system), n_segments=10, n_points=101)
    assert info.value.result.status == NON_FINITE

"""``simulate(..., jac=...)`` for the implicit methods (issue 16): the exact Jacobian by the
complex step is the default for Radau, BDF and LSODA; scipy's differences on request.

Reference: the same motion by DOP853 at rtol 1e-12 (an explicit method, no Jacobian). An
implicit method's Jacobian only steers its Newton iterations, so with either Jacobian the
end state agrees with the reference to the tolerance asked (rtol 1e-9: each case's bound is 10× the
largest global error measured over a few variations of the run, below)."""

import numpy as np
import pytest

import projeq as pq


# 10× the largest end-state error over t_end 0.2 and 0.3 s, rtol 1e-9 and 2e-9 with both Jacobians (at the
# test's 0.2 s, 1e-9: 3.4e-13, 1.5e-8, 3.8e-10, 2.0e-9; the largest: 2.7e-12, 2.7e-8, 1.1e-9, 4.1e-9; was 1e-6)
@pytest.mark.parametrize("method, scene, bound", [("Radau", "four_bar", 2.7e-11), ("BDF", "rolling_disk", 2.7e-7),
                                                  ("BDF", "chain", 1.1e-8), ("LSODA", "four_bar", 4.1e-8)])
def test_exact_jacobian_gives_the_same_motion(method, scene, bound):
    system = getattr(pq.scenes, scene)()
    reference = pq.simulate(system, 0.2, method="DOP853", rtol=1e-12, atol=1e-14, n_points=3)
    exact = pq.simulate(system, 0.2, method=method, rtol=1e-9, atol=1e-11, n_points=3)
    differences = pq.simulate(system, 0.2, method=method, jac="differences", rtol=1e-9, atol=1e-11, n_points=3)
    assert differences.njev == 0
    assert exact.njev > 0 or method == "LSODA"  # LSODA asks for none while it stays non-stiff (Adams)
    for run in (exact, differences):
        assert np.abs(run.q[-1] - reference.q[-1]).max() < bound


def test_bad_jac():
    with pytest.raises(ValueError, match="jac"):
        pq.simulate(pq.scenes.chain(2), 0.1, method="Radau", jac="symbolic")
    with pytest.raises(ValueError, match="jac"):
        pq.simulate(pq.scenes.chain(2), 0.1, method="RK45", jac=lambda t, x: np.eye(4))

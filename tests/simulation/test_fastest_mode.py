"""integrators.fastest_mode: the spectral radius and whether the fastest mode decays without
oscillating (a real eigenvalue −ρ), on linear systems ẋ = J x whose eigenvalues are known
(Golub & Van Loan, "Matrix Computations", 4th ed. (2013), §7.3.1, the power method)."""

import numpy as np
import pytest

from projeq.simulation.integrators import fastest_mode, spectral_radius


@pytest.mark.parametrize("J, rho, decays", [
    (np.array([[0.0, 1.0], [-1e6, 0.0]]), 1e3, False),  # an undamped oscillator, ±1000i
    (np.array([[0.0, 1.0], [-1e6, -200.0]]), None, False),  # lightly damped −100 ± 995i: ρ only roughly
    (np.array([[0.0, 1.0], [-1e6, -1e4]]), 9898.979485566356, True),  # overdamped: −9899, −101
    (np.diag([-5.0, -1.0, 0.5]), 5.0, True),
    (np.diag([5.0, -1.0]), 5.0, False),  # growing, not decaying
])
def test_fastest_mode_tells_a_decaying_mode_from_an_oscillation(J, rho, decays):
    found, real = fastest_mode(lambda t, x: J @ x, 0.0, np.zeros(len(J)))
    assert real is decays
    if rho is not None:
        assert found == pytest.approx(rho, rel=1e-3)
    assert spectral_radius(lambda t, x: J @ x, 0.0, np.zeros(len(J))) == found

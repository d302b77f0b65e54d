"""The pivots of the recursive pass and the Gauss form's mass matrix: a zero pivot (a motion
that moves no mass) and a negative one (which no mass distribution gives) get different
messages, each naming the joint."""

import numpy as np
import pytest

from projeq.assembly.linalg import SingularMassError, solve_spd


@pytest.mark.parametrize("D", [np.array([[0.0]]), np.diag([1.0, 0.0])])
def test_a_zero_pivot_is_a_motion_that_moves_no_mass(D):
    with pytest.raises(SingularMassError, match=r"joint 'elbow'.*moves no mass"):
        solve_spd(D, np.ones((len(D), 1)), "elbow", 1.0)


@pytest.mark.parametrize("D", [np.array([[-6.7e7]]), np.diag([1.0, -2.0])])
def test_a_negative_pivot_says_the_state_left_the_model(D):
    """A positive semi-definite M̂_n (Σ mass × velocity² ≥ 0) cannot give a negative pivot:
    the message names the eigenvalue and the state, not a massless motion."""
    with pytest.raises(SingularMassError, match=r"joint 'fore' is indefinite.*left the range") as error:
        solve_spd(D, np.ones((len(D), 1)), "fore", 1.0)
    assert "moves no mass" not in str(error.value) and f"{np.linalg.eigvalsh(D)[0]:.3g}" in str(error.value)

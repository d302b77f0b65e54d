"""Bad input to projeq.compare refused by name before any derivation runs."""

import numpy as np
import pytest

import projeq as pq


@pytest.mark.parametrize("kwargs, message", [
    ({"t_end": np.inf}, r"^t_end: must be a positive, finite number of seconds, got inf"),
    ({"formulations": []}, r"^formulations: none given; name at least one \(the first is the reference\)"),
], ids=["t_end-inf", "formulations-empty"])
def test_compare_refuses_before_deriving(kwargs, message):
    """Passes if each is a ValueError naming the parameter. Before: t_end = inf passed the check
    (inf > 0) on to the formulations' integrations, and formulations=[] returned a table without
    rows, without its reference row."""
    with pytest.raises(ValueError, match=message):
        pq.compare("n_link_pendulum", simulate=False, repeats=1, **kwargs)

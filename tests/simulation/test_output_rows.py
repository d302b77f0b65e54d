"""simulate's output rows (:meth:`projeq.system.Model.output_row`: one constraint matrix per row)
against the per-row definitions they replace: the model's energy, q̇ and constraint residual,
rank and mobility, each evaluated on its own at rows of a run."""

import numpy as np
import pytest

import projeq as pq
from projeq import scenes


def _per_row(model, q, s_dot, t):
    """The row's values by the model's public definitions, one call each."""
    energy = model.energy(q, s_dot, t)
    residual = model.constraint_residual(q, model.q_dot(q, s_dot, t), t)
    ranks = (model.rank(q, t), model.mobility(q, t)) if hasattr(model, "mobility") else None
    return energy, residual, ranks


@pytest.mark.parametrize("name, t_end", [("four_bar", 0.5), ("andrews_squeezer", 0.01), ("simple_pendulum", 0.5), ("double_pendulum", 0.5)])
def test_result_rows_equal_the_per_row_definitions(name, t_end):
    scene = scenes.SCENES[name]
    system = scene.build()
    result = pq.simulate(system, t_end, n_points=21, **(scene.settings or {}))
    for i in (0, 7, 20):
        q, s_dot, t = result.q[i], result.s_dot[i], result.t[i]
        energy, residual, ranks = _per_row(system, q, s_dot, t)
        # a tree's rows together (FastEvaluator.energies: T summed in another order): measured ≤ 2.4e-16
        # relative here, 3.6e-16 on chain(5) (1–2 ulp); the constrained models' rows bit for bit
        np.testing.assert_allclose((result.kinetic[i], result.potential[i]), energy, rtol=1e-15, atol=0)
        np.testing.assert_array_equal(result.constraint_residual[i], residual)
        if ranks is None:
            assert not len(result.rank)
        else:
            assert (result.rank[i], result.mobility[i]) == ranks
        row = system.output_row(q, s_dot, t)
        assert row[0] == energy and np.array_equal(row[1], residual) and row[2] == ranks


def test_output_row_of_a_constrained_system_matches_its_definitions_with_baumgarte_and_pfaffian_rows():
    """A loop closed by Φ with Baumgarte's correction (q̇ carries −β C_Φ⁺ Φ) off the constraint
    manifold, where the residual's Φ is not zero."""
    system = scenes.four_bar(correction="baumgarte")
    q = system.q0 + np.array([1e-3, -2e-3, 5e-4])[: system.n_q]
    s_dot = system.s_dot0 + 0.3
    energy, residual, ranks = _per_row(system, q, s_dot, 0.2)
    row = system.output_row(q, s_dot, 0.2)
    assert row[0] == energy and np.array_equal(row[1], residual) and row[2] == ranks
    assert np.abs(residual).max() > 1e-6  # the state is off Φ = 0: the test sees the residual

"""simulate's output rows (:meth:`projeq.system.Model.output_row`: one constraint matrix per row)
against the per-row definitions they replace: the model's energy, q̇ and constraint residual,
rank and mobility, each evaluated on its own at rows of a run."""

import numpy as np
import pytest

import projeq as pq
from projeq import scenes
from projeq.scenes import iftomm


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
        # rows together (FastEvaluator.energies: T summed in another order; a closed loop's by its compiled
        # rows, ConstrainedSystem.rows): measured ≤ 1.4e-15 relative here (the simple pendulum's), 3.6e-16 on
        # chain(5) (1–6 ulp); residuals measured equal (the compiled Φ's callback and Φ itself: 100 ε allowed
        # between them)
        np.testing.assert_allclose((result.kinetic[i], result.potential[i]), energy, rtol=1.4e-14, atol=0)
        np.testing.assert_allclose(result.constraint_residual[i], residual, rtol=0, atol=2.2e-14)
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


@pytest.mark.parametrize("name, t_end", [("four_bar", 0.2), ("flexible_four_bar", 0.2), ("whipple_bicycle", 0.2),
                                         ("bricard", 0.2), ("andrews_squeezer", 0.01)])
def test_closed_loops_rows_together_are_the_rows_one_by_one(name, t_end):
    """A closed loop's rows in one compiled call (:meth:`ConstrainedSystem.rows
    <projeq.constraints.partitioned.ConstrainedSystem.rows>`: the Gauss–Newton projection onto Φ = 0,
    ṡ_tree, residuals, rank, the tree's energies) against ``normalized`` and ``output_row`` row by row
    (the numpy path), at states of a run moved off Φ = 0 by up to 1e-5 so that each row projects: a
    user's Φ through its compiled callback (four-bar), a cut joint on a RitzBeam (the kernel's own rows),
    Pfaffian rows and a UserJoint from sympy (the bicycle); in the null-space form Bricard's mechanism
    (IFToMM A04, a redundant constraint) and Andrews' squeezer, the branch's tangent continued through
    the rows from the same kept tangent. Both projections stop once |Φ| is within POSITION_TOLERANCE
    (1e-12 · max(1, |q|)), so they may differ by one last Gauss–Newton step below it."""
    system = iftomm.bricard() if name == "bricard" else getattr(scenes, name)()
    result = pq.simulate(system, t_end, n_points=6)
    x = np.hstack((result.q + 1e-5 * np.sin(np.arange(result.q.size)).reshape(result.q.shape), result.s_dot))
    kept = getattr(system, "_tangent", None)  # the null-space form's (the rows continue it in place)
    kept = None if kept is None else np.array(kept)
    q, energies, residuals, ranks = system.rows(x, result.t)
    if kept is not None:
        system._tangent = kept  # the numpy path's rows from the same tangent
    for i, t in enumerate(result.t):
        q_i = system.normalized(x[i, :system.n_q], t)
        energy, residual, rank = system.output_row(q_i, x[i, system.n_q:], t)
        # measured (largest of the scenes, the bicycle's): q 7.1e-13, residuals 7.2e-13, energies 2.8e-13
        # relative (4.1e-13, 4.6e-13, 3.9e-13 on the four-bar; ≤ 1.6e-15 from states 1e-8 off Φ = 0, and
        # from these on Bricard's and Andrews' mechanisms)
        np.testing.assert_allclose(q[i], q_i, rtol=0, atol=8e-12)
        np.testing.assert_allclose(residuals[i], residual, rtol=0, atol=8e-12)
        np.testing.assert_allclose(energies[i], energy, rtol=4e-12, atol=0)
        assert tuple(ranks[i]) == rank

"""Constrained models evaluate their tree with the compiled kernels by default (issue 15): the
tree's M and b of the Gauss form come from :meth:`projeq.assembly.fast.FastEvaluator.gauss_form`
(composite bodies and Newton–Euler, Featherstone (2008) §5.3, §6.2), and the constrained s̈ and
multipliers λ equal those projected from the dense reference form (Σ J_nᵀ M_n J_n,
docs/theory.md §5), an independent formulation, to round-off; a tree the kernel does not know
is projected from the dense form after one InterpretedWarning naming the piece; the complex
step (exact Jacobians) still runs through the dense reference.
"""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.analysis.jacobians import state_jacobians
from projeq.assembly import InterpretedWarning
from projeq.constraints.augmented import AugmentedSystem
from projeq.constraints.compiled import UncompiledClosureWarning, unsupported
from projeq.constraints.partitioned import ConstrainedSystem
from projeq.scenes.iftomm import simple_pendulum

# the same M, b to ~1e-15 relative (tests/assembly/test_fast.py), then the same projection:
# measured ≤ 2.4e-15 of max(1, |s̈|∞) (s̈_tree and λ) on these scenes; 10× that (was 1e-12)
RTOL = 2.4e-14


def _augmented_pendulum():
    return AugmentedSystem(simple_pendulum().tree, phi=lambda q, t: [q[0] ** 2 + q[1] ** 2 - 1.0], q0=[1.0, 0.0])


MODELS = {name: pq.scenes.SCENES[name].build for name in
          ("four_bar", "bricard", "whipple_bicycle", "quick_return", "simple_pendulum", "n_four_bar")}
MODELS["augmented pendulum"] = _augmented_pendulum


@pytest.mark.parametrize("name", sorted(MODELS))
def test_the_default_projects_the_compiled_tree_and_equals_the_dense_projection(name):
    model = MODELS[name]()
    rng = np.random.default_rng(2)
    q, s_dot = model.q0, model.s_dot0 + rng.standard_normal(model.n_s)
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        assert model.evaluator().name == "partitioned(fast)"
        s_ddot_tree, lam = model.accelerations_tree(q, s_dot, 0.3)
    reference, lam_reference = model.accelerations_tree(q, s_dot, 0.3, method="dense")
    assert model.evaluator("dense").name == "partitioned(dense)"
    assert np.abs(s_ddot_tree - reference).max() <= RTOL * max(1.0, np.abs(reference).max())
    assert np.abs(lam - lam_reference).max(initial=0.0) <= RTOL * max(1.0, np.abs(lam_reference).max(initial=0.0))


def test_the_exact_jacobians_of_a_constrained_model_take_the_dense_reference():
    """The complex step (projeq.analysis.jacobians) cannot run through the real compiled
    kernels: with complex arguments the tree's form is the dense reference, and ∂s̈/∂ṡ of the
    four-bar by the complex step equals central differences of the compiled default (to
    their own error, h² |s⃛|/6: measured 1.7e-10 relative at h = 1e-4; the bound is 10 times that,
    was 1e-7)."""
    model = pq.scenes.four_bar()
    s_dot, step = np.array([0.7]), 1e-4
    jac = state_jacobians(model, model.q0, s_dot, 0.0)
    assert jac.derivatives == "exact"
    s_ddot = [model.accelerations(model.q0, s_dot + d) for d in (step, -step)]
    central = ((s_ddot[0] - s_ddot[1]) / (2 * step))[0]
    assert jac.s_ddot_s_dot[0, 0] == pytest.approx(central, rel=1.7e-9, abs=0)


class _OwnTerms(pq.RigidBody):
    """A rigid body with its own gauss_terms (the same ones), unknown to the kernel."""

    def gauss_terms(self, y_dot, R, gravity, q_e=None):
        return super().gauss_terms(y_dot, R, gravity, q_e)


def test_a_tree_the_kernel_does_not_know_is_projected_from_the_dense_form_saying_so():
    tree = pq.System({"x": pq.Frame(), "bob": _OwnTerms(1.0, (0, 0, 0), np.eye(3) * 1e-3)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")}, gravity=(0, 0, -9.81))
    pendulum = ConstrainedSystem(tree, phi=lambda q, t: [np.hypot(q[0], q[1]) - 1.0], q0=[0.6, -0.8], independent=[0])
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        ev = pendulum.evaluator()
        for _ in range(3):
            s_ddot = ev.accelerations(pendulum.q0, np.array([0.4]), 0.0)
    assert ev.name == "partitioned(dense)"
    # the tree says it is interpreted, naming the piece, and the model that its s̈ is not one compiled call, why
    assert [type(w.message) for w in said] == [InterpretedWarning, UncompiledClosureWarning]
    assert "_OwnTerms" in str(said[0].message) and unsupported(pendulum) in str(said[1].message)
    np.testing.assert_array_equal(s_ddot, pendulum.accelerations(pendulum.q0, [0.4], method="dense"))

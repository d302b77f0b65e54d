"""Bad states fed to the constrained models' public evaluators (issue 37, item 1): wrong shapes,
NaN, 1e200, complex and strided input to ConstrainedSystem.accelerations, accelerations_tree,
gauss_form, tree_velocities, q_dot, K, energy and the evaluator's own calls (accelerations and the
one-call ẋ that simulate takes), for both forms (the four-bar partitioned, the double four-bar in
the null-space form), each compiled. Type and shape are checked before any kernel reads the
state (before: a short q went straight into the compiled kernel, which reads q[i] for every tree
coordinate), a non-finite result raises naming the argument."""

import numpy as np
import pytest

import projeq as pq
from projeq.scenes.iftomm import n_four_bar


@pytest.fixture(scope="module", params=["partitioned", "null space"])
def model(request):
    system = pq.scenes.four_bar() if request.param == "partitioned" else n_four_bar(2)
    assert system.formulation == request.param and system.compiled_kernel() is not None
    return system


def _calls(system):
    """Every public entry point that takes a state, as f(q, s_dot)."""
    evaluator = system.evaluator()
    return {
        "accelerations": lambda q, s: system.accelerations(q, s),
        "accelerations_tree": lambda q, s: system.accelerations_tree(q, s),
        "gauss_form": lambda q, s: system.gauss_form(q, s),
        "tree_velocities": lambda q, s: system.tree_velocities(q, s),
        "q_dot": lambda q, s: system.q_dot(q, s),
        "energy": lambda q, s: system.energy(q, s),
        "K": lambda q, s: system.K(q),
        "evaluator": lambda q, s: evaluator.accelerations(q, s, 0.0),
    }


@pytest.mark.parametrize("case, change, message", [
    ("q-short", lambda q, s: (q[:2], s), r"^q: expected"),
    ("q-2d", lambda q, s: (q[None, :], s), r"^q: expected"),
    ("s_dot-long", lambda q, s: (q, np.append(s, 1.0)), r"^s_dot: expected"),
])
def test_a_state_of_the_wrong_shape_is_refused_by_name(model, case, change, message):
    q, s_dot = change(model.q0, model.s_dot0 + 0.5)
    for name, call in _calls(model).items():
        if name == "K" and case.startswith("s_dot"):
            continue
        with pytest.raises(ValueError, match=message):
            call(q, s_dot)


def test_the_one_call_state_derivative_refuses_a_short_state(model):
    with pytest.raises(ValueError, match=r"^x: expected"):
        model.evaluator().state_derivative(0.0, np.zeros(3))


def test_a_non_finite_or_overflowing_state_is_named(model):
    """NaN in q and ṡ = 1e200 (finite, its squares overflow): the checked calls name the argument."""
    q, s_dot = model.q0.copy(), model.s_dot0 + 0.5
    with pytest.raises(ValueError, match=r"^s_dot: s̈ is not finite at this state \(largest \|s_dot\| = 1e\+200"):
        model.accelerations(q, np.full(model.n_s, 1e200))
    with pytest.raises(ValueError, match=r"^s_dot: s̈_tree is not finite"):
        model.accelerations_tree(q, np.full(model.n_s, 1e200))
    bad = q.copy()
    bad[0] = np.nan
    with pytest.raises(ValueError, match=r"^q: "):
        model.accelerations(bad, s_dot)
    with pytest.raises(ValueError, match=r"^q: the constraint matrix is not finite at q = \[nan"):
        model.evaluator().accelerations(bad, s_dot, 0.0)  # values unchecked: an error, never finite garbage


def test_complex_lists_are_refused_and_strided_states_taken(model):
    q, s_dot = model.q0, model.s_dot0 + 0.5
    with pytest.raises(ValueError, match=r"^q: "):
        model.accelerations([complex(x) + 1e-3j for x in q], s_dot)
    wide = np.zeros((len(q), 2))
    wide[:, 0] = q
    expected = model.accelerations(q, s_dot)
    assert np.array_equal(model.accelerations(wide[:, 0], s_dot), expected)
    assert np.array_equal(model.evaluator().accelerations(wide[:, 0], s_dot, 0.0), expected)

"""Exact Jacobians (issue 16): ∂q̇/∂q, ∂q̇/∂ṡ, ∂s̈/∂q, ∂s̈/∂ṡ, ∂s̈/∂τ by the complex step
through the model's own evaluation (``projeq.analysis.jacobians``).

References: Richardson-extrapolated central differences (``differentiation.jacobian``,
truncation O(h⁴)) on hypothesis trees with every joint, force law and subsystem kind of
``tests/strategies.py`` and on the constrained, non-holonomic and elastic scenes (measured
≤ 2e-9 of max(1, |J|) over 120 trees at h = 1e-3: the differences' own error, so 1e-7
bounds it and still catches any lost term, which is O(1)); closed forms where the
derivative is known exactly (the compound pendulum: to round-off)."""

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

import projeq as pq
from projeq.analysis.differentiation import jacobian
from projeq.analysis.jacobians import state_derivative, state_jacobians
from strategies import trees

DIFFERENCES_TOL = 1e-7  # of max(1, |J|): the O(h⁴) differences' error at h = 1e-3 (module docstring)


def _check_against_differences(system, q, s_dot, t, inputs=()):
    J = state_jacobians(system, q, s_dot, t, inputs)
    assert J.derivatives == "exact"
    x0 = np.concatenate((q, s_dot))
    reference = jacobian(lambda x: state_derivative(system, x, t), x0, 1e-3)
    stacked = np.block([[J.q_dot_q, J.q_dot_s_dot], [J.s_ddot_q, J.s_ddot_s_dot]])
    scale = max(1.0, np.abs(reference).max(initial=0.0))
    assert np.abs(stacked - reference).max(initial=0.0) <= DIFFERENCES_TOL * scale
    if inputs:
        n_u = J.s_ddot_tau.shape[1]
        B = jacobian(lambda u: state_derivative(system, x0, t, u, inputs), np.zeros(n_u), 1e-3)[system.n_q:]
        assert np.abs(J.s_ddot_tau - B).max() <= DIFFERENCES_TOL * max(1.0, np.abs(B).max())


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=trees(max_n=5))
def test_spatial_trees(tree):
    inputs = [n for n, j in zip(tree.system.names, tree.system.joints) if j.n_s and not j.coupling][:1]
    _check_against_differences(tree.system, tree.q, tree.s_dot, tree.t, inputs)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=trees(max_n=5, planar=True))
def test_planar_trees(tree):
    _check_against_differences(tree.system, tree.q, tree.s_dot, tree.t)


@pytest.mark.parametrize("scene", ["four_bar", "slider_pendulum", "rolling_disk", "car", "quick_return"])
def test_constrained_and_nonholonomic_scenes(scene):
    system = getattr(pq.scenes, scene)()
    rng = np.random.default_rng(7)
    s_dot = rng.uniform(-1, 1, system.n_s)
    _check_against_differences(system, system.q0, s_dot, 0.3)


def test_compound_pendulum_is_exact_to_round_off():
    """One link of scenes.chain about its hinge: ∂θ̈/∂θ = −m g d / I_O at θ = 0 (I_O = I_c +
    m d², d = L/2, I_c = m (3r² + L²)/12), every other entry exactly 0 or 1."""
    J = state_jacobians(pq.scenes.chain(1), [0.0], [0.0])
    I_O = (3 * 0.01**2 + 1.0) / 12 + 0.25
    assert J.s_ddot_q[0, 0] == pytest.approx(-9.81 * 0.5 / I_O, rel=2e-16, abs=0)
    assert (J.q_dot_q, J.q_dot_s_dot, J.s_ddot_s_dot) == (0.0, 1.0, 0.0)


def test_differences_on_request():
    J = state_jacobians(pq.scenes.chain(2), [0.3, -0.2], [0.1, 0.4], derivatives="differences")
    assert J.derivatives == "differences"
    with pytest.raises(ValueError, match="derivatives"):
        state_jacobians(pq.scenes.chain(2), [0.3, -0.2], [0.1, 0.4], derivatives="symbolic")


def test_callables_without_complex_support_fall_back_to_differences():
    """np.hypot takes no complex arguments: the constraint derivatives and the Jacobians
    fall back to differences and say so; the pendulum's s̈ still matches the closed form
    θ̈ = −(g/l) sin θ of the bob on the circle (x = l sin θ, z = −l cos θ; ṡ = ẋ)."""
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")},
                     gravity=(0, 0, -9.81))
    theta = 0.6
    pendulum = pq.ConstrainedSystem(tree, phi=lambda q, t: [np.hypot(q[0], q[1]) - 1.0],
                                    q0=[np.sin(theta), -np.cos(theta)], independent=[0])
    assert not pendulum.exact
    J = state_jacobians(pendulum, pendulum.q0, [0.0])
    assert J.derivatives == "differences"
    x_ddot = pendulum.accelerations(pendulum.q0, [0.0])[0]  # at rest: ẍ = l cos θ θ̈
    assert x_ddot == pytest.approx(-9.81 * np.sin(theta) * np.cos(theta), rel=1e-10)


@pytest.mark.parametrize("precomputed", [False, True], ids=["quadrature", "precomputed"])
def test_elastic_beam_on_a_hub(precomputed):
    """A RitzBeam (bending both ways, axial, stiffening) on a revolute hub with gravity, by
    both integration strategies: exact Jacobians against differences."""
    beam = pq.RitzBeam(1.0, 1.0, 2.0, EA=50.0, n_v=2, n_w=2, n_u=1, precomputed_integrals=precomputed)
    system = pq.System({"beam": beam}, {"beam": pq.Revolute(axis="y")}, gravity=(0.0, 0.0, -9.81))
    rng = np.random.default_rng(3)
    q = 0.01 * rng.uniform(-1, 1, system.n_q)
    _check_against_differences(system, q, rng.uniform(-1, 1, system.n_s), 0.2)


def test_beam_in_a_chain():
    """The flexible arm (scenes.flexible_arm: a RitzBeam with a tip mass as the third of three
    links, gravity), bent and moving: the Jacobian the implicit methods get
    (simulate(..., jac="exact")) against differences, its elastic rows up to ω² ≈ 1e7 1/s²."""
    system = pq.scenes.flexible_arm()
    rng = np.random.default_rng(11)
    q = system.q0 + np.r_[0.0, 0.0, 0.0, 0.01 * rng.uniform(-1, 1, system.n_q - 3)]
    _check_against_differences(system, q, rng.uniform(-1, 1, system.n_s), 0.0)


@pytest.mark.parametrize("scene", ["n_four_bar", "bricard"])
def test_tangent_system_scenes(scene):
    """TangentSystem (F from the SVD's null space, carried through the complex step by a Newton
    step of the real basis): exact, against differences, on the IFToMM double four-bar and
    Bricard's overconstrained mechanism (redundant rows)."""
    system = getattr(pq.scenes, scene)()
    s_dot = np.random.default_rng(5).uniform(-1, 1, system.n_s)
    _check_against_differences(system, system.q0, s_dot, 0.3)


def _pendulum_on_sliders(rows: int):
    """A bob on x and z sliders kept on the unit circle, its closure written ``rows`` times."""
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")},
                     gravity=(0, 0, -9.81))
    return tree, lambda q, t: [k * (np.sqrt(q[0] ** 2 + q[1] ** 2) - 1.0) for k in range(1, rows + 1)]


def test_tangent_system_jacobians_are_the_partitioned_ones():
    """A second formulation: the pendulum on sliders as a TangentSystem with its closure written
    twice (a redundant row) and as a ConstrainedSystem with it once, both with ẋ independent,
    have the same F, f̄ and s̈, so their exact Jacobians agree to round-off (measured 1.6e-15 of the
    largest entry; 1e-12 allowed)."""
    from projeq.constraints.tangent import TangentSystem

    q0, s_dot = [0.6, -0.8], [0.7]
    tangent = TangentSystem(*_pendulum_on_sliders(2), q0=q0, independent=[0])
    partitioned = pq.ConstrainedSystem(*_pendulum_on_sliders(1), q0=q0, independent=[0])
    J, K = state_jacobians(tangent, q0, s_dot, 0.2), state_jacobians(partitioned, q0, s_dot, 0.2)
    assert J.derivatives == K.derivatives == "exact"
    for a, b in zip(J[:5], K[:5]):
        assert np.abs(a - b).max(initial=0.0) <= 1e-12 * np.abs(b).max(initial=1.0)

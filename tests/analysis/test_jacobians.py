"""Exact Jacobians (issue 16): ∂q̇/∂q, ∂q̇/∂ṡ, ∂s̈/∂q, ∂s̈/∂ṡ, ∂s̈/∂τ by the complex step
through the model's own evaluation (``projeq.analysis.jacobians``).

References: Richardson-extrapolated central differences (``differentiation.jacobian``,
truncation O(h⁴)) on hypothesis trees with every joint, force law and subsystem kind of
``tests/strategies.py`` and on the constrained, non-holonomic and elastic scenes (measured
at h = 1e-3, of max(1, |J|): ≤ 3.3e-9 over 120 trees, ∂s̈/∂τ 4.5e-9, the flexible arm 6.9e-9 —
the differences' own error —, so DIFFERENCES_TOL = 7e-8, 10× the largest (was 1e-7), bounds it
and still catches any lost term, which is O(1)); closed forms where the
derivative is known exactly (the compound pendulum: to round-off)."""

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

import projeq as pq
from projeq.analysis.differentiation import COMPLEX_STEP, DifferencesWarning, exact_jacobian, jacobian
from projeq.analysis.jacobians import differentiate, state_derivative, state_jacobian, state_jacobians
from projeq.assembly import kernels
from projeq.assembly.beam_fast import HubBeamEvaluator
from projeq.assembly.fast import FastEvaluator
from strategies import random_state, trees, with_couplings, with_every_law

DIFFERENCES_TOL = 7e-8  # of max(1, |J|): the O(h⁴) differences' error at h = 1e-3 (module docstring)


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


def test_differentiate_warns_once_per_callable_that_falls_back():
    """math.sin casts a complex z to float (a ComplexWarning, as an error): differentiate falls back to Richardson's
    differences, the derivative still cos z₀ to their accuracy, and says so once, naming the
    callable and what is differentiated."""

    def real_only(z):
        return np.array([math.sin(z[0])])

    with pytest.warns(DifferencesWarning, match=r"^the pendulum: .*real_only \(test_jacobians.py:\d+\).*ComplexWarning") \
            as caught:
        for z in (0.3, 0.7):
            J, used = differentiate(real_only, np.array([z]), piece="the pendulum")
            # measured 4.7e-13, 1.2e-12 relative (at most 1.5e-12 over five z; was rel 1e-10)
            assert used == "differences" and J[0, 0] == pytest.approx(np.cos(z), rel=1.5e-11, abs=0)
    assert len([w for w in caught if w.category is DifferencesWarning]) == 1


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

    def circle(q, t):
        return [np.hypot(q[0], q[1]) - 1.0]

    with pytest.warns(DifferencesWarning, match=r"^phi: .*circle .*TypeError") as built:
        pendulum = pq.ConstrainedSystem(tree, phi=circle, q0=[np.sin(theta), -np.cos(theta)], independent=[0])
    assert not pendulum.exact
    J = state_jacobians(pendulum, pendulum.q0, [0.0])  # no second warning: the same callable
    assert J.derivatives == "differences"
    assert len([w for w in built if w.category is DifferencesWarning]) == 1
    x_ddot = pendulum.accelerations(pendulum.q0, [0.0])[0]  # at rest: ẍ = l cos θ θ̈
    # the differences' error: measured 1.7e-13 relative (at most 1.2e-12 over four θ; was rel 1e-10)
    assert x_ddot == pytest.approx(-9.81 * np.sin(theta) * np.cos(theta), rel=1.2e-11, abs=0)


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
    have the same F, f̄ and s̈ on the constraint manifold, so their exact Jacobians agree there
    along the manifold's tangent in q and every ṡ: measured 5.0e-12 of the largest entry (bound
    10×; 1.6e-15 before the null-space form took its tangent at the state moved onto the manifold,
    whose Gauss–Newton step the complex step differentiates too). Off the manifold the partition
    takes F at the state itself: the columns across it differ."""
    from projeq.constraints.partitioned import TangentSystem

    q0, s_dot = np.array([0.6, -0.8]), [0.7]
    tangent = TangentSystem(*_pendulum_on_sliders(2), q0=q0, independent=[0])
    partitioned = pq.ConstrainedSystem(*_pendulum_on_sliders(1), q0=q0, independent=[0])
    J, K = state_jacobians(tangent, q0, s_dot, 0.2), state_jacobians(partitioned, q0, s_dot, 0.2)
    assert J.derivatives == K.derivatives == "exact"
    along = np.zeros((3, 2))  # x = (q, ṡ) moving along the circle in q, and in ṡ
    along[:2, 0], along[2, 1] = (0.8, 0.6), 1.0
    for a, b in zip(J[:5], K[:5]):
        a, b = (m @ along if np.ndim(m) == 2 and np.shape(m)[1] == 3 else m for m in (a, b))
        assert np.abs(a - b).max(initial=0.0) <= 5e-11 * np.abs(b).max(initial=1.0)


# -- the complex step through the compiled kernels (issue 16) ------------------------------------
# References: the complex step through the interpreted reference evaluators (recursive, dense for
# coupled joints: a second formulation of s̈, whose round-off differs with the conditioning), and
# the same kernel source run interpreted (compiled=False: the same algorithm in Python's complex
# arithmetic, which checks numba's complex128 specialization). Bounds of max(1, |J|), from the
# measurements in each test's docstring.


def _reference_jacobian(system, x, t, evaluator):
    """∂ẋ/∂x by the complex step column by column through ``evaluator``'s accelerations."""
    n_q = system.n_q
    return exact_jacobian(lambda y: np.concatenate((system.q_dot(y[:n_q], y[n_q:], t),
                                                    evaluator.accelerations(y[:n_q], y[n_q:], t))), x)


EPS = np.finfo(float).eps


def _relative(J, reference):
    return np.abs(J - reference).max(initial=0.0) / max(1.0, np.abs(reference).max(initial=0.0))


def _conditioning(system, q, t) -> float:
    """max(1, κ₂(M)/10⁴): how much more than a well-conditioned tree two orders of the same
    arithmetic may differ. s̈ solves M s̈ = b, whose forward error grows as κ(M) ε (Higham,
    "Accuracy and Stability of Numerical Algorithms", 2nd ed. (2002), §7.1); random trees reach
    κ ≈ 10⁵ (hypothesis found a planar–planar–revolute chain with κ = 7.8·10⁴ whose compiled and
    interpreted Jacobians differ by 1.2e-12 = 0.07 κ ε)."""
    M = system.mass_matrix(q, t)
    return max(1.0, np.linalg.cond(M) / 1e4) if M.size else 1.0


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=trees(max_n=6, kinds=("revolute", "prismatic", "fixed"), forces=False))
def test_compiled_one_call_equals_interpreted_complex_step(tree):
    """Trees the kernel computes alone (revolute, prismatic, fixed joints, gravity): all columns
    in one compiled call (kernels.tree_jacobian) = the complex step through the recursive
    evaluator to 1e-13 of max(1, |J|) (measured ≤ 1.0e-14 over 200 trees), = the same kernel
    source interpreted to 1e-13 (measured ≤ 3e-15 over 150)."""
    system, x, t = tree.system, np.concatenate((tree.q, tree.s_dot)), tree.t
    one_call = system.evaluator().state_jacobian(t, x)
    assert one_call is not None  # the compiled Jacobian, not a fall-back
    J, used = state_jacobian(system, x, t)
    assert used == "exact" and np.array_equal(J, one_call)
    assert _relative(J, _reference_jacobian(system, x, t, system.evaluator("recursive"))) <= 1e-13
    assert _relative(J, FastEvaluator(system, compiled=False).state_jacobian(t, x)) <= 1e-13


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=trees(max_n=5))
def test_compiled_column_by_column_with_every_joint_and_force_law(tree):
    """Every joint (kind GIVEN: their relative_values on complex arguments) and force law (their
    add_to on the complex workspace), coupled joints too: the complex step column by column
    through the compiled evaluator = the one through the reference evaluator to 1e-11 of
    max(1, |J|) (measured ≤ 3.1e-13, coupled ≤ 2.2e-12 over 200 trees: the two evaluators'
    round-off on ill-conditioned random trees) and = the same kernel source interpreted to 1.1e-11
    (measured ≤ 3.8e-14, coupled ≤ 1.5e-13 over 150; hypothesis found a coupled spherical–car–revolute
    chain with joint springs and forces at 1.1e-12, seed=173630040), both bounds times
    :func:`_conditioning` beyond κ(M) = 10⁴."""
    coupled = with_couplings(tree)
    for system, (q, s_dot, t) in ((tree.system, (tree.q, tree.s_dot, tree.t)),
                                  (coupled, random_state(coupled, tree.rng))):
        x = np.concatenate((q, s_dot))
        J, used = state_jacobian(system, x, t)
        assert used == "exact" and system.evaluator().name == "fast"
        reference, scale = system.evaluator("dense" if system.coupled else "recursive"), _conditioning(system, q, t)
        assert _relative(J, _reference_jacobian(system, x, t, reference)) <= 1e-11 * scale
        assert _relative(J, _reference_jacobian(system, x, t, FastEvaluator(system, compiled=False))) <= 1.1e-11 * scale


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=trees(max_n=6, kinds=("revolute", "prismatic", "fixed"), forces="constant"))
def test_compiled_one_call_with_every_compiled_force_law(tree):
    """Trees the kernel computes alone carrying every force law kind with a compiled row (forces
    and torques in world and body frames, joint forces, joint springs, spring-dampers to the
    ground and between bodies, damped): one compiled call (kernels.tree_jacobian with the loads
    loop) = the complex step column by column through the compiled evaluator to 1e-14 of
    max(1, |J|) (the same arithmetic), = the same kernel source interpreted to max(1e-13, κ(M) ε/2)
    (two orders of the same arithmetic: s̈ solves M s̈ = b, forward error ∝ κ ε, Higham (2002) §7.1;
    hypothesis found a planar chain with κ = 3.4·10³ at 1.09e-13 = 0.15 κ ε), = the
    complex step through the recursive evaluator (the laws' own add_to) to 2e-13 (measured at most
    1.2e-14 over 300 spatial and 1.9e-14 over 300 planar drawn trees, κ(M) up to 3.7e4; was 1e-11)
    and = Richardson's central differences to DIFFERENCES_TOL."""
    _check_one_call_with_laws(tree)


@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=trees(max_n=6, planar=True, kinds=("revolute", "prismatic", "fixed"), forces="constant"))
def test_compiled_one_call_with_every_compiled_force_law_on_planar_trees(tree):
    """As above on planar bodies (a selection S: the kernel loads their spatial h_n, the
    reference their selected coordinates, h_n += Sᵀ S w; no in-plane motion sees the
    difference)."""
    _check_one_call_with_laws(tree)


def _check_one_call_with_laws(tree):
    system, x, t = with_every_law(tree), np.concatenate((tree.q, tree.s_dot)), tree.t
    assert all(law.compiled_terms() is not None for law in system.forces)
    one_call = system.evaluator().state_jacobian(t, x)
    assert one_call is not None  # the compiled Jacobian, not a fall-back
    assert _relative(one_call, _reference_jacobian(system, x, t, system.evaluator())) <= 1e-14
    kappa = np.linalg.cond(system.mass_matrix(tree.q, t)) if system.n_s else 1.0
    interpreted = FastEvaluator(system, compiled=False).state_jacobian(t, x)
    assert _relative(one_call, interpreted) <= max(1e-13, kappa * EPS / 2)
    assert _relative(one_call, _reference_jacobian(system, x, t, system.evaluator("recursive"))) <= 2e-13
    _check_against_differences(system, tree.q, tree.s_dot, t)


def test_compiled_one_call_on_the_flyball_governor():
    """IFToMM A05, the flyball governor (two stiff spring-dampers, SpringDamper rows): its
    ∂ẋ/∂x in one compiled call = the complex step column by column through the compiled
    evaluator to 1e-14 and = Richardson's central differences to DIFFERENCES_TOL."""
    system = pq.scenes.flyball_governor()
    rng = np.random.default_rng(5)
    q, s_dot = np.asarray(system.q0) + 0.01 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s)
    x = np.concatenate((q, s_dot))
    one_call = system.evaluator().state_jacobian(0.3, x)
    assert one_call is not None
    assert _relative(one_call, _reference_jacobian(system, x, 0.3, system.evaluator())) <= 1e-14
    _check_against_differences(system, q, s_dot, 0.3)


def _bent_flexible_arm():
    """The state of test_beam_in_a_chain."""
    system = pq.scenes.flexible_arm()
    rng = np.random.default_rng(11)
    q = system.q0 + np.r_[0.0, 0.0, 0.0, 0.01 * rng.uniform(-1, 1, system.n_q - 3)]
    return system, np.concatenate((q, rng.uniform(-1, 1, system.n_s)))


def test_compiled_flexible_arm():
    """The flexible arm (a RitzBeam with a tip mass on its station, in a chain): one compiled call
    = the complex step column by column through the compiled evaluator exactly (the same
    arithmetic), = the same kernel source interpreted and = the complex step through the
    recursive evaluator to 1e-9 of max(1, |J|) (measured 1.2e-10 and 3.5e-11; the interpreted
    source and the recursive evaluator differ by 8e-11). The bound is the conditioning: M has
    cond(M) = 4.2e7 at this state (elastic rows up to ω² ≈ 1e7 1/s²), ε cond(M) ≈ 9e-9, while the
    real s̈ of the compiled and the interpreted source agree bit for bit."""
    system, x = _bent_flexible_arm()
    J = system.evaluator().state_jacobian(0.0, x)
    assert J is not None
    assert np.array_equal(J, _reference_jacobian(system, x, 0.0, system.evaluator()))
    assert _relative(J, FastEvaluator(system, compiled=False).state_jacobian(0.0, x)) <= 1e-9
    assert _relative(J, _reference_jacobian(system, x, 0.0, system.evaluator("recursive"))) <= 1e-9


def test_compiled_flexible_arm_with_force_laws():
    """The flexible arm with a joint spring on its shoulder, a spring-damper from the ground to
    its tip mass and a force on the beam (its reference frame): one compiled call = the complex
    step column by column through the compiled evaluator exactly, = the complex step through the
    recursive evaluator (the laws' own add_to) to 1e-9 of max(1, |J|) (measured 3.3e-10; the
    conditioning of test_compiled_flexible_arm)."""
    arm = pq.scenes.flexible_arm()
    names = list(arm.names)
    laws = [pq.JointSpring(names[0], 30.0, 1.0), pq.Force(names[1], (0.0, 1.0, 0.5), point=(0.1, 0.0, 0.0)),
            pq.SpringDamper(None, (0.2, 0.1, 0.0), names[-1], (0.0, 0.0, 0.0), 100.0, 2.0, 0.3)]
    system = pq.System(dict(zip(names, arm.subsystems)), dict(zip(names, arm.joints)), gravity=arm.gravity,
                       q0=arm.q0, forces=laws)
    rng = np.random.default_rng(1)
    x = np.r_[np.asarray(system.q0) + 0.01 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s)]
    J = system.evaluator().state_jacobian(0.2, x)
    assert J is not None
    assert np.array_equal(J, _reference_jacobian(system, x, 0.2, system.evaluator()))
    assert _relative(J, _reference_jacobian(system, x, 0.2, system.evaluator("recursive"))) <= 1e-9


@pytest.mark.parametrize("family", ["default", "clamped_free"])
def test_compiled_hub_beam(family):
    """The spin-up beam (a RitzBeam on a prescribed hub): one call of
    kernels.hub_beam_jacobian = its source interpreted to 100 ε of max(1, |J|) (measured 2.0e-15
    with the default functions, 2.6e-17 clamped–free), and, with the clamped–free functions, = the
    complex step through the interpreted path (the beam's own elastic_terms, a second formulation)
    to 100 ε (measured 2.0e-16; both bounds were 1e-13). The default functions'
    M_ee is ill-conditioned: the two paths' s̈ differ by 1.8e-11 of |s̈| already, so no
    cross-formulation bound below that is meaningful there."""
    system = pq.scenes.spin_up_beam() if family == "default" else pq.scenes.spin_up_beam(family=family, n_shapes=3)
    rng = np.random.default_rng(2)
    x, t = np.r_[0.01 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s)], 3.0
    evaluator = system.evaluator()
    J = evaluator.state_jacobian(t, x)
    assert evaluator.name == "hub_beam" and J is not None
    ev = evaluator.evaluator
    interpreted = np.empty_like(J)
    assert kernels.hub_beam_jacobian_kernel(False)(*ev._head, x, COMPLEX_STEP, *ev._tail[np.dtype(complex)],
                                                   interpreted) < 0
    eps = np.finfo(float).eps
    assert _relative(J, interpreted) <= 100 * eps, _relative(J, interpreted)
    if family != "default":
        reference = HubBeamEvaluator(system, compiled=False)
        error = _relative(J, _reference_jacobian(system, x, t, reference))
        assert error <= 100 * eps, error

"""The fast evaluator (projeq/assembly/fast.py, docs/theory.md §6 in one compiled loop) equals the
dense Gauss form (docs/theory.md §5, an independent O(N³) formulation) on random trees, with the
tolerance of tests/assembly/test_recursive_vs_dense.py (1e-10 relative to max(1, |s̈|∞)
while κ∞(M) ≤ 1e4, the forward-error bound 1e-14 κ∞(M) max(1, |s̈|∞) beyond; both are
backward stable, see that module's docstring). Both the numba-compiled kernel and the
interpreted one are checked; method="fast" is the compiled kernel or a ValueError saying
why (numba missing, a piece the kernel does not know), and method="auto" picks the best
evaluator available and says which.
"""

import types
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from strategies import trees, with_couplings, with_every_law
from test_recursive_vs_dense import _agree

import projeq as pq
from projeq.assembly import AutoEvaluator, InterpretedWarning, kernels
from projeq.assembly.beam_fast import HubBeamEvaluator
from projeq.assembly.fast import FastEvaluator
from projeq.assembly.linalg import SingularMassError
from projeq.spatial import chain_matrix, cross, rotation
from projeq.subsystems.rigid import rigid_h

HAS_NUMBA = kernels.has_numba()
# M and b summed in another order than the dense J_nᵀ M_n J_n: round-off only, relative to the
# largest entry (measured ≤ 1.9e-15 over 1000 random trees of 1–12 bodies and 0–3 coupled ones); 100 ε
# (was 1e-13). Their complex-step derivatives Im M(q + i h v)/h, Im b/h: measured ≤ 9.3e-15 over 1000
# trees of 1–8 bodies, bound 10× that (was 1e-13 too)
GAUSS_RTOL = 100 * np.finfo(float).eps
COMPLEX_GAUSS_RTOL = 9.3e-14


@given(trees(max_n=30))
def test_fast_equals_dense_on_random_trees(tree):
    """Trees of 1–30 rigid bodies on every spatial joint type (revolute, prismatic and
    fixed about random axes, which the kernel computes; planar, free, prescribed,
    spherical, screw, a non-holonomic car and a rheonomic turntable, whose ``relative``
    feeds the kernel), random joint frames, masses over four decades, and every force law
    (forces, torques in world and body frames, constant or state-dependent, joint forces,
    joint springs, spring-dampers): fast s̈ = dense s̈. The default evaluator
    (method=None, "auto") is the compiled kernel, without a warning; the interpreted kernel
    is tested below."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        assert tree.system.evaluator().name == "fast"
    _agree(tree, "auto", "dense")


@given(trees(max_n=30, planar=True))
def test_fast_equals_dense_on_planar_trees(tree):
    """Trees of PlanarBody objects (x–y plane; full inertia tensors, mass centres off the
    plane) on every planar joint and force law: the kernel evaluates the spatial terms of
    the same bodies (no selection), which equal the selected ones on motions in the plane
    (docs/theory.md §3); fast s̈ = dense s̈ (the selected reference), compiled by default
    without a warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        assert tree.system.evaluator().name == "fast"
    _agree(tree, "auto", "dense")


@given(trees(max_n=12))
def test_fast_equals_dense_with_coupled_joints(tree):
    """Random trees with up to three more bodies on coupled revolute or prismatic joints
    (shared minimal velocities): the kernel's Gauss form in every joint's own velocities,
    projected with P (M = Pᵀ M_all P, b = Pᵀ b_all), gives the s̈ of the dense Gauss form,
    which builds ∂ẏ/∂ṡ with the coupling in it (docs/theory.md §5); compiled by default."""
    system = with_couplings(tree)
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        assert system.evaluator().name == "fast"
    q, s_dot, t = tree.rng.uniform(-1, 1, system.n_q), tree.rng.uniform(-1, 1, system.n_s), tree.t
    q = system.normalized(q)
    _agree(types.SimpleNamespace(system=system, q=q, s_dot=s_dot, t=t), "auto", "dense")


@given(trees(max_n=12), st.booleans())
def test_compiled_gauss_form_equals_the_dense_one(tree, planar_or_coupled):
    """M(q) and b(q, ṡ, t) by the compiled composite-body and Newton–Euler kernel
    (projeq.assembly.kernels.gauss_form; Featherstone (2008) §5.3, §6.2) equal those of the
    dense J_nᵀ M_n J_n sums (docs/theory.md §5) to round-off, relative to their largest entries,
    on spatial trees with coupled joints; the interpreted kernel source agrees too."""
    system = with_couplings(tree) if planar_or_coupled else tree.system
    q, s_dot = system.normalized(tree.rng.uniform(-1, 1, system.n_q)), tree.rng.uniform(-1, 1, system.n_s)
    M, b = system.gauss_form(q, s_dot, tree.t)
    for compiled in ([True, False] if HAS_NUMBA else [False]):
        M_fast, b_fast = FastEvaluator(system, compiled=compiled).gauss_form(q, s_dot, tree.t)
        scale = max(1.0, np.abs(M).max(initial=0.0))
        assert M_fast.shape == M.shape and np.abs(M_fast - M).max(initial=0.0) <= GAUSS_RTOL * scale
        assert np.abs(b_fast - b).max(initial=0.0) <= GAUSS_RTOL * max(scale, np.abs(b).max(initial=0.0))


@given(trees(max_n=8), st.booleans())
def test_compiled_gauss_form_takes_the_complex_step(tree, coupled):
    """The compiled Gauss form on complex arguments (its complex128 specialization, for the
    complex step of projeq.analysis.jacobians): Im M(q + i h v)/h and Im b(q + i h v, ṡ + i h w)/h
    equal the dense sums' to round-off (COMPLEX_GAUSS_RTOL of their largest entries), along random v, w."""
    system = with_couplings(tree) if coupled else tree.system
    q, s_dot = system.normalized(tree.rng.uniform(-1, 1, system.n_q)), tree.rng.uniform(-1, 1, system.n_s)
    h, v, w = 1e-30, tree.rng.uniform(-1, 1, system.n_q), tree.rng.uniform(-1, 1, system.n_s)
    z, z_dot = q + 1j * h * v, s_dot + 1j * h * w
    M, b = (np.imag(a) / h for a in system.evaluator("dense").gauss_form(z, z_dot, tree.t))
    M_fast, b_fast = (np.imag(a) / h for a in FastEvaluator(system, compiled=HAS_NUMBA).gauss_form(z, z_dot, tree.t))
    scale = max(1.0, np.abs(M).max(initial=0.0))
    assert np.abs(M_fast - M).max(initial=0.0) <= COMPLEX_GAUSS_RTOL * scale
    assert np.abs(b_fast - b).max(initial=0.0) <= COMPLEX_GAUSS_RTOL * max(scale, np.abs(b).max(initial=0.0))


@settings(max_examples=max(5, settings().max_examples // 5))
@given(trees(max_n=8))
def test_interpreted_kernel_equals_dense(tree):
    """The pure-numpy fallback (the same kernel source, not compiled) = dense s̈, tested
    whether numba is installed or not (fewer, smaller trees: it runs ~300 µs per body)."""
    tree.system._evaluators["fast"] = FastEvaluator(tree.system, compiled=False)
    assert not tree.system.evaluator("fast").compiled
    _agree(tree, "fast", "dense")


@pytest.mark.skipif(not HAS_NUMBA, reason="numba is not installed")
def test_the_kernel_is_compiled_unless_asked_otherwise(monkeypatch):
    """The interpreted kernel only on request (compiled=False); no environment variable
    switches it (the former PROJEQ_FAST_KERNEL=python is ignored), and compiling rebinds
    nothing in projeq.assembly.kernels (its functions stay plain Python)."""
    monkeypatch.setenv("PROJEQ_FAST_KERNEL", "python")
    plain = {name: getattr(kernels, name) for name in dir(kernels) if callable(getattr(kernels, name))}
    system = pq.scenes.chain(2)
    assert system.evaluator("fast").compiled is True and FastEvaluator(system).compiled is True
    assert FastEvaluator(system, compiled=False).compiled is False
    assert {name: getattr(kernels, name) for name in plain} == plain
    assert all(type(f) is types.FunctionType for f in (kernels.chain_terms, kernels.passes, kernels._rigid_h))


def test_without_numba_fast_is_refused_and_auto_picks_the_recursive_evaluator(monkeypatch):
    """The interpreted kernel is slower than the recursive evaluator, so without numba
    method="fast" raises saying so, and method="auto" picks the recursive evaluator and
    says why; the interpreted kernel still runs on request (compiled=False)."""
    monkeypatch.setattr(kernels, "_numba", lambda: None)
    system = pq.scenes.chain(2)
    with pytest.raises(ValueError, match="numba is not installed"):
        system.evaluator("fast")
    auto = AutoEvaluator(system)
    assert auto.name == "recursive" and "numba is not installed" in auto.reason
    q, s_dot = np.array([0.3, -0.2]), np.array([0.1, 0.5])
    np.testing.assert_array_equal(auto.accelerations(q, s_dot, 0.0), system.accelerations(q, s_dot, method="recursive"))
    assert FastEvaluator(system, compiled=False).compiled is False


def test_compiled_without_numba_is_refused(monkeypatch):
    monkeypatch.setattr(kernels, "_numba", lambda: None)
    with pytest.raises(ValueError, match="compiled: numba is not installed"):
        FastEvaluator(pq.scenes.chain(2), compiled=True)


# measured over 500 seeds: ≤ 1.3e-15 relative (rigid h), ≤ 8e-16 (rotation); the kernel
# writes the same formulas as scalar sums in another order, so only round-off differs
TWIN_RTOL = 5e-15


@pytest.mark.parametrize("seed", range(20))
def test_the_kernel_twins_equal_their_array_forms(seed):
    """The kernel's scalar twins (projeq/assembly/kernels.py, "Compiled twins") equal the
    one numeric home of each formula: Rodrigues' rotation (projeq.spatial.rotation; E for
    prismatic and fixed joints), T_np (spatial.chain_matrix), a × b (spatial.cross) and the
    rigid-body h of docs/theory.md §3 (projeq.subsystems.rigid.rigid_h)."""
    rng = np.random.default_rng(seed)
    e = rng.standard_normal(3)
    e /= np.linalg.norm(e)
    x, r = rng.uniform(-np.pi, np.pi), rng.uniform(-2, 2, 3)
    A = np.empty((3, 3))
    for kind in (kernels.PRISMATIC, kernels.FIXED):
        kernels._relative_rotation(kind, e, x, A)
        assert np.array_equal(A, np.eye(3))
    kernels._relative_rotation(kernels.REVOLUTE, e, x, A)
    assert np.abs(A - rotation(e, x)).max() <= TWIN_RTOL
    T = np.empty((6, 6))
    kernels.chain_matrix_into(A, r, T)
    assert np.abs(T - chain_matrix(A, r)).max() <= TWIN_RTOL * np.abs(T).max()
    a, b = rng.uniform(-3, 3, (2, 3))
    out = np.array([0.5, -1.0, 2.0])
    kernels.add_cross(a, b, out)
    assert np.abs(out - ([0.5, -1.0, 2.0] + cross(a, b))).max() <= TWIN_RTOL * 10
    m, r_c, L = 10 ** rng.uniform(-2, 2), rng.uniform(-1, 1, 3), rng.standard_normal((3, 3))
    I_c, twist, g = m * L @ L.T, rng.uniform(-3, 3, 6), rng.uniform(-10, 10, 3)
    h = np.empty(6)
    kernels._rigid_h(m, r_c, I_c, twist, g, h, np.empty((2, 3)))
    expected = rigid_h(m, r_c, I_c, twist, g)
    assert np.abs(h - expected).max() <= TWIN_RTOL * np.abs(expected).max()


@pytest.mark.parametrize("name", ["rolling_disk", "knife_edge_disc", "barhorst_particle", "nonholonomic_particle",
                                  "car"])
def test_a_sympy_joints_scalar_code_equals_its_relative(name):
    """A UserJoint from sympy states relative_values (what the kernel reads for a joint of kind
    GIVEN) as scalar code of the same expressions as its numpy ``relative``: the same numbers
    to round-off at random states and times; a subclass that restates ``relative`` gets the
    packed default back (its override is never bypassed)."""
    joint = pq.scenes.SCENES[name].build().joints[0]
    rng = np.random.default_rng(8)
    for _ in range(5):
        q_n, s_dot_n, t = rng.uniform(-1, 1, joint.n_q), rng.uniform(-2, 2, joint.n_s), rng.uniform(0, 3)
        rel = joint.relative(q_n, s_dot_n, t)
        packed = np.concatenate((rel.A.ravel(), rel.r, rel.w, rel.zeta, rel.F.T.ravel()))
        values = np.asarray(joint.relative_values(q_n, s_dot_n, t), dtype=float)
        assert values.shape == packed.shape
        assert np.abs(values - packed).max() <= 1e-14 * max(1.0, np.abs(packed).max())

    class Restated(pq.UserJoint):
        def relative(self, q_n, s_dot_n, t):
            return super().relative(q_n, s_dot_n, t)

    assert Restated.relative_values is pq.joints.Joint.relative_values


@pytest.mark.parametrize("name", ["rolling_disk", "knife_edge_disc", "car"])
def test_a_sympy_joints_scalar_rates_equal_K_s_dot(name):
    """q̇ = K ṡ of a UserJoint from sympy, as scalar code at real arrays, equals K(q) ṡ from its
    own lambdified K; complex arguments (a complex step) take the numpy form and agree."""
    joint = pq.scenes.SCENES[name].build().joints[0]
    rng = np.random.default_rng(3)
    for _ in range(5):
        q_n, s_dot_n, t = rng.uniform(-1, 1, joint.n_q), rng.uniform(-2, 2, joint.n_s), rng.uniform(0, 3)
        expected = joint.K(q_n, t) @ s_dot_n
        q_dot = joint.q_dot(q_n, s_dot_n, t)
        assert q_dot.dtype == float and np.abs(q_dot - expected).max() <= 1e-14 * max(1.0, np.abs(expected).max())
        complex_q_dot = joint.q_dot(q_n + 0j, s_dot_n, t)
        assert np.iscomplexobj(complex_q_dot) and np.abs(complex_q_dot - expected).max() <= 1e-14 * max(
            1.0, np.abs(expected).max())


def test_the_kernel_takes_massless_frames():
    """A Frame states rigid-body terms of zero mass (``rigid_inertia``), so a universal joint
    (two revolutes through a Frame) is compiled and equals the recursive evaluator."""
    system = pq.System(
        {"cross": pq.Frame(), "bob": pq.RigidBody(2.0, (0, 0, -1), np.diag([0.1, 0.2, 0.3]))},
        {"cross": pq.Revolute(axis="x"), "bob": pq.Revolute(parent="cross", axis="y")},
        gravity=(0, 0, -9.81), q0=[0.3, 0.5], s_dot0=[1.0, -2.0],
    )
    ev = FastEvaluator(system, compiled=False)  # the kernel's source, with or without numba: not refused
    np.testing.assert_allclose(ev.accelerations(system.q0, system.s_dot0, 0.0),
                               system.accelerations(system.q0, system.s_dot0, method="recursive"),
                               rtol=100 * np.finfo(float).eps, atol=0)  # measured 2e-16 relative (was 1e-13)


class _OwnTerms(pq.RigidBody):
    """A rigid body that restates its Gauss-form terms (the same ones): the kernel cannot know
    what an overridden ``gauss_terms`` computes, so it has no ``rigid_inertia``."""

    def gauss_terms(self, y_dot, R, gravity, q_e=None):
        return super().gauss_terms(y_dot, R, gravity, q_e)


def _own_terms_on_a_rope():
    """The Atwood machine (coupled joints) with a pulley of its own gauss_terms."""
    system = pq.scenes.atwood()
    subsystems = dict(zip(system.names, system.subsystems))
    pulley = subsystems["pulley"]
    subsystems["pulley"] = _OwnTerms(pulley.m, pulley.r_c, pulley.I_c)
    return pq.System(subsystems, dict(zip(system.names, system.joints)), gravity=system.gravity)


@pytest.mark.parametrize(
    ("build", "reason"),
    [
        (lambda: pq.System({"rod": _OwnTerms(1.0, (0, 0, -0.5), np.eye(3) * 0.1)}, {"rod": pq.Revolute(axis="y")},
                           gravity=(0, 0, -9.81)), "_OwnTerms"),
        (_own_terms_on_a_rope, "_OwnTerms"),
    ],
    ids=["overridden gauss_terms", "overridden gauss_terms, coupled joints"],
)
def test_unsupported_systems_are_refused_and_auto_picks_the_general_path(build, reason):
    """Unknown pieces: method="fast" raises naming the piece; the default evaluator
    (method=None, "auto") picks the general evaluator, says why once (one
    InterpretedWarning naming the piece, however often it is called), and its s̈ is
    exactly the general evaluator's (it is the same call)."""
    system = build()
    with pytest.raises(ValueError, match=f"^system: the fast kernel cannot evaluate it: .*{reason}"):
        system.evaluator("fast")
    general = "dense" if system.coupled else "recursive"
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        ev = system.evaluator()
        assert system.evaluator("auto") is ev
        system.accelerations(system.q0, system.s_dot0)
    assert ev.name == general and reason in ev.reason
    assert [type(w.message) for w in said] == [InterpretedWarning]
    assert f"interpreted {general!r} evaluator" in str(said[0].message) and reason in str(said[0].message)
    rng = np.random.default_rng(3)
    q, s_dot = system.normalized(system.q0 + 0.1 * rng.standard_normal(system.n_q)), rng.standard_normal(system.n_s)
    np.testing.assert_array_equal(system.accelerations(q, s_dot, 0.2, method="auto"),
                                  system.accelerations(q, s_dot, 0.2, method=general))


def test_workspace_reuse_gives_identical_results():
    """One evaluator called at many states returns bit for bit what a new one returns (the
    compiled kernel, or without numba the interpreted one)."""
    system = pq.scenes.chain(12)
    ev, rng = FastEvaluator(system, compiled=HAS_NUMBA), np.random.default_rng(5)
    states = [(rng.uniform(-2, 2, 12), rng.uniform(-2, 2, 12)) for _ in range(4)]
    reused = [ev.accelerations(q, s_dot, 0.0) for q, s_dot in states]
    for (q, s_dot), a in zip(states, reused):
        np.testing.assert_array_equal(a, FastEvaluator(system, compiled=HAS_NUMBA).accelerations(q, s_dot, 0.0))


@pytest.mark.parametrize("compiled", [False, True] if HAS_NUMBA else [False])
def test_zero_pivot_raises_singular_mass_error(compiled):
    """A point mass on its own revolute axis moves no inertia: D_n = 0, as in recursive."""
    system = pq.System({"p": pq.PointMass(1.0, (0, 0, 0))}, {"p": pq.Revolute(axis="z")})
    with pytest.raises(SingularMassError, match="'p'"):
        FastEvaluator(system, compiled=compiled).accelerations(np.zeros(1), np.zeros(1), 0.0)


@pytest.mark.parametrize("compiled", [False, True] if HAS_NUMBA else [False])
def test_zero_pivot_with_coupled_joints_raises_singular_mass_error(compiled):
    """Two point masses on their revolute axes, one following the other (a gear): M = 0."""
    system = pq.System({"p": pq.PointMass(1.0), "g": pq.PointMass(2.0)},
                       {"p": pq.Revolute(axis="z"), "g": pq.Revolute(axis="z", r_pn=(1, 0, 0), coupling={"p": -2.0})})
    with pytest.raises(SingularMassError, match="system mass matrix M"):
        FastEvaluator(system, compiled=compiled).accelerations(np.zeros(1), np.zeros(1), 0.0)


@pytest.mark.skipif(not HAS_NUMBA, reason="the one-call ẋ is compiled")
@settings(max_examples=20, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(tree=trees(max_n=6, kinds=("revolute", "prismatic", "fixed"), forces="constant"))
def test_state_derivative_in_one_call(tree):
    """simulate's right-hand side ẋ = (q̇, s̈) in one compiled call (kernels.tree_state_derivative)
    on trees the kernel computes alone carrying every compiled force law: bit for bit the model's
    q̇ = K ṡ (K = E) and the compiled s̈ (the same arithmetic, tested against the dense Gauss form
    above), = the same kernel source interpreted to 1e-13 of max(1, |ẋ|∞); None where the state is
    not finite (simulate's checked evaluation then names it) and for a complex state."""
    system = with_every_law(tree)
    q, s_dot, t = tree.q, tree.s_dot, tree.t
    x = np.concatenate((q, s_dot))
    x_dot = system.evaluator().state_derivative(t, x)
    assert x_dot is not None  # the one compiled call, not a fall-back
    np.testing.assert_array_equal(x_dot, np.concatenate((system.q_dot(q, s_dot, t),
                                                         system.evaluator().accelerations(q, s_dot, t))))
    interpreted = FastEvaluator(system, compiled=False).state_derivative(t, x)
    assert np.abs(x_dot - interpreted).max(initial=0.0) <= 1e-13 * max(1.0, np.abs(x_dot).max(initial=0.0))
    assert system.evaluator().state_derivative(t, x.astype(complex)) is None
    if x.size:  # (a tree of fixed joints has no state)
        x[-1] = np.nan
        assert system.evaluator().state_derivative(t, x) is None


def test_simulate_with_the_fast_evaluator():
    """simulate(..., evaluator="auto") (the compiled kernel with numba) follows the
    recursive run (same integrator steps up to round-off: the trajectories agree far below
    rtol = 1e-8: measured 1.7e-14, and at most that over chain(3), chain(6), 2 s and rtol 1e-9; the
    bound 2e-13 is 10 times it, was 1e-9)."""
    system = pq.scenes.chain(4)
    a = pq.simulate(system, 1.0, evaluator="auto", rtol=1e-8, atol=1e-10, n_points=11)
    b = pq.simulate(system, 1.0, evaluator="recursive", rtol=1e-8, atol=1e-10, n_points=11)
    np.testing.assert_allclose(a.q, b.q, rtol=0, atol=2e-13)


def _tilted_hub_beam(precomputed, stiffening=True):
    """A beam with axial, torsional and rotary terms, damping and gravity, on a hub that
    turns about a tilted axis away from the origin (every term of the hub path in play)."""
    beam = pq.RitzBeam(
        1.5, 2.0, 30.0, EI_y=40.0, EA=900.0, GI_t=5.0, rho_I=(1e-3, 2e-3), n_v=3, n_w=2, n_u=1, n_beta=1,
        family="clamped_free", damping=0.01, stiffening=stiffening, precomputed_integrals=precomputed,
    )
    tilt = np.linalg.qr(np.random.default_rng(7).standard_normal((3, 3)))[0]
    tilt *= np.linalg.det(tilt)  # a proper rotation
    hub = pq.Prescribed(pq.Revolute(axis="z", r_pn=(0.2, -0.1, 0.3), orientation=tilt),
                        lambda t: (0.3 * t**2, 0.6 * t, 0.6))
    return pq.System({"beam": beam}, {"beam": hub}, gravity=(0, 0, -9.81))


def _tilted_plain_beam(inner):
    """A beam without rotary inertia (damping, axial, gravity) on a Prescribed Revolute or
    Prismatic about a tilted axis away from the origin (the compiled hub path's kinds)."""
    beam = pq.RitzBeam(1.2, 1.5, 25.0, EI_y=35.0, EA=800.0, n_v=3, n_w=2, n_u=1, family="clamped_free",
                       damping=0.02)
    tilt = np.linalg.qr(np.random.default_rng(3).standard_normal((3, 3)))[0]
    tilt *= np.linalg.det(tilt)
    hub = pq.Prescribed(inner(axis=(0.3, -0.5, 0.8), r_pn=(0.1, 0.2, -0.1), orientation=tilt),
                        lambda t: (0.4 * t**2, 0.8 * t, 0.8))
    return pq.System({"beam": beam}, {"beam": hub}, gravity=(0, 0, -9.81))


def _clamped_beam():
    """A beam on a Fixed joint to the ground, bent by gravity (precomputed, no rotary)."""
    beam = pq.RitzBeam(2.0, 1.0, 20.0, n_v=2, n_w=3, family="polynomial", precomputed_integrals=True)
    return pq.System({"beam": beam}, {"beam": pq.Fixed(orientation=rotation(np.array([0.0, 1.0, 0.0]), 0.4))},
                     gravity=(0, 0, -9.81))


@pytest.mark.parametrize(
    "build",
    [
        lambda: pq.scenes.spin_up_beam(omega_s=4.0, n_shapes=3, family="clamped_free"),
        lambda: pq.scenes.spin_up_beam(omega_s=4.0, n_shapes=3, precomputed_integrals=True),
        lambda: _tilted_hub_beam(False),
        lambda: _tilted_hub_beam(True),
        lambda: _tilted_hub_beam(True, stiffening=False),
        _clamped_beam,
    ],
    ids=["spin-up", "spin-up precomputed", "tilted hub", "tilted hub precomputed", "unstiffened", "fixed root"],
)
def test_hub_beam_path_equals_recursive(build):
    """One RitzBeam on a prescribed or fixed hub goes through its own evaluator
    (method="hub_beam", projeq/assembly/beam_fast.py: M_ee q̈ = h_e − M_eR ζ, no chain, no
    passes), which "auto" picks, and "fast" (the order-n kernel's elastic block, rotary
    inertia and torsion included) takes too; each equals the recursive evaluator
    (docs/theory.md §6) to round-off (1e-10 of max(1, |s̈|∞)) at deformed, moving states and
    several times."""
    system = build()
    assert system.evaluator("auto").name == "hub_beam"
    methods = ["hub_beam", "fast"]
    rng = np.random.default_rng(4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # the unstiffened beam may spin too fast: said once
        for t in (0.3, 2.0, 7.5):
            q, s_dot = 0.05 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s)
            recursive = system.accelerations(q, s_dot, t, method="recursive")
            for method in methods:
                fast = system.accelerations(q, s_dot, t, method=method)
                assert np.abs(fast - recursive).max() <= 1e-10 * max(1.0, np.abs(recursive).max())


@pytest.mark.parametrize(
    "build",
    [lambda: pq.scenes.spin_up_beam(omega_s=4.0), lambda: _tilted_hub_beam(True), _clamped_beam,
     lambda: pq.scenes.spin_up_beam(omega_s=4.0, n_shapes=3, n_axial=2, gravity=9.81, precomputed_integrals=True),
     lambda: _tilted_plain_beam(pq.Revolute), lambda: _tilted_plain_beam(pq.Prismatic)],
    ids=["spin-up", "tilted hub rotary", "fixed root", "spin-up axial, gravity", "tilted revolute", "tilted prismatic"],
)
def test_hub_beam_compiled_equals_interpreted(build):
    """The compiled hub path (projeq/assembly/kernels.py hub_beam: the elastic block's slice
    sums and rotary terms, M_ee by Cholesky) equals the interpreted one (the beam's
    elastic_terms by its integration strategy, numpy's solve) to round-off, rotary inertia and
    torsion included, and its ẋ in one call (``state_derivative``, what simulate calls) is
    (ṡ, s̈) of ``accelerations``."""
    system = build()
    compiled, interpreted = HubBeamEvaluator(system), HubBeamEvaluator(system, compiled=False)
    assert compiled.compiled and not interpreted.compiled
    rng = np.random.default_rng(11)
    for t in (0.3, 2.0, 17.0):
        q, s_dot = 0.05 * rng.standard_normal(system.n_q), rng.standard_normal(system.n_s)
        reference = interpreted.accelerations(q, s_dot, t)
        fast = compiled.accelerations(q, s_dot, t)
        assert np.abs(fast - reference).max() <= 1e-10 * max(1.0, np.abs(reference).max())
        x_dot = compiled.state_derivative(t, np.concatenate((q, s_dot)))
        np.testing.assert_array_equal(x_dot, np.concatenate((s_dot, fast)))
    assert compiled.state_derivative(0.0, np.full(2 * system.n_s, np.nan)) is None  # the driver's checks name it


def test_hub_beam_evaluator_refuses_other_systems():
    with pytest.raises(ValueError, match="system: the system has 2 subsystems"):
        HubBeamEvaluator(pq.scenes.chain(2))


def _layouts(types) -> set:
    """(layout, mutable) of every array among numba ``types`` (tuples opened)."""
    found = set()
    for t in types:
        if hasattr(t, "layout"):
            found.add((t.layout, t.mutable))
        elif hasattr(t, "types"):
            found |= _layouts(t.types)
    return found


def test_kernels_are_specialised_once_per_dtype():
    """numba compiles a dispatcher once per tuple of argument types, an array's layout and
    mutability included (numba documentation, "Compiling Python code with @jit": lazy
    compilation, one specialisation per input type), 10–30 s each on a clean checkout: one
    body (a transposed view would be F-contiguous), several bodies, a beam in a chain (F wider
    than 6), a joint stating its own motion, read-only and strided states must all reach the
    chain-terms kernel with C-contiguous arrays, writeable except the model's constants."""
    chain_terms = kernels.kernel(True)[0]
    for name in ("simple_pendulum", "chain", "elastic_arm", "car"):
        system = pq.scenes.SCENES[name].build()
        ev = system.evaluator("fast")
        q, s_dot = np.asarray(system.q0, dtype=float), np.asarray(system.s_dot0, dtype=float) + 0.1
        frozen = q.copy()
        frozen.flags.writeable = False
        strided = np.repeat(s_dot, 2)[::2]
        for state in ((q, s_dot), (frozen, strided), (q + 0j, s_dot)):
            ev.accelerations(*state, 0.0)
    layouts = _layouts(a for signature in chain_terms.signatures for a in signature)
    assert {layout for layout, _ in layouts} == {"C"}, layouts
    states = {(signature[4].layout, signature[4].mutable, signature[5].mutable) for signature in chain_terms.signatures}
    assert states == {("C", True, True)}, states
    assert len(chain_terms.signatures) <= 2, chain_terms.signatures


@pytest.mark.parametrize("name", ["fast", "recursive", "dense"])
def test_an_evaluator_counts_each_call(name):
    """``n_calls`` (the evaluations that benchmarks/jacobians.py and the trade-off study count) rises by
    one for each accelerations or gauss_form call."""
    system = pq.scenes.chain(3)
    evaluator = system.evaluator(name)
    evaluator.accelerations(system.q0, system.s_dot0, 0.0)
    assert evaluator.n_calls == 1
    if hasattr(evaluator, "gauss_form"):
        evaluator.gauss_form(system.q0, system.s_dot0, 0.0)
        assert evaluator.n_calls == 2

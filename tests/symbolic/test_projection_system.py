"""``projeq.symbolic.gauss_form(system)``: symbolic == numeric on random trees (STYLE §0.5) and
scenes with every kind of joint, closed forms with symbolic parameters, refusal of what
the symbolic chain does not cover."""

import numpy as np
import pytest
import sympy as sp
from hypothesis import HealthCheck, assume, given, settings

import projeq as pq
from projeq.symbolic import gauss_form
from tests.strategies import spherical_joint, trees

# the symbolic and the numeric evaluators are two double-precision evaluations of the same
# equations for ≤ 3 bodies with masses in [1e-2, 1e2]: round-off ~1e-13 relative to the
# largest entry; 1e-9 covers the conditioning of M (mass ratios up to 1e4) with margin
RTOL = 1e-9


def assert_equal_to_numeric(system, gauss, q, s_dot, t=0.0):
    """M and s̈ of the compiled symbolic Gauss form = the numeric dense Gauss form and both
    numeric evaluators (recursive only for uncoupled systems) at (q, ṡ, t)."""
    evaluator = gauss.evaluator()
    M, _ = evaluator.gauss_form(q, s_dot, t)
    M_ref, _ = system.gauss_form(q, s_dot, t)
    assert np.allclose(M, M_ref, rtol=0, atol=RTOL * np.abs(M_ref).max())
    s_ddot = evaluator.accelerations(q, s_dot, t)
    for method in ("dense",) if system.coupled else ("recursive", "dense"):
        reference = system.accelerations(q, s_dot, t, method=method)
        assert np.allclose(s_ddot, reference, rtol=RTOL, atol=RTOL * np.abs(reference).max())


SLOW_OK = [HealthCheck.too_slow]


@settings(max_examples=10, deadline=None, suppress_health_check=SLOW_OK)
@given(trees(max_n=2, kinds=("revolute", "prismatic", "fixed", "planar", "free"), scleronomic=True, forces="constant"))
def test_symbolic_equals_numeric_on_random_spatial_trees(tree):
    """Random trees (STYLE §0.5; ≤ 2 bodies: three free bodies with general float axes take
    seconds to compile) of revolute, prismatic, planar, free (quaternion) and fixed
    joints with random axes, offsets, orientations, masses, inertias, gravity and force laws
    with constant loads (forces, torques, joint forces, damped springs): the symbolic Gauss
    form equals the numeric dense one and both numeric evaluators at a random state."""
    system = tree.system
    assume(system.n_s > 0)  # a system of Fixed joints only has no equations of motion
    assert_equal_to_numeric(system, gauss_form(system), tree.q, tree.s_dot, tree.t)


@settings(max_examples=10, deadline=None, suppress_health_check=SLOW_OK)
@given(trees(max_n=3, planar=True, kinds=("revolute", "prismatic", "fixed", "planar", "car_sympy"),
             scleronomic=True, forces="constant"))
def test_symbolic_equals_numeric_on_random_planar_trees(tree):
    """Planar trees of PlanarBody subsystems, including Bremer's non-holonomic car joint built
    with ``UserJoint.from_sympy`` (B(11)): symbolic = numeric dense and recursive."""
    system = tree.system
    assume(system.n_s > 0)
    assert_equal_to_numeric(system, gauss_form(system), tree.q, tree.s_dot, tree.t)


@pytest.mark.parametrize("scene", ["chain_planar", "car", "knife_edge_disc", "rolling_disk"])
def test_scenes_symbolic_equals_numeric(scene):
    """PlanarBody chain, the car (UserJoint.from_sympy with constant body force and torque),
    the knife-edge disc and Barhorst's rolling disk (non-holonomic user joints): symbolic =
    numeric at a random state near the scene's initial one."""
    system = {"chain_planar": lambda: pq.scenes.chain(3, planar=True),
              "car": lambda: pq.scenes.car(f_x=100.0, M_z=20.0, f_y=-50.0),
              "knife_edge_disc": pq.scenes.knife_edge_disc, "rolling_disk": pq.scenes.rolling_disk}[scene]()
    rng = np.random.default_rng(3)
    q = system.q0 + 0.3 * rng.uniform(-1, 1, system.n_q)
    assert_equal_to_numeric(system, gauss_form(system), q, rng.uniform(-1, 1, system.n_s))


def test_atwood_coupled_joints_give_the_closed_form():
    """Atwood machine (``scenes.atwood``, Problem 1 of the Lagrange problem book): the masses'
    prismatic joints are coupled to the pulley angle θ (shared minimal velocity). With
    symbolic masses m₁, m₂, pulley inertia I and g: M = I + (m₁ + m₂) a², rhs = −(m₁ − m₂) g a
    (mass 1 rises by a θ); and symbolic = numeric dense at a random state."""
    m1, m2, I, g = sp.symbols("m_1 m_2 I g", positive=True)
    system = pq.scenes.atwood()
    a = 0.1  # the scene's default pulley radius, the coupling ratio
    gauss = gauss_form(system, {"mass1.m": m1, "mass2.m": m2, "pulley.I_c": sp.diag(0, I, 0),
                                "gravity": (0, 0, -g)})
    residual = [gauss.M[0, 0] - (I + (m1 + m2) * a**2), gauss.rhs[0] + (m1 - m2) * g * a]
    rng = np.random.default_rng(4)
    for _ in range(3):
        values = dict(zip((m1, m2, I, g), rng.uniform(0.5, 3.0, 4)))
        # the ratio a = 0.1 is a binary float: a² is exact to ~1e-17; values are O(1)
        assert max(abs(float(r.subs(values))) for r in residual) < 1e-14
    assert_equal_to_numeric(system, gauss_form(system), [0.3], [-0.7])


def test_prescribed_joint_and_massless_frame():
    """A rheonomic arm: a revolute joint whose angle is prescribed as θ(t) = 0.5 sin 2t
    carries, through a massless Frame on a slider, a pendulum bob. The motion is given to
    ``gauss_form`` as a sympy expression (the joint keeps only its compiled function);
    symbolic = numeric dense and recursive at t = 0.7 (the f⁶, ζ terms of docs/theory.md §4)."""
    time = sp.Symbol("t")
    motion = sp.sin(2 * time) / 2
    system = pq.System(
        {"arm": pq.RigidBody(2.0, (0.3, 0.0, 0.0), np.diag([0.01, 0.05, 0.05])), "slider": pq.Frame(),
         "bob": pq.PointMass(0.5, (0.0, 0.0, -0.4))},
        {"arm": pq.Prescribed(pq.Revolute(axis="z"), motion), "slider": pq.Prismatic("arm", axis="x"),
         "bob": pq.Revolute("slider", axis="y", r_pn=(0.2, 0.0, 0.0))},
        gravity=(0.0, 0.0, -9.81))
    gauss = gauss_form(system, {"arm.motion": motion})
    assert gauss.parameters == ()
    assert_equal_to_numeric(system, gauss, [0.2, 0.4], [0.3, -1.1], t=0.7)
    with pytest.raises(ValueError, match="^parameters: joint 'arm' \\(Prescribed\\) needs its motion"):
        gauss_form(system)
    with pytest.raises(ValueError, match="^parameters: 'bob.motion' is for Prescribed joints"):
        gauss_form(system, {"arm.motion": motion, "bob.motion": motion})


def test_double_pendulum_with_symbolic_parameters_is_the_closed_form():
    """Problem 8 of the Lagrange problem book (``scenes.double_pendulum``): for point masses
    m₁, m₂ on rods l₁, l₂, θ₂ relative, M = [[(m₁+m₂)l₁² + m₂l₂² + 2m₂l₁l₂ cos θ₂,
    m₂l₂² + m₂l₁l₂ cos θ₂], [·, m₂l₂²]]; the parameters are given as sympy symbols."""
    m1, m2, l1, l2, g = sp.symbols("m_1 m_2 l_1 l_2 g", positive=True)
    gauss = gauss_form(pq.scenes.double_pendulum(), {
        "bob1.m": m1, "bob2.m": m2, "bob1.r_c": (0, 0, -l1), "bob2.r_c": (0, 0, -l2),
        "bob2.r_pn": (0, 0, -l1), "gravity": (0, 0, -g),
    })
    theta2 = gauss.q[1]
    c = sp.cos(theta2)
    expected = sp.Matrix([[(m1 + m2) * l1**2 + m2 * l2**2 + 2 * m2 * l1 * l2 * c, m2 * l2**2 + m2 * l1 * l2 * c],
                          [m2 * l2**2 + m2 * l1 * l2 * c, m2 * l2**2]])
    assert sp.simplify(gauss.M - expected) == sp.zeros(2, 2)
    assert set(gauss.parameters) == {m1, m2, l1, l2, g}
    # at rest the right-hand side is the gravity torque: −(m₁+m₂) g l₁ sin θ₁ − m₂ g l₂ sin(θ₁+θ₂), −m₂ g l₂ sin(θ₁+θ₂)
    theta1 = gauss.q[0]
    rest = gauss.rhs.subs({s_k: 0 for s_k in gauss.s})
    gravity = sp.Matrix([-(m1 + m2) * g * l1 * sp.sin(theta1) - m2 * g * l2 * sp.sin(theta1 + theta2),
                         -m2 * g * l2 * sp.sin(theta1 + theta2)])
    assert sp.simplify(rest - gravity) == sp.zeros(2, 1)


def test_coordinates_are_named_by_the_system():
    """The symbols of q and ṡ carry the coordinates' names (bob1.angle → bob1_angle), so that
    printed equations read as the model; names that would coincide fall back to q_1, q_2."""
    from projeq.symbolic.system import named_symbols

    gauss = gauss_form(pq.scenes.double_pendulum())
    names = ["bob1_angle", "bob2_angle", "bob1_angle_dot", "bob2_angle_dot"]
    assert [str(x) for x in (*gauss.q, *gauss.s)] == names
    assert "bob2_angle" in str(gauss.M) and "q_" not in str(gauss.M)
    assert named_symbols(["a.b_c", "a_b.c"], "q") == sp.symbols("q_1 q_2")
    assert named_symbols(["1st.x"], "s") == (sp.Symbol("s_1"),)


def test_callable_loads_and_functions_are_refused():
    """Loads and joints given as numeric callables have no expressions: refused by name."""
    body = {"b": pq.RigidBody(1.0, I_c=np.eye(3))}
    push = pq.Force("b", lambda t, q, s_dot: (0.0, np.sin(t), 0.0))
    pushed = pq.System(body, {"b": pq.Revolute()}, forces=[push])
    with pytest.raises(ValueError, match="^system: forces\\[0\\] \\(Force\\) has a callable force"):
        gauss_form(pushed)
    spherical = pq.System(body, {"b": spherical_joint()})
    with pytest.raises(ValueError, match="^system: joint 'b' \\(UserJoint from callables\\)"):
        gauss_form(spherical)


def test_bad_parameters_are_named():
    system = pq.scenes.double_pendulum()
    with pytest.raises(ValueError, match="^parameters: unknown key 'bob3.m'"):
        gauss_form(system, {"bob3.m": sp.Symbol("m")})
    with pytest.raises(ValueError, match=r"^parameters: 'bob1.r_c' must have shape \(3, 1\)"):
        gauss_form(system, {"bob1.r_c": (0, sp.Symbol("l"))})

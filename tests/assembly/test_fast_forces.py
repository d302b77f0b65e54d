"""The force laws in the fast evaluator's compiled code (projeq/assembly/loads.py): every law of
projeq/forces.py with constant loads or stated terms is a row of the compiled loop, which
calls the statement the law's ``add_to`` calls for the reference evaluators. Checked against
independent references: the dense Gauss form and the recursive evaluator on random trees
carrying every law kind (spatial and planar bodies), the closed form B(9) of Bremer's car
(H. Bremer, *Elastic Multibody Dynamics: A Direct Ritz Approach*, Springer 2008/2009, §2.2:
m v̇_x − m c ω_z² = f_x, C° ω̇_z + m c v_x ω_z = M_z + c f_y), and, for the laws that stay in
Python (a user's subclass), the reference evaluators' numbers. Tolerances
are those of tests/assembly/test_recursive_vs_dense.py (``_agree``).
"""

import types
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from strategies import random_state, trees, with_every_law
from test_fast_beams import trees_with_beams
from test_recursive_vs_dense import _agree

import projeq as pq
from projeq.assembly import InterpretedWarning, kernels, loads
from projeq.assembly.fast import FastEvaluator

pytestmark = pytest.mark.skipif(not kernels.has_numba(), reason="numba is not installed")

#: the compiled loads against the reference evaluators' at one state: round-off (measured at most 3.7e-16
#: relative for the car's B(9), the bound pendulum, the stiffer spring and the quiet damper; was 1e-12)
EXACT = 100 * np.finfo(float).eps


def _check(system, rng):
    """Every law has a compiled row; compiled fast s̈ = dense s̈ = recursive s̈ at a random state."""
    assert all(law.compiled_terms() is not None for law in system.forces)
    q, s_dot, t = random_state(system, rng)
    state = types.SimpleNamespace(system=system, q=q, s_dot=s_dot, t=t)
    _agree(state, "fast", "dense")
    _agree(state, "fast", "recursive")


@given(trees(max_n=12, forces="constant"))
def test_compiled_laws_equal_dense_and_recursive_on_spatial_trees(tree):
    """Spatial trees on every joint type with forces and torques (world and body frames), joint
    forces, joint springs and spring-dampers (to the ground and between bodies), all compiled."""
    _check(with_every_law(tree), tree.rng)


@given(trees(max_n=12, planar=True, forces="constant"))
def test_compiled_laws_equal_dense_and_recursive_on_planar_trees(tree):
    """Planar bodies (a selection S: the reference loads them in their own coordinates,
    h_n += Sᵀ S w; the kernel adds the spatial w, whose difference no in-plane motion sees)."""
    _check(with_every_law(tree), tree.rng)


@settings(max_examples=max(10, settings().max_examples // 3), deadline=None)
@given(trees_with_beams())
def test_compiled_laws_on_trees_with_beams_equal_dense_and_recursive(tree):
    """RitzBeams in the tree (on its bodies and on the beams' stations): the loads act on the
    bodies' reference frames (the first six rows of h_n, S = [E; 0]); a joint force's pair
    reaches an elastic parent's q̇_e rows through T_np. Compiled, without a warning."""
    system = with_every_law(tree)
    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        warnings.simplefilter("ignore", RuntimeWarning)  # an unstiffened beam spun fast: said once
        assert system.evaluator().name == "fast"
        state = types.SimpleNamespace(system=system, q=tree.q, s_dot=tree.s_dot, t=tree.t)
        _agree(state, "fast", "dense")
        _agree(state, "fast", "recursive")


@settings(max_examples=10)
@given(trees(max_n=6, forces="constant"))
def test_the_interpreted_loop_is_the_compiled_one(tree):
    """compiled=False runs the same loop source interpreted: the same s̈ as the compiled one."""
    system = with_every_law(tree)
    q, s_dot, t = random_state(system, tree.rng)
    compiled = FastEvaluator(system).accelerations(q, s_dot, t)
    interpreted = FastEvaluator(system, compiled=False).accelerations(q, s_dot, t)
    assert np.allclose(compiled, interpreted, rtol=1e-12, atol=1e-12 * np.abs(compiled).max(initial=1.0))


def test_the_car_is_B9_with_its_loads_compiled():
    """scenes.car with nonzero f_x, M_z, f_y (three compiled rows, body frame, f_y at the mass
    centre) on the default evaluator: s̈ from B(9) solved for v̇_x, ω̇_z."""
    rng = np.random.default_rng(9)
    for _ in range(5):
        m, c, f_x, f_y, M_z = rng.uniform(500, 2000), rng.uniform(0.2, 2.0), *rng.uniform(-3000, 3000, 3)
        C0 = m * c * c + rng.uniform(200, 3000)
        system = pq.scenes.car(m=m, C0=C0, c=c, f_x=f_x, M_z=M_z, f_y=f_y)
        ev = system.evaluator()
        assert ev.name == "fast" and all(law.compiled_terms() is not None for law in system.forces)
        for _ in range(5):
            q, (v_x, omega_z) = rng.uniform(-5, 5, 3), (rng.uniform(-20, 20), rng.uniform(-2, 2))
            expected = ((f_x + m * c * omega_z**2) / m, (M_z + c * f_y - m * c * v_x * omega_z) / C0)
            assert np.allclose(ev.accelerations(q, np.array([v_x, omega_z]), 0.0), expected, rtol=EXACT, atol=EXACT)


class Doubled(pq.Force):
    """A user's law: twice the force it is given (restates ``wrench``)."""

    def wrench(self, R, t, q, s_dot):
        return 2.0 * super().wrench(R, t, q, s_dot)


class Stiffer(pq.JointSpring):
    """A user's joint spring twice as stiff and damped (restates ``generalized_force``)."""

    def generalized_force(self, t, q, s_dot):
        return 2.0 * super().generalized_force(t, q, s_dot)


class Quiet(pq.SpringDamper):
    """A user's subclass that restates none of the numbers: it keeps the compiled row."""


def _pendulum(*forces) -> pq.System:
    body = pq.RigidBody(2.0, (0.3, 0.0, 0.1), np.diag([0.05, 0.06, 0.07]))
    return pq.System({"a": body, "b": body}, {"a": pq.Revolute(axis="y"), "b": pq.Revolute("a", "x", (0.6, 0, 0))},
                     gravity=(0, 0, -9.81), forces=list(forces))


def test_a_user_law_keeps_its_python_and_a_callable_load_runs_compiled_on_the_fast_evaluator():
    """A subclass that restates ``wrench`` or ``generalized_force`` loses the compiled row it
    inherits (its override is never bypassed): the fast evaluator calls its ``add_to`` and gives
    the reference's numbers — which differ from the plain law's (the override counts). A load given
    as a callable of (t, q, ṡ) has a row whose load numba compiles (``compiled_load``), with the
    reference's numbers. A subclass that restates nothing keeps its row."""
    doubled = Doubled("b", (1.0, -2.0, 0.5), (0.2, 0.1, 0.0))
    callable_load = pq.Force("a", lambda t, q, s: (t, q[1], s[0]))
    assert Doubled.compiled_terms is pq.ForceLaw.compiled_terms
    assert Quiet.compiled_terms is pq.SpringDamper.compiled_terms
    q, s_dot, t = np.array([0.4, -0.7]), np.array([1.1, -0.3]), 0.8
    plain = _pendulum(pq.Force("b", (1.0, -2.0, 0.5), (0.2, 0.1, 0.0)), callable_load)
    system = _pendulum(doubled, callable_load)
    bound = system.forces
    assert bound[0].compiled_terms() is None and bound[1].compiled_terms() is not None
    assert bound[1].compiled_load()[1:] == (0, 3)
    assert [law for law in system.evaluator("fast")._python_laws] == [bound[0]]
    fast = system.accelerations(q, s_dot, t, method="fast")
    assert np.allclose(fast, system.accelerations(q, s_dot, t, method="recursive"), rtol=EXACT, atol=EXACT)
    assert not np.allclose(fast, plain.accelerations(q, s_dot, t, method="fast"), rtol=1e-3)
    stiffer, spring = _pendulum(Stiffer("b", 5.0, 0.5, 0.2)), _pendulum(pq.JointSpring("b", 5.0, 0.5, 0.2))
    assert stiffer.forces[0].compiled_terms() is None
    fast = stiffer.accelerations(q, s_dot, t, method="fast")
    assert np.allclose(fast, stiffer.accelerations(q, s_dot, t, method="dense"), rtol=EXACT, atol=EXACT)
    assert not np.allclose(fast, spring.accelerations(q, s_dot, t, method="fast"), rtol=1e-3)
    quiet = _pendulum(Quiet("a", (0.1, 0, 0), None, (0.5, 0.5, 0.5), 30.0, 2.0, 0.2))
    assert quiet.forces[0].compiled_terms() is not None
    assert np.allclose(quiet.accelerations(q, s_dot, t, method="fast"),
                       quiet.accelerations(q, s_dot, t, method="dense"), rtol=EXACT, atol=EXACT)


def test_coincident_spring_points_raise_the_laws_error_on_the_fast_evaluator():
    """A spring-damper whose two points coincide has no direction: the compiled row reports it
    and the fast evaluator raises the law's own error, as the reference does."""
    system = _pendulum(pq.SpringDamper("a", (0.0, 0.0, 0.0), None, (0.0, 0.0, 0.0), 10.0))
    for method in ("fast", "recursive"):
        with pytest.raises(ValueError, match="the two points coincide"):
            system.accelerations(np.zeros(2), np.zeros(2), 0.0, method=method)


def test_the_compiled_loop_takes_a_complex_step():
    """The loop's statements are analytic (real parts compared only): on complex kinematics
    the compiled loop gives the interpreted one's h_n, and its imaginary part over the step
    is the derivative of the real loads (a central difference of the real loop)."""
    system = _pendulum(pq.SpringDamper("a", (0.2, 0.0, 0.1), "b", (0.0, 0.3, 0.0), 40.0, 3.0, 0.1),
                       pq.Force("b", (1.0, 2.0, -3.0), (0.1, 0.2, 0.3), frame="body"),
                       pq.Torque("a", (0.5, -0.2, 0.1)), pq.JointSpring("b", 7.0, 0.4, 0.1), pq.JointForce("a", [2.5]))
    ev = FastEvaluator(system)
    q, s_dot = np.array([0.4, -0.7]), np.array([1.1, -0.3])
    ev.accelerations(q, s_dot, 0.0)  # the workspace at (q, ṡ)
    rng = np.random.default_rng(3)
    ws = ev._real  # the real workspace
    direction = {name: rng.standard_normal(getattr(ws, name).shape) for name in ("R", "r", "twist", "F", "T")}

    def loads_at(step, kernel):
        args = [getattr(ws, name) + step * direction[name] for name in ("R", "r", "twist", "F", "T")]
        h = np.zeros(ws.h_hat.shape, dtype=np.result_type(step, float))
        state = (q + step * 0.3, s_dot - step * 0.2)
        kernel(ev._laws, ev._law_constants, ev._index, 0.0, *state, *state, *args, h)
        return h

    h_complex = loads_at(1e-30j, loads.kernel(True))
    assert np.allclose(h_complex, loads_at(1e-30j, loads.kernel(False)), rtol=1e-13, atol=1e-13)
    real = loads.kernel(True)
    central = (loads_at(1e-6, real) - loads_at(-1e-6, real)) / 2e-6
    # central differences of step 1e-6: round-off ε |h| / step, absolute: measured 2.2e-9 with loads up
    # to 44 (was 1e-6 + 1e-6 relative)
    assert np.allclose(h_complex.imag / 1e-30, central, rtol=0, atol=2.5e-8)


@pytest.mark.parametrize("joint", ["l0", "beam", "tip"])
def test_a_joint_force_is_tau_on_its_own_velocity_with_beams_in_the_tree(joint):
    """B(14): the pair h_n += w, h_p −= T_npᵀ w projects to exactly τ on the joint's minimal
    velocity, so at rest, without gravity and deflection, M s̈ = τ e_j (M from
    ``mass_matrix``, which no load enters) — on the joint of a beam (F_n carries q̇_e columns
    after the joint's own) and on a joint at a beam's station (the reaction on the beam)."""
    beam = pq.RitzBeam(0.8, rho_A=0.8, EI_z=40.0, n_v=3, n_w=0)
    system = pq.System(
        {"l0": pq.RigidBody(2.0, (0.3, 0, 0), np.diag([1e-3, 0.06, 0.06])), "beam": beam,
         "tip": pq.RigidBody(0.3, (0.05, 0, 0), np.diag([1e-4, 2e-4, 2e-4]))},
        {"l0": pq.Revolute(axis="z"), "beam": pq.Revolute("l0", "z", (0.6, 0, 0)),
         "tip": pq.Revolute("beam", "z", (0.8, 0, 0))},
        forces=[pq.JointForce(joint, [1.7])])
    q, s_dot = np.array([0.3, -0.4, 0.0, 0.0, 0.0, 0.2]), np.zeros(system.n_s)
    e_j = np.zeros(system.n_s)
    e_j[system.s_slice[system.index(joint)].start] = 1.7
    expected = np.linalg.solve(system.mass_matrix(q, 0.0), e_j)
    assert system.evaluator().name == "fast"
    for method in ("fast", "recursive", "dense"):
        assert np.allclose(system.accelerations(q, s_dot, 0.0, method=method), expected, rtol=1e-10, atol=1e-10)

"""Bad input gets a clear error naming the parameter, raised where the input enters."""

import numpy as np
import pytest

import projeq as pq

ROD = dict(m=1.0, r_c=(0, 0, -0.5), I_c=np.diag([0.1, 0.1, 0.01]))


def _pendulum(**forces):
    return pq.System({"bob": pq.RigidBody(**ROD)}, {"bob": pq.Revolute(axis="y")}, gravity=(0, 0, -9.81), **forces)


@pytest.mark.parametrize("m", [0.0, -1.0, np.nan, np.inf], ids=["zero", "negative", "nan", "inf"])
def test_mass_must_be_positive_and_finite(m):
    with pytest.raises(ValueError, match="^m"):
        pq.RigidBody(m, ROD["r_c"], ROD["I_c"])


@pytest.mark.parametrize(
    "I_c, match",
    [
        (np.array([[1.0, 0.2, 0], [0.0, 1, 0], [0, 0, 1]]), "not symmetric"),
        (np.diag([1.0, 1.0, -0.5]), "not positive definite"),
        (np.diag([0.0, 0.0, 0.0]), "not positive definite"),
        (np.diag([1.0, 1.0, 3.0]), "triangle inequality"),
        (np.eye(2), "shape"),
        (np.diag([1.0, np.nan, 1.0]), "non-finite"),
    ],
    ids=["asymmetric", "indefinite", "zero", "triangle", "shape", "nan"],
)
def test_inertia_must_be_a_real_mass_distribution(I_c, match):
    with pytest.raises(ValueError, match=f"^I_c.*{match}"):
        pq.RigidBody(1.0, (0, 0, 0), I_c)


@pytest.mark.parametrize(
    "axis, match",
    [((0, 0, 0), "zero axis"), ((np.nan, 0, 1), "non-finite"), ((1, 0), "3-vector"), ("w", "unknown axis")],
    ids=["zero", "nan", "shape", "name"],
)
@pytest.mark.parametrize("joint", [pq.Revolute, pq.Prismatic])
def test_joint_axis_must_have_a_direction(joint, axis, match):
    with pytest.raises(ValueError, match=f"^axis.*{match}"):
        joint(axis=axis)


def test_a_body_is_attached_once():
    builder = pq.SystemBuilder()
    builder.add("link", pq.RigidBody(**ROD), pq.Revolute(axis="y"))
    with pytest.raises(ValueError, match="^name.*attached already"):
        builder.add("link", pq.RigidBody(**ROD), pq.Revolute(axis="y"))


def test_a_cycle_is_not_a_tree():
    body = pq.RigidBody(**ROD)
    with pytest.raises(ValueError, match="^joints.*cycle"):
        pq.System({"a": body, "b": body}, {"a": pq.Revolute("b", "y"), "b": pq.Revolute("a", "y")})


def test_a_subsystem_cannot_be_its_own_parent():
    with pytest.raises(ValueError, match="own parent"):
        pq.System({"a": pq.RigidBody(**ROD)}, {"a": pq.Revolute("a", "y")})


def test_parent_must_be_in_the_system():
    with pytest.raises(ValueError, match=r"^joints\['a'\]: parent 'ghost' is not in the system"):
        pq.System({"a": pq.RigidBody(**ROD)}, {"a": pq.Revolute("ghost", "y")})


def test_every_subsystem_needs_a_joint_and_vice_versa():
    body = pq.RigidBody(**ROD)
    with pytest.raises(ValueError, match=r"^joints: no joint for subsystem\(s\) \['b'\]"):
        pq.System({"a": body, "b": body}, {"a": pq.Revolute(axis="y")})
    with pytest.raises(ValueError, match="^joints: joint.*unknown subsystem"):
        pq.System({"a": body}, {"a": pq.Revolute(axis="y"), "c": pq.Revolute(axis="y")})


@pytest.mark.parametrize("method", ["accelerations", "gauss_form", "energy"])
@pytest.mark.parametrize("bad", ["q", "s_dot"])
def test_state_of_the_wrong_length(method, bad):
    system = _pendulum()
    q, s_dot = ([0.1, 0.2], [0.0]) if bad == "q" else ([0.1], [0.0, 1.0])
    with pytest.raises(ValueError, match=f"^{bad}: expected 1 entries"):
        getattr(system, method)(q, s_dot)


@pytest.mark.parametrize("bad", ["q", "s_dot"])
def test_nan_in_a_state(bad):
    system = _pendulum()
    q, s_dot = ([np.nan], [0.0]) if bad == "q" else ([0.1], [np.inf])
    with pytest.raises(ValueError, match=f"^{bad}: non-finite"):
        system.accelerations(q, s_dot)
    with pytest.raises(ValueError, match=f"^{bad}0: non-finite"):  # simulate names its own q0, s_dot0
        pq.simulate(system, 1.0, q, s_dot)


def test_mass_matrix_with_a_wrong_q():
    with pytest.raises(ValueError, match="^q: expected 1 entries"):
        _pendulum().mass_matrix([0.1, 0.2])


@pytest.mark.parametrize(
    "build, match",
    [
        (lambda: pq.System({"a": pq.RigidBody(**ROD)}, {"a": pq.Revolute(axis="y")}, gravity=(0, np.nan, 0)), "^gravity"),
        (lambda: pq.RigidBody(1.0, (0, np.inf, 0), ROD["I_c"]), "^r_c"),
        (lambda: pq.Revolute(axis="y", r_pn=(0, 0, np.nan)), "^r_pn"),
        (lambda: pq.Force("a", (1.0, np.nan, 0)), "^force"),
        (lambda: pq.JointSpring("a", stiffness=-1.0), "^stiffness"),
        (lambda: pq.System({"a": pq.RigidBody(**ROD)}, {"a": pq.Revolute(axis="y")}, q0=[np.nan]), "^q0"),
    ],
    ids=["gravity", "r_c", "r_pn", "force", "stiffness", "q0"],
)
def test_nan_in_a_parameter(build, match):
    with pytest.raises(ValueError, match=match):
        build()


def test_force_on_an_unknown_body_lists_the_known_ones():
    with pytest.raises(ValueError, match=r"unknown subsystem 'ghost'.*\['bob'\]"):
        _pendulum(forces=[pq.Force("ghost", (1.0, 0, 0))])


def test_a_force_that_turns_nan_fails_the_run_and_keeps_the_trajectory():
    """A force law that returns NaN after t = 0.5 s: SimulationError with the time
    reached and the trajectory up to the last finished segment kept."""
    force = pq.Force("bob", lambda t, q, s_dot: np.array([np.nan if t > 0.5 else 0.0, 0.0, 0.0]))
    system = _pendulum(forces=[force])
    with pytest.raises(pq.SimulationError, match=r"integration failed at t = .*force") as info:
        pq.simulate(system, 1.0, [0.3], [0.0], n_segments=10)
    result = info.value.result
    assert not result.success and result.status == -1
    assert 0.4 <= result.t[-1] <= 0.5 + 1e-12
    assert np.all(np.isfinite(result.q))


def test_an_integrator_that_fails_reports_its_message_and_keeps_the_trajectory():
    """A drive torque τ = 1/(1 − t)³ blows up at t = 1: solve_ivp's step size underflows
    (status −1); the message names the integrator's reason and the time reached."""
    drive = pq.JointForce("bob", lambda t, q, s_dot: np.array([1.0 / (1.0 - t) ** 3]))
    system = _pendulum(forces=[drive])
    with pytest.raises(pq.SimulationError, match=r"integration failed at t = (0\.9\d*|1) s") as info:
        pq.simulate(system, 2.0, [0.0], [0.0], method="RK45", n_segments=4)
    assert 0.75 <= info.value.result.t[-1] < 1.0


def test_a_joint_that_moves_no_mass_is_singular():
    """A point mass on the axis of its revolute joint has D_n = 0."""
    system = pq.System({"p": pq.PointMass(1.0, (0, 0, 0))}, {"p": pq.Revolute(axis="z")})
    with pytest.raises(pq.SingularMassError, match="'p'.*singular"):
        system.accelerations([0.0], [0.0])


@pytest.mark.parametrize("method", ["newton", 3])
def test_unknown_evaluator(method):
    with pytest.raises(ValueError, match="^method: unknown evaluator"):
        _pendulum().accelerations([0.0], [0.0], method=method)


def test_end_time_must_follow_the_start():
    with pytest.raises(ValueError, match="^t_end"):
        pq.simulate(_pendulum(), 0.0)


def test_unknown_integrator():
    with pytest.raises(ValueError, match="^method: unknown integrator 'Euler42'"):
        pq.simulate(_pendulum(), 1.0, method="Euler42")

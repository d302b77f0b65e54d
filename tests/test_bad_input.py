"""Bad input gets a clear error naming the parameter, raised where the input enters.

One test per kind of bad input (STYLE §4.8 item 11), its variants as parametrized cases;
every message is matched from its start, so that it begins with the parameter's name.
"""

import numpy as np
import pytest

import projeq as pq

ROD = {"m": 1.0, "r_c": (0, 0, -0.5), "I_c": np.diag([0.1, 0.1, 0.01])}


def _pendulum(**kwargs):
    """One rod on a revolute joint about y under gravity: n_q = n_s = 1."""
    return pq.System(
        {"bob": pq.RigidBody(**ROD)}, {"bob": pq.Revolute(axis="y")}, gravity=(0, 0, -9.81), **kwargs
    )


# -- subsystems and joints ----------------------------------------------------------------


@pytest.mark.parametrize(
    "build",
    [
        lambda m: pq.RigidBody(m, ROD["r_c"], ROD["I_c"]),
        lambda m: pq.PointMass(m),
        lambda m: pq.PlanarBody(m, I_c=0.1),
    ],
    ids=["RigidBody", "PointMass", "PlanarBody"],
)
@pytest.mark.parametrize(
    "m, problem",
    [
        (0.0, "must be positive"),
        (-1.0, "must be positive"),
        (np.nan, "non-finite"),
        (np.inf, "non-finite"),
        ("heavy", "expected numbers"),
    ],
    ids=["zero", "negative", "nan", "inf", "text"],
)
def test_mass_must_be_positive_and_finite(build, m, problem):
    with pytest.raises(ValueError, match=rf"^m \(mass\): {problem}"):
        build(m)


@pytest.mark.parametrize(
    "I_c, problem",
    [
        (np.array([[1.0, 0.2, 0], [0.0, 1, 0], [0, 0, 1]]), "inertia tensor is not symmetric"),
        (np.diag([1.0, 1.0, -0.5]), "inertia tensor is not positive definite"),
        (np.zeros((3, 3)), "inertia tensor is not positive definite"),
        (np.diag([1.0, 1.0, 3.0]), r"principal moments \[1. 1. 3.\] violate the triangle inequality"),
        (np.diag([1.0, np.nan, 1.0]), "non-finite"),
        (np.eye(2), r"expected shape \(3, 3\)"),
    ],
    ids=["asymmetric", "indefinite", "zero", "triangle", "nan", "shape"],
)
def test_inertia_must_be_a_mass_distribution(I_c, problem):
    with pytest.raises(ValueError, match=f"^I_c: {problem}"):
        pq.RigidBody(1.0, (0, 0, 0), I_c)


@pytest.mark.parametrize(
    "axis, problem",
    [
        ((0, 0, 0), "zero axis"),
        ((1e-14, 0, 0), "zero axis"),
        ((np.nan, 0, 1), "axis has non-finite entries"),
        ((0, 0, np.inf), "axis has non-finite entries"),
        ((1, 0), "expected a 3-vector"),
        ("w", "unknown axis 'w'"),
    ],
    ids=["zero", "tiny", "nan", "inf", "shape", "name"],
)
@pytest.mark.parametrize("joint", [pq.Revolute, pq.Prismatic])
def test_joint_axis_must_have_a_direction(joint, axis, problem):
    with pytest.raises(ValueError, match=f"^axis: {problem}"):
        joint(axis=axis)


# -- the tree -------------------------------------------------------------------------------


def test_a_body_is_attached_once():
    builder = pq.SystemBuilder()
    builder.add("link", pq.RigidBody(**ROD), pq.Revolute(axis="y"))
    with pytest.raises(ValueError, match="^name: a subsystem 'link' is attached already"):
        builder.add("link", pq.RigidBody(**ROD), pq.Revolute(axis="y"))


@pytest.mark.parametrize(
    "parents, loop",
    [
        ({"a": "b", "b": "a"}, "'a' -> 'b' -> 'a'"),
        ({"root": None, "a": "c", "b": "a", "c": "b", "leaf": "c"}, "'a' -> 'c' -> 'b' -> 'a'"),
    ],
    ids=["two", "three-with-root-and-leaf"],
)
def test_a_cycle_is_not_a_tree(parents, loop):
    """The message names the loop itself, not the bodies merely hanging from it."""
    body = pq.RigidBody(**ROD)
    joints = {name: pq.Revolute(parent, "y") for name, parent in parents.items()}
    with pytest.raises(ValueError, match=rf"^joints: the parents form a cycle \(following parents: {loop}\)"):
        pq.System(dict.fromkeys(parents, body), joints)


def test_a_subsystem_cannot_be_its_own_parent():
    with pytest.raises(ValueError, match=r"^joints\['a'\]: a subsystem cannot be its own parent"):
        pq.System({"a": pq.RigidBody(**ROD)}, {"a": pq.Revolute("a", "y")})


def test_parent_must_be_in_the_system():
    with pytest.raises(
        ValueError, match=r"^joints\['a'\]: parent 'ghost' is not in the system; known subsystems are \['a'\]"
    ):
        pq.System({"a": pq.RigidBody(**ROD)}, {"a": pq.Revolute("ghost", "y")})


BODY, JOINT = pq.RigidBody(**ROD), pq.Revolute(axis="y")


@pytest.mark.parametrize(
    "subsystems, joints, message",
    [
        ({"a": BODY, "b": BODY}, {"a": JOINT}, r"^joints: no joint for subsystem\(s\) \['b'\]"),
        ({"a": BODY}, {"a": JOINT, "c": JOINT}, r"^joints: joint\(s\) for unknown subsystem\(s\) \['c'\]"),
        ({"a": 1.0}, {"a": JOINT}, r"^subsystems\['a'\]: 1.0 is not a subsystem"),
        ({"a": BODY}, {"a": "revolute"}, r"^joints\['a'\]: 'revolute' is not a Joint"),
        ({}, {}, "^subsystems: expected a non-empty dict"),
    ],
    ids=["joint-missing", "joint-extra", "not-a-subsystem", "not-a-joint", "empty"],
)
def test_subsystems_and_joints_must_match(subsystems, joints, message):
    with pytest.raises(ValueError, match=message):
        pq.System(subsystems, joints)


# -- states ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda s: s.accelerations([0.1, 0.2], [0.0]), "q"),
        (lambda s: s.accelerations([0.1], [0.0, 1.0]), "s_dot"),
        (lambda s: s.mass_matrix([0.1, 0.2]), "q"),
        (lambda s: s.gauss_form([0.1], []), "s_dot"),
        (lambda s: s.energy([[0.1]], [0.0]), "q"),
        (lambda s: s.energy([0.1], [0.0, 1.0]), "s_dot"),
        (lambda s: pq.simulate(s, 1.0, q0=[0.1, 0.2]), "q0"),
        (lambda s: pq.simulate(s, 1.0, s_dot0=[]), "s_dot0"),
        (lambda s: s.q_dot([0.1, 0.2], [0.0]), "q"),
        (lambda s: s.q_dot([0.1], [0.0, 1.0]), "s_dot"),
        (lambda s: pq.System({"b": pq.RigidBody(**ROD)}, {"b": pq.Revolute(axis="y")}, q0=[0.1, 0.2]), "q0"),
        (
            lambda s: pq.System({"b": pq.RigidBody(**ROD)}, {"b": pq.Revolute(axis="y")}, s_dot0=[0, 1]),
            "s_dot0",
        ),
    ],
    ids=[
        "accelerations-q",
        "accelerations-s_dot",
        "mass_matrix-q",
        "gauss_form-s_dot",
        "energy-q",
        "energy-s_dot",
        "simulate-q0",
        "simulate-s_dot0",
        "q_dot-q",
        "q_dot-s_dot",
        "System-q0",
        "System-s_dot0",
    ],
)
def test_state_of_the_wrong_length(call, name):
    with pytest.raises(ValueError, match=rf"^{name}: expected 1 entries, got shape"):
        call(_pendulum())


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda s: s.accelerations([np.nan], [0.0]), "q"),
        (lambda s: s.accelerations([0.1], [np.inf]), "s_dot"),
        (lambda s: s.accelerations([0.1], [0.0], t=np.nan), "t"),
        (lambda s: s.mass_matrix([np.inf]), "q"),
        (lambda s: s.energy([0.1], [np.nan]), "s_dot"),
        (lambda s: pq.simulate(s, 1.0, q0=[np.nan]), "q0"),
        (lambda s: pq.simulate(s, 1.0, s_dot0=[-np.inf]), "s_dot0"),
        (lambda s: s.q_dot([np.nan], [0.0]), "q"),
        (lambda s: s.q_dot([0.1], [np.inf]), "s_dot"),
        (lambda s: pq.System({"b": pq.RigidBody(**ROD)}, {"b": pq.Revolute(axis="y")}, q0=[np.nan]), "q0"),
        (
            lambda s: pq.System({"b": pq.RigidBody(**ROD)}, {"b": pq.Revolute(axis="y")}, s_dot0=[np.nan]),
            "s_dot0",
        ),
    ],
    ids=[
        "accelerations-q",
        "accelerations-s_dot",
        "accelerations-t",
        "mass_matrix-q",
        "energy-s_dot",
        "simulate-q0",
        "simulate-s_dot0",
        "q_dot-q",
        "q_dot-s_dot",
        "System-q0",
        "System-s_dot0",
    ],
)
def test_non_finite_state(call, name):
    with pytest.raises(ValueError, match=rf"^{name}: non-finite entries \(NaN or inf\) at flat index \[0\]"):
        call(_pendulum())


@pytest.mark.parametrize(
    "call, name",
    [
        (lambda s: pq.System({"b": pq.RigidBody(**ROD)}, {"b": pq.Free()}, q0=np.zeros(7)), "q0"),
        (lambda s: pq.simulate(s, 1.0, q0=np.zeros(7)), "q0"),
        (lambda s: s.accelerations(np.zeros(7), np.zeros(6)), "q"),
    ],
    ids=["System", "simulate", "accelerations"],
)
def test_a_zero_quaternion_cannot_be_normalised(call, name):
    """A free joint's orientation (w, x, y, z) = 0 is no rotation: an error, not NaN poses."""
    system = pq.System({"b": pq.RigidBody(**ROD)}, {"b": pq.Free()})
    with pytest.raises(ValueError, match=rf"^{name}: the coordinates .* of joint 'b' .*cannot be normalised"):
        call(system)


# -- parameters and forces ------------------------------------------------------------------


@pytest.mark.parametrize(
    "build, name",
    [
        (
            lambda: pq.System(
                {"a": pq.RigidBody(**ROD)}, {"a": pq.Revolute(axis="y")}, gravity=(0, np.nan, 0)
            ),
            "gravity",
        ),
        (lambda: pq.RigidBody(1.0, (0, np.inf, 0), ROD["I_c"]), "r_c"),
        (lambda: pq.PointMass(1.0, (np.nan, 0, 0)), "r_c"),
        (lambda: pq.Revolute(axis="y", r_pn=(0, 0, np.nan)), "r_pn"),
        (lambda: pq.Prismatic(axis="x", r_pn=(np.inf, 0, 0)), "r_pn"),
        (lambda: pq.Force("bob", (1.0, np.nan, 0)), "force"),
        (lambda: pq.Force("bob", (1.0, 0, 0), point=(np.nan, 0, 0)), "point"),
        (lambda: pq.Torque("bob", (0, 0, np.inf)), "torque"),
        (lambda: _pendulum(forces=[pq.JointForce("bob", [np.nan])]), "tau of joint 'bob'"),
        (lambda: _pendulum(forces=[pq.JointSpring("bob", 1.0, q_ref=np.nan)]), "q_ref"),
        (lambda: pq.JointSpring("bob", stiffness=np.nan), "stiffness"),
        (lambda: pq.SpringDamper("bob", (0, 0, 0), None, (0, 0, 1), 1.0, length=np.inf), "length"),
    ],
    ids=[
        "gravity",
        "r_c",
        "r_c-point-mass",
        "r_pn",
        "r_pn-prismatic",
        "force",
        "point",
        "torque",
        "tau",
        "q_ref",
        "stiffness",
        "length",
    ],
)
def test_non_finite_parameter(build, name):
    with pytest.raises(ValueError, match=rf"^{name}: non-finite entries \(NaN or inf\)"):
        build()


@pytest.mark.parametrize(
    "force, name",
    [
        (pq.Force("ghost", (1.0, 0, 0)), "body"),
        (pq.Torque("ghost", (0, 0, 1.0)), "body"),
        (pq.JointForce("ghost", 1.0), "joint"),
        (pq.JointSpring("ghost", 1.0), "joint"),
        (pq.SpringDamper("bob", (0, 0, 0), "ghost", (0, 0, 0), 1.0), "body_b"),
        (pq.SpringDamper("ghost", (0, 0, 0), None, (0, 0, 0), 1.0), "body_a"),
    ],
    ids=["Force", "Torque", "JointForce", "JointSpring", "SpringDamper-b", "SpringDamper-a"],
)
def test_a_force_on_an_unknown_body_lists_the_known_ones(force, name):
    with pytest.raises(ValueError, match=rf"^{name}: unknown subsystem 'ghost'; the system has \['bob'\]"):
        _pendulum(forces=[force])


def test_a_force_law_must_be_a_force_law():
    with pytest.raises(ValueError, match=r"^forces\[1\]: 3 is not a force law"):
        _pendulum(forces=[pq.Force("bob", (1.0, 0, 0)), 3])


def test_a_spring_damper_needs_two_bodies():
    with pytest.raises(
        ValueError, match="^body_b: a spring-damper needs two distinct bodies, not 'bob' twice"
    ):
        _pendulum(forces=[pq.SpringDamper("bob", (0, 0, 0), "bob", (0, 0, -1), stiffness=10.0)])


@pytest.mark.parametrize("method", ["recursive", "simulate"])
def test_a_joint_that_moves_no_mass_is_singular(method):
    """A point mass on the axis of its revolute joint: D_n = F_nᵀ M̂_n F_n = 0. The error
    names the joint, also from simulate, which evaluates the initial state before the run."""
    system = pq.System({"p": pq.PointMass(1.0, (0, 0, 0))}, {"p": pq.Revolute(axis="z")})
    with pytest.raises(pq.SingularMassError, match=r"^D_n = F_nᵀ M̂_n F_n of joint 'p' is singular"):
        system.accelerations([0.0], [0.0]) if method == "recursive" else pq.simulate(system, 1.0)


def test_the_dense_evaluator_reports_a_singular_mass_matrix():
    """The Gauss form cannot tell which joint: it names the system mass matrix M(q)."""
    system = pq.System({"p": pq.PointMass(1.0, (0, 0, 0))}, {"p": pq.Revolute(axis="z")})
    with pytest.raises(pq.SingularMassError, match=r"^system mass matrix M\(q\) is singular"):
        system.accelerations([0.0], [0.0], method="dense")


# -- failures during a simulation -----------------------------------------------------------


def test_a_force_that_turns_nan_fails_the_run_and_keeps_the_trajectory():
    """A force law that returns NaN after t = 0.5 s: SimulationError naming the force and
    the time reached; ``.result`` keeps the rows up to the last accepted step, all finite: the
    output times before 0.5 s (the state at 0.5 s needs a step that ends there, and the steps of
    the compiled loop approach the failure from below without landing on it)."""
    force = pq.Force("bob", lambda t, q, s_dot: np.array([np.nan if t > 0.5 else 0.0, 0.0, 0.0]))
    with pytest.raises(
        pq.SimulationError,
        match=r"^integration failed at t = 0\.5\d* s \(t_end = 1\.0\): force: non-finite entries .*; "
        r"the trajectory up to t = 0\.4 s is in \.result",
    ) as info:
        pq.simulate(_pendulum(forces=[force]), 1.0, [0.3], [0.0], n_segments=10, n_points=11)
    result = info.value.result
    assert result.status == -1 and not result.success
    # every output time up to the failure (measured 0; was allclose's defaults)
    assert np.allclose(result.t, np.linspace(0.0, 0.4, 5), rtol=0, atol=100 * np.finfo(float).eps)
    assert np.all(np.isfinite(result.q)) and np.all(np.isfinite(result.energy))
    assert isinstance(info.value.__cause__, ValueError)  # the original error is chained


def test_a_force_law_that_raises_fails_the_run_and_keeps_the_trajectory():
    """Any exception of a user's force law mid-run: the same SimulationError, with the
    exception's type in the message and the exception as ``__cause__``."""

    def torque(t, q, s_dot):
        if t > 0.25:
            raise ZeroDivisionError("float division by zero")
        return np.zeros(3)

    with pytest.raises(
        pq.SimulationError, match=r"^integration failed at t = 0\.25\d* s .*ZeroDivisionError"
    ) as info:
        pq.simulate(_pendulum(forces=[pq.Torque("bob", torque)]), 1.0, [0.3], [0.0], n_segments=4, n_points=5)
    assert np.allclose(info.value.result.t, [0.0, 0.25], rtol=0, atol=100 * np.finfo(float).eps)  # measured 0
    assert isinstance(info.value.__cause__, ZeroDivisionError)


def test_an_integrator_that_fails_reports_its_message_and_keeps_the_trajectory():
    """A drive torque τ = 1/(1 − t)³ makes θ̇ blow up at t = 1 s: solve_ivp's step size
    underflows (status −1). The message gives solve_ivp's own reason and the time reached
    (t → 1), ``.result`` the outputs before it. Loose tolerances only make the step size
    collapse in fewer steps; the failure is the same at any tolerance."""
    drive = pq.JointForce("bob", lambda t, q, s_dot: np.array([1.0 / (1.0 - t) ** 3]))
    with pytest.raises(
        pq.SimulationError,
        match=r"^integration failed at t = (1|0\.9999\d*) s \(t_end = 2\.0\): "
        r"Required step size is less than spacing between numbers\..*the solution may blow up here",
    ) as info:
        pq.simulate(
            _pendulum(forces=[drive]),
            2.0,
            [0.0],
            [0.0],
            method="RK45",
            rtol=1e-3,
            atol=1e-6,
            n_segments=2,
            n_points=21,
        )
    result = info.value.result
    assert result.status == -1 and "step size" in result.message
    # the outputs before the blow-up (measured 0; was allclose's defaults)
    assert np.allclose(result.t, np.linspace(0.0, 0.9, 10), rtol=0, atol=100 * np.finfo(float).eps)
    assert np.all(np.diff(result.s_dot[:, 0]) > 0)  # spun up by the drive, never NaN


# -- arguments of simulate ------------------------------------------------------------------


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"t_end": 0.0}, "^t_end: must be after t_start = 0.0, got 0.0"),
        ({"t_end": -1.0}, "^t_end: must be after t_start = 0.0, got -1.0"),
        ({"t_end": 1.0, "t_start": 2.0}, "^t_end: must be after t_start = 2.0, got 1.0"),
        ({"t_end": np.nan}, r"^t_end: non-finite entries"),
        ({"t_start": np.inf}, r"^t_start: non-finite entries"),
        ({"method": "Euler42"}, r"^method: unknown integrator 'Euler42'; use one of \['RK45', "),
        ({"method": len}, "^method: unknown integrator"),
        ({"evaluator": "newton"}, r"^evaluator: unknown evaluator 'newton'; use one of \['auto', 'dense', 'fast', 'hub_beam', 'recursive'\]"),
        ({"rtol": 0.0}, "^rtol: must be positive, got 0.0"),
        ({"atol": -1e-9}, "^atol: must be positive"),
        ({"t_eval": [0.0, 2.0]}, r"^t_eval: must increase strictly within \[0.0, 1.0\]"),
        ({"t_eval": [0.5, 0.2]}, "^t_eval: must increase strictly"),
        ({"t_eval": [[0.1, 0.2]]}, r"^t_eval: expected a 1-D array of output times, got shape \(1, 2\)"),
        ({"t_eval": []}, r"^t_eval: expected a 1-D array of output times, got shape \(0,\)"),
        ({"n_points": 1}, "^n_points: expected an integer >= 2, got 1"),
        ({"n_segments": 0}, "^n_segments: expected an integer >= 1, got 0"),
        ({"n_segments": 2.5}, "^n_segments: expected an integer >= 1, got 2.5"),
        (
            {"events": [lambda t, q, s_dot: q[0], "bottom"]},
            r"^events\[1\]: expected a callable event\(t, q, s_dot\)",
        ),
        ({"progress": True}, r"^progress: expected a callable progress\(t\), got True"),
        ({"max_step": 0.0}, "^max_step: must be positive, got 0.0"),
        ({"max_step": np.nan}, r"^max_step: non-finite entries \(NaN or inf\)"),
        ({"first_step": -1e-3, "method": "RK45"}, "^first_step: must be positive, got -0.001"),
        ({"min_step": -1.0, "method": "LSODA"}, "^min_step: must not be negative, got -1.0"),
        ({"dense_output": "no"}, "^dense_output: expected True or False, got 'no'"),
    ],
    ids=[
        "t_end-equal",
        "t_end-before",
        "t_end-before-start",
        "t_end-nan",
        "t_start-inf",
        "method-name",
        "method-function",
        "evaluator",
        "rtol",
        "atol",
        "t_eval-outside",
        "t_eval-decreasing",
        "t_eval-2d",
        "t_eval-empty",
        "n_points",
        "n_segments",
        "n_segments-float",
        "events",
        "progress",
        "max_step-zero",
        "max_step-nan",
        "first_step",
        "min_step",
        "dense_output-text",
    ],
)
def test_simulate_arguments(kwargs, message):
    kwargs = {"t_end": 1.0, **kwargs}
    with pytest.raises(ValueError, match=message):
        pq.simulate(_pendulum(), **kwargs)


def test_a_jacobian_matrix_is_taken_and_checked():
    """Passes if jac given as a matrix, which the docstring offers, runs Radau (a constant
    approximation of ∂ẋ/∂x: Newton's iteration converges to the steps' equations; its counts set the
    step sizes, so the steps differ a little) to the exact Jacobian's run within the tolerance (rtol
    1e-10: measured 9.1e-12, 10× the largest over q0 = 0.5, 0.8, 1.2 rad and 0.5, 1 s: 9.1e-11; 2.2e-15
    while each of the 20 segments cut its last step short for both; was 1e-8), and a matrix of the
    wrong shape is refused by name.
    Before, any matrix failed with numpy's "The truth value of an array with more than one element
    is ambiguous" (jac == "differences" compared elementwise)."""
    exact = pq.simulate(_pendulum(), 0.5, [0.8], method="Radau", rtol=1e-10, atol=1e-12, n_points=3)
    frozen = pq.simulate(_pendulum(), 0.5, [0.8], method="Radau", rtol=1e-10, atol=1e-12, n_points=3,
                         jac=[[0.0, 1.0], [-15.0, 0.0]])
    np.testing.assert_allclose(frozen.q, exact.q, rtol=0, atol=9.1e-11)
    with pytest.raises(ValueError, match=r"^jac: expected shape \(2, 2\), got \(3, 3\)"):
        pq.simulate(_pendulum(), 0.5, method="Radau", jac=np.eye(3))


def test_an_unlimited_max_step_is_solve_ivps_default():
    """Passes if max_step = inf, solve_ivp's own default, is accepted and gives the run without it
    bit for bit (the step-size check refuses 0, negative and NaN, not inf)."""
    plain = pq.simulate(_pendulum(), 0.3, method="RK45", n_points=4)
    unlimited = pq.simulate(_pendulum(), 0.3, method="RK45", n_points=4, max_step=np.inf)
    assert np.array_equal(plain.q, unlimited.q) and np.array_equal(plain.s_dot, unlimited.s_dot)


@pytest.mark.parametrize("method", ["newton", 3])
def test_unknown_evaluator(method):
    with pytest.raises(
        ValueError, match=r"^method: unknown evaluator .*; use one of \['auto', 'dense', 'fast', 'hub_beam', 'recursive'\]"
    ):
        _pendulum().accelerations([0.0], [0.0], method=method)


# -- issue 20: the silently accepted and the unclear, one table -------------------------------
# Each row: (id, the call, the exception, the words its message must contain, in order).


def _prescribed(motion):
    """A hub turned by ``motion`` carrying a pendulum."""
    hub = pq.Prescribed(pq.Revolute(axis="z"), motion)
    return pq.System({"hub": pq.RigidBody(**ROD), "bob": pq.RigidBody(**ROD)},
                     {"hub": hub, "bob": pq.Revolute("hub", "y")}, gravity=(0, 0, -9.81))


def _run(system, **kwargs):
    return pq.simulate(system, 1.0, n_points=11, **kwargs)


def motor_torque(t, q, s_dot):
    """A user force law that fails after 0.1 s."""
    if t > 0.1:
        raise RuntimeError("the motor model broke")
    return np.zeros(1)


def _shifted_derivative_family(n, L):
    """Clamped polynomials whose Φ′ is 3 times too large: inconsistent with Φ."""
    k = np.arange(2, n + 2)[:, None]

    def shapes(x):
        xi = np.asarray(x, dtype=float)[None, :] / L
        return xi**k, 3 * k * xi ** (k - 1) / L, k * (k - 1) * xi ** (k - 2) / L**2

    return shapes


def _slider(**kwargs):
    """A point mass on a slider along x, through a user joint from callables."""
    return pq.UserJoint.from_functions(
        1, 1, kwargs.pop("pose", lambda q, t: (np.eye(3), np.array([q[0], 0 * q[0], 0 * q[0]]))),
        lambda q, t: np.array([[1.0], [0], [0], [0], [0], [0]]) + 0 * q[0], lambda q, t: np.eye(1), **kwargs)


def _load(tmp_path, kind):
    path = tmp_path / "run.npz"
    if kind == "foreign":
        np.savez(path, a=np.arange(3))
    elif kind == "random":
        path.write_bytes(np.random.default_rng(0).bytes(500))
    elif kind == "pickled":  # numpy's own format, holding a pickled object
        path = tmp_path / "run.npy"
        np.save(path, np.array([object()], dtype=object))
    else:
        result = pq.simulate(_pendulum(), 0.1, n_points=5)
        result.save(path)
        if kind == "inconsistent":  # Result.save refuses to write it: altered afterwards
            with np.load(path) as data:
                np.savez(path, **{name: data[name][:3] if name == "q" else data[name] for name in data.files})
        if kind == "truncated":
            path.write_bytes(path.read_bytes()[:400])
    return pq.Result.load(path)


BAD_INPUT = [
    ("simulate-misspelt-option", lambda tmp: _run(_pendulum(), max_stepp=0.1), ValueError,
     r"options: unknown option \['max_stepp'\] .* \(did you mean 'max_step'\?\); it takes \['first_step', 'max_step'\]"),
    ("simulate-rtol-above-1", lambda tmp: _run(_pendulum(), rtol=5.0), ValueError, r"^rtol: .* below 1"),
    ("simulate-rtol-1", lambda tmp: _run(_pendulum(), rtol=1.0), ValueError, r"^rtol: .* below 1 .*got 1.0"),
    ("simulate-a-name", lambda tmp: pq.simulate("chain", 1.0), ValueError, r"^system: expected a System"),
    ("prescribed-nan", lambda tmp: _run(_prescribed(lambda t: (np.nan, 0.0, 0.0))), ValueError,
     r"^motion: the prescribed motion .*<lambda> returned .*nan.* at t = 0; they must be finite"),
    ("prescribed-nan-later", lambda tmp: _run(_prescribed(lambda t: (t, 1.0, 0.0) if t < 0.5 else (np.nan, 1.0, 0.0))),
     pq.SimulationError, r"failed at t = 0.5 s .*motion: the prescribed motion .* at t = 0.5"),
    ("prescribed-scalar", lambda tmp: _prescribed(lambda t: 0.1 * t), ValueError,
     r"^motion: .* must return three numbers \(θ, θ̇, θ̈\) at t = 0, got 0.0"),
    ("prescribed-malformed-text", lambda tmp: _prescribed("sin(t"), ValueError, r"^motion: cannot read 'sin\(t'"),
    ("prescribed-unknown-symbol", lambda tmp: _prescribed("sin(w*t)"), ValueError, r"^motion: depends on \['w'\]; only t"),
    ("event-signature", lambda tmp: _run(_pendulum(), events=lambda t, x: x[0]), ValueError,
     r"^events\[0\] .*: calling it as event\(t, q, s_dot\) at t = 0.0 failed"),
    ("event-nan", lambda tmp: _run(_pendulum(), events=lambda t, q, s_dot: np.nan), ValueError,
     r"^events\[0\] .*: returned nan at the initial state"),
    ("event-nan-later", lambda tmp: _run(_pendulum(), events=lambda t, q, s_dot: 1.0 if t < 0.5 else np.nan),
     pq.SimulationError, r"events\[0\] .*: returned nan at t = 0.5"),
    ("event-array", lambda tmp: _run(_pendulum(), events=lambda t, q, s_dot: q), ValueError,
     r"^events\[0\] .*: must return one real number"),
    ("force-law-raises", lambda tmp: _run(_pendulum(forces=[pq.JointForce("bob", motor_torque)])), pq.SimulationError,
     r"failed at t = 0.1.* RuntimeError in motor_torque \(.*test_bad_input.py:\d+\): the motor model broke"),
    ("constraints-raise", lambda tmp: _slider(constraints=lambda q, q_dot, t: 1 / 0, n_c=1), ValueError,
     r"^constraints: .*<lambda> raised ZeroDivisionError"),
    ("constraints-shape", lambda tmp: _slider(constraints=lambda q, q_dot, t: [0.0, 0.0], n_c=1), ValueError,
     r"^constraints \(.*\) at t = 0: expected shape \(1,\)"),
    ("user-joint-not-a-rotation", lambda tmp: _slider(pose=lambda q, t: (np.diag([2.0, 1, 1]), np.array([q[0], 0, 0]))),
     ValueError, r"^pose A: is not a rotation matrix .*\|AᵀA − I\| = 3"),
    ("beam-quadrature", lambda tmp: pq.RitzBeam(1.0, 1.0, 1.0, n_v=6, quadrature_order=2), ValueError,
     r"^quadrature_order: 2 Gauss points .* degree 3 .* reach degree 14; give at least 8"),
    ("beam-derivatives", lambda tmp: pq.RitzBeam(1.0, 1.0, 1.0, n_v=3, n_w=0, family=_shifted_derivative_family),
     ValueError, r"^family: Φ′ of the Ritz functions \[0, 1, 2\] for v is not the derivative of Φ"),
    ("beam-memory", lambda tmp: pq.RitzBeam(1.0, 1.0, 1.0, n_v=100_000), ValueError,
     r"^n_v, n_w, n_u, n_beta: 100004 Ritz functions make each n_y × n_y matrix of the beam 74.5 GiB"),
    ("beam-count-text", lambda tmp: pq.RitzBeam(1.0, 1.0, 1.0, n_v="four"), ValueError,
     r"^n_v: number of Ritz functions must be a non-negative integer, got 'four'"),
    ("beam-axis-moves-nothing", lambda tmp: _run(pq.System({"b": pq.RitzBeam(1.0, 1.0, 1.0, n_v=2, n_w=2)},
                                                           {"b": pq.Revolute(axis="x")})),
     pq.SingularMassError, r"joint 'b' is singular .* minimal velocities \[1.0, 0.0, 0.0, 0.0, 0.0\] moves no mass"),
    ("nan-state-pivot", lambda tmp: pq.scenes.chain(3).evaluator("recursive").accelerations(
        np.array([0.1, np.nan, 0.2]), np.zeros(3), 0.0), FloatingPointError, r"is not finite .* NaN or overflowed"),
    ("eigenvalue-sweep-empty", lambda tmp: pq.eigenvalue_sweep(lambda v: _pendulum(), []), ValueError,
     r"^values: the sweep is empty"),
    ("joint-spring-q-ref", lambda tmp: _pendulum(forces=[pq.JointSpring("bob", 1.0, q_ref=[0.0, 1.0])]), ValueError,
     r"^q_ref: joint 'bob' has 1 coordinate\(s\); give one number or 1, got shape \(2,\)"),
    ("load-foreign", lambda tmp: _load(tmp, "foreign"), ValueError, r"^path: .* is not a projeq Result .* lacks \['meta'"),
    ("load-random", lambda tmp: _load(tmp, "random"), ValueError, r"^path: .* is not a projeq Result"),
    ("load-truncated", lambda tmp: _load(tmp, "truncated"), ValueError, r"^path: .* is a truncated or damaged archive"),
    ("load-pickled-npy", lambda tmp: _load(tmp, "pickled"), ValueError, r"^path: .*run.npy' is not a projeq Result"),
    ("load-inconsistent", lambda tmp: _load(tmp, "inconsistent"), ValueError,
     r"^path: .* field 'q' has shape \(3, 1\) where t has 5 rows: expected \(5, 1\), one column per coordinate"),
]


@pytest.mark.parametrize("call, error, words", [row[1:] for row in BAD_INPUT], ids=[row[0] for row in BAD_INPUT])
def test_bad_input_is_refused_by_name(tmp_path, call, error, words):
    """Passes if each bad input of the table raises its exception with a message that names the
    parameter, the value and what is expected (issue 20: 11 silently accepted, 34 unclear)."""
    with pytest.raises(error, match=words):
        call(tmp_path)


def test_sweep_output_out_of_range_is_named_per_point():
    """Passes if an output q<i> beyond a point's coordinates fails that point with a message
    naming the output and the valid range (chain(n) has n coordinates: q2 exists for n = 3 only)."""
    table = pq.sweep("chain", grid={"n": [2, 3]}, outputs=["q2"], t_end=0.01, progress=False, workers=1)
    assert table["status"].tolist() == [-1, 0]
    assert table["error"][0] == "ValueError: outputs: 'q2' asks for q[2], but this point's model has 2 (q0 … q1)"


def _slip_after_half_a_second(q, q_dot, t):
    """A velocity constraint's residual that fails after 0.5 s (a slip model out of its range)."""
    if t > 0.5:
        raise RuntimeError("the slip model is undefined here")
    return [q_dot[0]]


def _circle_until_x_below(limit):
    """Φ = |r| − 1 of a pendulum on two sliders, failing once x drops below ``limit``."""
    def circle(q, t):
        if np.real(q[0]) < limit:
            raise RuntimeError("the circle is left")
        return [np.hypot(q[0], q[1]) - 1.0]
    return circle


def _sliding_pendulum(phi):
    tree = pq.System({"x": pq.Frame(), "bob": pq.PointMass(1.0)},
                     {"x": pq.Prismatic(axis="x"), "bob": pq.Prismatic(parent="x", axis="z")}, gravity=(0, 0, -9.81))
    return pq.ConstrainedSystem(tree, phi=phi, q0=[0.6, -0.8], independent=[0])


@pytest.mark.parametrize("system, words, t_kept", [
    (pq.System({"d": pq.RigidBody(**ROD)}, {"d": _slider(constraints=_slip_after_half_a_second, n_c=1)}),
     r"^integration failed at t = 0\.6 s .*constraints: _slip_after_half_a_second raised RuntimeError: "
     r"the slip model is undefined here at t = 0\.6.*the trajectory up to t = 0\.5 s is in \.result", 0.5),
    (_sliding_pendulum(_circle_until_x_below(0.3)),
     r"^integration failed at t = 0\.3\d* s .*RuntimeError in _circle_until_x_below.<locals>.circle \(.*test_bad_input.py:\d+\): the circle is "
     r"left; the trajectory up to t = 0\.3 s is in \.result", 0.3),
], ids=["user-joint-residual", "constrained-system-phi"])
def test_a_constraint_function_that_raises_late_fails_the_run_and_keeps_the_trajectory(system, words, t_kept):
    """A constraint function that raises only late in the run: a UserJoint's residual function
    (evaluated for the output rows, after the integration) and a ConstrainedSystem's Φ (in the
    right-hand side). Either way a SimulationError naming the function and the time, with the
    rows before it in ``.result`` (issue 20: the residual's failure lost the whole run)."""
    with pytest.raises(pq.SimulationError, match=words) as info:
        pq.simulate(system, 1.0, n_points=11)
    result = info.value.result
    assert result.status == -1 and np.allclose(result.t, np.arange(0.0, t_kept + 0.05, 0.1), rtol=0,
                                               atol=100 * np.finfo(float).eps)  # measured 0
    assert np.all(np.isfinite(result.q)) and result.constraint_residual.shape == (len(result.t), 1)
    assert isinstance(info.value.__cause__, (ValueError, RuntimeError))


def test_a_joint_spring_needs_rates_equal_to_speeds_everywhere():
    """Passes if a JointSpring on a planar joint is refused: its K(q) = diag(R(θ), 1) is E at
    θ = 0 only, where the check looked, so −k (q − q_ref) was applied to the body-axis speeds ṡ
    instead of Kᵀ ∇V. Before, a planar body on such a spring, started at rest at (0.5 m, 0, 1 rad),
    gained and lost energy: max |E − E₀| = 6 % of E₀ = 6.25 J over 2 s at rtol 1e-10 (energy
    conservation, the reference). On a revolute joint (K = E) the same law is accepted."""
    spring = pq.JointSpring("b", 10.0)
    with pytest.raises(ValueError, match="^joint: JointSpring needs q̇ = ṡ, which joint 'b' does not have"):
        pq.System({"b": pq.PlanarBody(1.0, I_c=0.1)}, {"b": pq.Planar()}, forces=[spring])
    assert _pendulum(forces=[pq.JointSpring("bob", 10.0)]).forces[0].stiffness == 10.0


class _DragWithoutReturn(pq.ForceLaw):
    """A user's law whose bind forgets ``return self`` (the contract: bind returns the law)."""

    def bind(self, system):
        self.n = system.index("bob")

    def add_to(self, h, kin, t, q, s_dot):
        h[self.n][3:] -= 0.1 * kin.twist[self.n][3:]


def test_a_force_law_whose_bind_returns_nothing_is_named():
    """Passes if the System names the law and the remedy when its bind returns None; before, None
    was kept as the bound law and every evaluation failed deep inside with "AttributeError:
    'NoneType' object has no attribute 'compiled_terms'"."""
    with pytest.raises(ValueError, match=r"^forces\[0\]: _DragWithoutReturn.bind returned None, not the bound law; "
                                         r"end bind with `return self`"):
        _pendulum(forces=[_DragWithoutReturn()])


def test_system_K_and_generalized_force_take_plain_lists():
    """Passes if K and generalized_force accept q and τ as lists, like every other System method:
    a revolute joint's K = E, and τ on its one velocity is Q = τ. Before, numpy read the list in
    np.result_type as a structured dtype: "TypeError: Field elements must be 2- or 3-tuples, got '0.3'"."""
    system = _pendulum()
    assert system.K([0.3]).tolist() == [[1.0]]
    assert system.generalized_force([0.3], 0.0, {"bob": [2.5]}).tolist() == [2.5]


@pytest.mark.parametrize("joint", [pq.Revolute(axis="y"), pq.Free()], ids=["Revolute", "Free"])
def test_system_q_dot_takes_plain_lists(joint):
    """Passes if q̇ from lists equals K(q) ṡ, the block-diagonal K of the joints formed apart
    (docs/theory.md, "Kinematic chain and joints"), for a revolute joint (K = E) and a free joint (quaternion rates).
    Before, numpy read the list in np.result_type as a structured dtype: "TypeError: Field
    elements must be 2- or 3-tuples, got '0.3'"."""
    system = pq.System({"b": pq.RigidBody(**ROD)}, {"b": joint})
    q = np.linspace(0.3, 0.9, system.n_q)
    s_dot = np.linspace(-1.0, 2.0, system.n_s)
    np.testing.assert_allclose(system.q_dot(q.tolist(), s_dot.tolist()), system.K(q) @ s_dot, rtol=1e-15, atol=1e-15)


@pytest.mark.parametrize("call, message", [
    (lambda: pq.scenes.double_pendulum().state(q=[0.1, 0.2]),
     r"^q: expected a dict \{name: value\} of the entries to set, got \[0.1, 0.2\]"),
    (lambda: pq.scenes.double_pendulum().state(q={"bob1": 0.1}, bob1=0.5),
     r"^q: \['bob1'\] set both in q and by keyword; give each once"),
    (lambda: pq.scenes.four_bar().state(crank=0.6),
     r"^q: violates the loop closures Φ\(q\) = \[-0.0849  0.0976\]; give a consistent q"),
    (lambda: pq.scenes.double_pendulum().state(bob1="up"), r"^q\['bob1'\] \(bob1.angle\): expected numbers, got 'up'"),
    (lambda: pq.scenes.double_pendulum().state(s_dot={"bob2.angle_dot": [1.0, 2.0]}),
     r"^s_dot\['bob2.angle_dot'\] \(bob2.angle_dot\): expected 1 entries, got shape \(2,\)"),
], ids=["q-a-list", "set-twice", "open-loop", "a-word", "two-values"])
def test_model_state_refuses_what_it_cannot_mean(call, message):
    """Passes if each is a ValueError naming q. Before: a list was "TypeError: cannot convert
    dictionary update sequence element #0 to a sequence"; q={"bob1": 0.1} beside bob1=0.5 took 0.5
    without a word; and the four-bar's state(crank=0.6), documented to have to close its loop,
    returned the open loop (|Φ| = 0.1 m), which simulate then moved onto Φ = 0 by minimum norm,
    starting the run at crank = 0.535, not 0.6 (ConstrainedSystem.project, the reference); bob1="up"
    said "could not convert string to float" without naming the coordinate (issue 37)."""
    with pytest.raises(ValueError, match=message):
        call()


@pytest.mark.parametrize("joint", [pq.Fixed(), pq.Prescribed(pq.Revolute(axis="y"), "sin(t)")], ids=["Fixed", "Prescribed"])
def test_a_joint_spring_on_a_joint_without_coordinates_is_refused(joint):
    """Passes if a JointSpring (k = 100 N m/rad) on a fixed or prescribed joint, which has no
    coordinate for it to act on, is refused by name; before, it was accepted and did nothing
    (its τ had n_s = 0 entries)."""
    with pytest.raises(ValueError, match=rf"^joint: joint 'b' \({type(joint).__name__}\) has no coordinates of its "
                                         r"own; a JointSpring on it would act on nothing"):
        pq.System({"a": pq.RigidBody(**ROD), "b": pq.RigidBody(**ROD)}, {"a": pq.Revolute(axis="x"), "b": joint},
                  forces=[pq.JointSpring("b", 100.0)])


@pytest.mark.parametrize("names, message", [
    (("a", "a.b"), r"^subsystems\['a.b'\]: a name must not contain '.', .*it would shadow the subsystem 'a'; use "
                   r"another character, e.g. 'a_b'"),
    (("x.y",), r"^subsystems\['x.y'\]: a name must not contain '.', which separates a subsystem from its coordinate"),
    (("",), r"^subsystems: a name must be a non-empty string, got ''"),
], ids=["shadowing", "dotted", "empty"])
def test_subsystem_names_are_unambiguous(names, message):
    """Passes if a subsystem name with '.' (or an empty one) is refused at construction, naming it.
    Before (issue 37), subsystems 'a' and 'a.b' were both accepted: q_index('a') spanned both and
    state(a=...) set a.b's angle too, as full names are split at the first '.'."""
    subsystems = {name: pq.RigidBody(**ROD) for name in names}
    joints = {name: pq.Revolute(axis="y", parent=names[0] if i else None) for i, name in enumerate(names)}
    with pytest.raises(ValueError, match=message):
        pq.System(subsystems, joints)

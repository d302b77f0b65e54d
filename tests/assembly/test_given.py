"""Joints of kind GIVEN in compiled code (:mod:`projeq.assembly.given`): the fast evaluator's one-call
ẋ = (q̇, s̈) and ∂ẋ/∂x, and its s̈ through the joints' C callbacks, against the reference evaluators
(recursive and dense numpy paths, q̇ by the System's own ``q_dot``) and the complex step through them;
Planar's and Free's printed values against their own ``relative_values`` and ``K``."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import projeq as pq
from projeq.analysis.jacobians import exact_jacobian

EPS = np.finfo(float).eps
LINK = {"r_c": (0.0, 0.0, -0.5), "I_c": np.diag([0.08, 0.09, 0.01])}


def _link(m=1.0):
    return pq.RigidBody(m, **LINK)


def _planar_tree():
    """A body on a Planar joint in the z–x plane with two links below it (3D revolute joints)."""
    body = pq.RigidBody(2.0, r_c=(0.1, 0.0, 0.2), I_c=np.diag([0.3, 0.4, 0.5]))
    return pq.System({"body": body, "a": _link(), "b": _link(0.7)},
                     {"body": pq.Planar(plane="zx", r_pn=(0.1, 0.2, 0.0)), "a": pq.Revolute("body", axis="y"),
                      "b": pq.Revolute("a", axis=(0.6, 0.0, 0.8), r_pn=(0.0, 0.0, -1.0))})


def _free_tree():
    """A body on a Free joint with two links below it."""
    body = pq.RigidBody(2.0, r_c=(0.1, -0.1, 0.2), I_c=np.diag([0.3, 0.4, 0.5]))
    return pq.System({"body": body, "a": _link(), "b": _link(0.7)},
                     {"body": pq.Free(), "a": pq.Revolute("body", axis="y"),
                      "b": pq.Prismatic("a", axis="z", r_pn=(0.0, 0.0, -1.0))})


def _prescribed_tree():
    """A hub turned by a motion given in sympy, two links below it."""
    hub = pq.Prescribed(pq.Revolute(axis=(0.0, 0.6, 0.8), r_pn=(0.2, 0.0, 0.1)), "0.5*sin(2*t) + 0.3*t**2")
    return pq.System({"hub": pq.RigidBody(1.5, r_c=(0.3, 0.0, 0.0), I_c=np.diag([0.1, 0.2, 0.3])),
                      "a": _link(), "b": _link(0.7)},
                     {"hub": hub, "a": pq.Revolute("hub", axis="x", r_pn=(0.5, 0.0, 0.0)),
                      "b": pq.Revolute("a", axis="y", r_pn=(0.0, 0.0, -1.0))})


def _sliding_joint(parent):
    """A UserJoint from sympy with K ≠ E: a body that slides along its own x-axis and turns about z
    (Bremer's car, B(11)), its heading θ moved besides at the rate k = 0.2 cos t."""
    x, y, theta, t = sp.symbols("x y theta t")
    v, w = sp.symbols("v w")
    c, s = sp.cos(theta), sp.sin(theta)
    A = sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    F = sp.Matrix([[1, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0, 1]])
    K = sp.Matrix([[c, 0], [s, 0], [0, 1]])
    return pq.UserJoint.from_sympy([x, y, theta], [v, w], A, [x, y, 0], F, K, t=t,
                                   f=[0, 0, 0, 0, 0, 0.2 * sp.cos(t)], k=[0, 0, 0.2 * sp.cos(t)], parent=parent)


def _mixed_tree():
    """Prescribed, Planar, Revolute, Free and a UserJoint from sympy with K ≠ E and a rheonomic k in one tree."""
    hub = pq.Prescribed(pq.Revolute(axis="z"), "0.4*cos(3*t)")
    body = pq.RigidBody(2.0, r_c=(0.1, -0.1, 0.2), I_c=np.diag([0.3, 0.4, 0.5]))
    joints = {"hub": hub, "slider": pq.Planar("hub", plane="xy", r_pn=(0.3, 0.0, 0.0)),
              "arm": pq.Revolute("slider", axis="x"), "free": pq.Free("arm", r_pn=(0.0, 0.0, -1.0)),
              "sled": _sliding_joint("free")}
    return pq.System({"hub": pq.RigidBody(1.0, r_c=(0.1, 0.0, 0.0), I_c=np.diag([0.1, 0.2, 0.3])),
                      "slider": body, "arm": _link(), "free": body, "sled": _link(0.4)}, joints)


def _elastic_tree():
    """A RitzBeam on a revolute joint below a Planar-jointed body, a Free-jointed tip body at its end (the
    beam's q̇_e = ṡ_e between the joints' rows in q̇)."""
    beam = pq.RitzBeam(1.2, 1.5, 25.0, EI_y=35.0, n_v=2, n_w=1, family="clamped_free", damping=0.02)
    body = pq.RigidBody(2.0, r_c=(0.1, -0.1, 0.2), I_c=np.diag([0.3, 0.4, 0.5]))
    return pq.System({"body": body, "beam": beam, "tip": _link()},
                     {"body": pq.Planar(plane="zx"), "beam": pq.Revolute("body", axis="y"),
                      "tip": pq.Free("beam", r_pn=(1.2, 0.0, 0.0))}, gravity=(0.0, 0.0, -9.81))


def _beam_on_planar_tree():
    """A RitzBeam on a Planar joint (n_s = 3 < 6: the row's q̇ follows F⁶'s three columns, where the
    chain kernel must not read a fourth column of F⁶ for the beam's first elastic column), a rigid body on
    its tip station."""
    beam = pq.RitzBeam(1.0, 2.0, 50.0, EI_y=40.0, n_v=2, n_w=1, family="clamped_free")
    return pq.System({"beam": beam, "tip": _link(0.5)},
                     {"beam": pq.Planar(plane="xy"), "tip": pq.Revolute("beam", axis="z", r_pn=(1.0, 0.0, 0.0))},
                     gravity=(0.0, 0.0, -9.81))


ELASTIC = {"elastic": _elastic_tree, "beam_on_planar": _beam_on_planar_tree}
MODELS = {
    "rolling_disk": pq.scenes.rolling_disk, "car": pq.scenes.car, "knife_edge_disc": pq.scenes.knife_edge_disc,
    "planar": _planar_tree, "free": _free_tree, "prescribed": _prescribed_tree, "mixed": _mixed_tree,
}


def _state(model, seed: int):
    """A random state near q0 (a Free joint's quaternion off the unit sphere) and t."""
    rng = np.random.default_rng(seed)
    q = np.array(model.q0, dtype=float) + 0.2 * rng.standard_normal(model.n_q)
    s_dot = np.array(getattr(model, "s_dot0", np.zeros(model.n_s)), dtype=float) + rng.standard_normal(model.n_s)
    return np.concatenate((q, s_dot)), 0.3 + rng.random()


def _reference(model, method: str, t: float):
    """ẋ = (q̇, s̈) by the System's q_dot and the numpy evaluator ``method`` (complex-safe)."""
    ev, n_q = model.evaluator(method), model.n_q
    return lambda x: np.concatenate((model.q_dot(x[:n_q], x[n_q:], t), ev.accelerations(x[:n_q], x[n_q:], t)))


@pytest.mark.parametrize("name", [*sorted(MODELS), *ELASTIC])
def test_one_call_state_derivative_is_the_reference(name):
    """ẋ of the one-call kernel (the joints' rows by their C callbacks, q̇ of K ≠ E joints from the rows)
    and the fast s̈ = the recursive and dense numpy paths' to round-off, at two random states; the
    one-call path is taken (not None). With a RitzBeam in the tree (the kernels' variant that reads
    each body's n_y) ẋ only: the complex step through the recursive evaluator's beam terms differs from
    the kernel's by 4e-11 of the largest entry already on the same tree with revolute joints only (before
    the GIVEN joints were compiled), which no 1e-12 bound on a Jacobian of this tree could tell apart."""
    model = {**MODELS, **ELASTIC}[name]()
    fast = model.evaluator("fast")
    for seed in range(2):
        x, t = _state(model, seed)
        x_dot = fast.state_derivative(t, x)
        assert x_dot is not None
        for method in ("recursive", "dense"):
            want = _reference(model, method, t)(x)
            scale = np.abs(want).max()
            assert np.abs(x_dot - want).max() <= 1e-13 * scale, method
            s_ddot = fast.accelerations(x[:model.n_q], x[model.n_q:], t)
            assert np.abs(s_ddot - want[model.n_q:]).max() <= 1e-13 * scale, method


@pytest.mark.parametrize("name", sorted(MODELS))
def test_one_call_jacobian_is_the_complex_step_through_the_reference(name):
    """∂ẋ/∂x of the one-call kernel (complex callbacks, ∂q̇/∂q of K ≠ E joints included) = the complex
    step column by column through the recursive evaluator and the System's q_dot."""
    model = MODELS[name]()
    x, t = _state(model, 5)
    J = model.evaluator("fast").state_jacobian(t, x)
    assert J is not None
    want = exact_jacobian(_reference(model, "recursive", t), x)
    # measured 1.8e-15 of the largest entry (was 1e-12)
    assert np.abs(J - want).max() <= 100 * EPS * np.abs(want).max()


@pytest.mark.parametrize("joint", [pq.Planar(plane="zx"), pq.Planar(plane="xy"), pq.Free()], ids=["zx", "xy", "free"])
def test_planar_and_free_compiled_values_are_their_relative_values(joint):
    """The printed row = relative_values, then K ṡ, at random states (Free's quaternion off the unit
    sphere), and so are its derivatives (the complex step through both)."""
    values = joint.compiled_values()
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, s_dot, t = rng.standard_normal(joint.n_q), rng.standard_normal(joint.n_s), 0.4

        def row(q, s_dot=s_dot, t=t):
            return np.concatenate((joint.relative_values(q, s_dot.astype(q.dtype), t), joint.K(q, t) @ s_dot))

        assert np.abs(values(q, s_dot, t) - row(q)).max() <= 1e-14 * np.abs(row(q)).max()
        for k in range(joint.n_q):
            z = q + 1e-30j * np.eye(joint.n_q)[k]
            got, want = values(z, s_dot.astype(complex), t).imag, row(z).imag
            assert np.abs(got - want).max() <= 1e-14 * max(np.abs(want).max(), 1e-30)


def test_a_user_joint_from_callables_keeps_the_python_path():
    """A joint without compiled values (a UserJoint from callables): no one-call ẋ or ∂ẋ/∂x (None), s̈
    by its relative_values in Python, = the reference."""
    def pose(q, t):
        c, s = np.cos(q[2]), np.sin(q[2])
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), np.array([q[0], q[1], 0.0])

    def K(q, t):
        c, s = np.cos(q[2]), np.sin(q[2])
        return np.array([[c, 0.0], [s, 0.0], [0.0, 1.0]])

    joint = pq.UserJoint.from_functions(3, 2, pose, lambda q, t: np.array([[1.0, 0], [0, 0], [0, 0], [0, 0], [0, 0],
                                                                           [0, 1.0]]), K)
    model = pq.System({"car": pq.RigidBody(2.0, r_c=(0.3, 0.0, 0.0), I_c=np.diag([0.1, 0.2, 0.3])), "a": _link()},
                      {"car": joint, "a": pq.Revolute("car", axis="x")})
    fast = model.evaluator("fast")
    x, t = _state(model, 1)
    assert joint.compiled_values() is None
    assert fast.state_derivative(t, x) is None and fast.state_jacobian(t, x) is None
    want = _reference(model, "recursive", t)(x)[model.n_q:]
    # measured 1.7e-16 of the largest entry (was 1e-13)
    assert np.abs(fast.accelerations(x[:model.n_q], x[model.n_q:], t) - want).max() <= 100 * EPS * np.abs(want).max()


@pytest.mark.parametrize("extra", [1, -2], ids=["longer", "shorter"])
def test_a_state_of_another_size_is_refused_by_name(extra):
    """The one-call kernels read n_q + n_s entries of x without bounds checks: another size (a constrained
    system's state handed to its tree) is a ValueError naming x and the size, not memory read or written
    past its end."""
    model = pq.scenes.rolling_disk()
    fast = model.evaluator("fast")
    x = np.zeros(model.n_q + model.n_s + extra)
    for one_call in (fast.state_derivative, fast.state_jacobian):
        with pytest.raises(ValueError, match=r"x: expected the tree's state \(q, ṡ\) of n_q \+ n_s = 8 entries"):
            one_call(0.0, x)


def test_the_interpreted_kernels_are_the_reference():
    """compiled=False runs the same one-call source interpreted (the joints' printed functions called as
    they are, q̇ from their rows): ẋ = the recursive path's on the mixed tree."""
    from projeq.assembly.fast import FastEvaluator

    model = _mixed_tree()
    x, t = _state(model, 3)
    x_dot = FastEvaluator(model, compiled=False).state_derivative(t, x)
    want = _reference(model, "recursive", t)(x)
    assert np.abs(x_dot - want).max() <= 100 * EPS * np.abs(want).max()  # measured 5.2e-16 of it (was 1e-13)


def test_a_hub_beam_on_a_motion_in_sympy_reads_it_by_its_callback():
    """A RitzBeam on a Prescribed hub whose motion is given in sympy (method "hub_beam"): the hub's row by
    its C callback in one compiled call per evaluation; s̈ and the one-call ẋ = (ṡ, s̈) = the recursive
    evaluator's to round-off at three times."""
    beam = pq.RitzBeam(1.2, 1.5, 25.0, EI_y=35.0, n_v=3, n_w=2, family="clamped_free", damping=0.02)
    hub = pq.Prescribed(pq.Revolute(axis=(0.3, -0.5, 0.8), r_pn=(0.1, 0.2, -0.1)), "0.5*sin(2*t) + 0.3*t**2")
    model = pq.System({"beam": beam}, {"beam": hub}, gravity=(0.0, 0.0, -9.81))
    ev = model.evaluator("hub_beam")
    rng = np.random.default_rng(4)
    for t in (0.3, 2.0, 7.5):
        q, s_dot = 0.05 * rng.standard_normal(model.n_q), rng.standard_normal(model.n_s)
        want = model.accelerations(q, s_dot, t, method="recursive")
        scale = max(1.0, np.abs(want).max())  # measured ≤ 4.3e-16 of it (was 1e-13)
        assert np.abs(ev.accelerations(q, s_dot, t) - want).max() <= 100 * EPS * scale
        x_dot = ev.state_derivative(t, np.concatenate((q, s_dot)))
        assert np.abs(x_dot - np.concatenate((s_dot, want))).max() <= 100 * EPS * scale


@pytest.mark.parametrize("scene", ["whipple_bicycle", "car"])
def test_output_rows_energies_in_one_compiled_call(scene, monkeypatch):
    """The energies of a run's output rows on a tree with joints of kind GIVEN (the bicycle's rear frame,
    the car's rolling joint) take one compiled call per chunk of rows (given.rows_kernel: each row's
    relative motions by their callbacks, then its kinematics), equal bit for bit (measured 0.0) to the
    rows one at a time with the joints' relative motions from Python."""
    from projeq.assembly import given

    system = getattr(pq.scenes, scene)()
    ev = system.tree.evaluator("fast")
    result = pq.simulate(system, 1.0, n_points=51)
    s_tree = np.array([system.tree_velocities(q, s, t) if hasattr(system, "tree_velocities") else s
                       for q, s, t in zip(result.q, result.s_dot, result.t)])
    calls, kernel = [], given.rows_kernel
    monkeypatch.setattr(given, "rows_kernel", lambda: (calls.append(1), kernel())[1])
    together = ev.energies(result.q, s_tree, result.t)
    assert calls
    monkeypatch.setattr(ev, "_given_motions", None)  # the joints' relative_values, a row at a time
    assert np.array_equal(together, ev.energies(result.q, s_tree, result.t))

"""A Prescribed joint moved by a callable t -> (θ, θ̇, θ̈) stays compiled (projeq/assembly/given.py,
``motion_callbacks``): the callable is printed from its source with the numbers it reads as data (or
compiled by numba.njit with them frozen), its values checked against its own, and the joint's row
printed at θ, θ̇, θ̈ — as a load given as a callable is (projeq/assembly/generated.py). Checked against
the recursive evaluator (the callable run as Python), the same motion given in sympy, and a run of
each; a callable numba cannot compile, or whose compiled values differ from its own, is named once."""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.assembly import PythonPieceWarning

numba = pytest.importorskip("numba")

OMEGA, A, W = 2.0, 0.3, 5.0  # θ = Ω t + a sin ωt


def _spin(omega, a, w):
    """θ(t) = Ω t + a sin ωt and its rates, a closure over its numbers."""
    return lambda t: (omega * t + a * np.sin(w * t), omega + a * w * np.cos(w * t), -a * w**2 * np.sin(w * t))


def _hub_chain(motion) -> pq.System:
    """A hub turned by ``motion`` about an oblique axis, two links hanging below it under gravity."""
    link = {"r_c": (0.0, 0.0, -0.5), "I_c": np.diag([0.08, 0.09, 0.01])}
    hub = pq.Prescribed(pq.Revolute(axis=(0.0, 0.6, 0.8), r_pn=(0.2, 0.0, 0.1)), motion)
    return pq.System({"hub": pq.RigidBody(1.5, r_c=(0.3, 0.0, 0.0), I_c=np.diag([0.1, 0.2, 0.3])),
                      "a": pq.RigidBody(1.0, **link), "b": pq.RigidBody(0.7, **link)},
                     {"hub": hub, "a": pq.Revolute("hub", axis="x", r_pn=(0.5, 0.0, 0.0)),
                      "b": pq.Revolute("a", axis="y", r_pn=(0.0, 0.0, -1.0))},
                     gravity=(0.0, 0.0, -9.81), q0=(0.4, -0.3))


def _quiet(system):
    """The default evaluator, built with every warning an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return system.evaluator()


def _states():
    rng = np.random.default_rng(3)
    return [(t, rng.uniform(-1, 1, 2), rng.uniform(-2, 2, 2)) for t in (0.0, 0.8, 2.9)]


def test_a_callable_motion_runs_compiled_and_equals_the_reference():
    """No warning, the default evaluator compiled with nothing in Python (its reason says so), s̈ and the
    one-call ẋ = (q̇, s̈) = the recursive evaluator's (the callable in Python) and = the default
    evaluator's for the same motion given in sympy (its θ̇, θ̈ differentiated, then printed), relative to
    1 + |s̈|: measured 4.8e-16 against the recursive, 3.2e-16 between the two motions, bound 100 ε."""
    system, stated = _hub_chain(_spin(OMEGA, A, W)), _hub_chain(f"{OMEGA}*t + {A}*sin({W}*t)")
    ev, sympy_ev = _quiet(system), _quiet(stated)
    assert ev.name == "fast" and ev.evaluator.interpreted == [] and "in Python" not in ev.reason, ev.reason
    for t, q, s_dot in _states():
        reference = system.accelerations(q, s_dot, t, method="recursive")
        scale = 1 + np.abs(reference).max()
        x_dot = ev.state_derivative(t, np.concatenate((q, s_dot)))
        for found in (ev.accelerations(q, s_dot, t), x_dot[2:], sympy_ev.accelerations(q, s_dot, t)):
            assert np.abs(found - reference).max() <= 100 * np.finfo(float).eps * scale, (t, found, reference)
        assert np.array_equal(x_dot[:2], s_dot)


def test_a_run_driven_by_the_callable_is_the_run_driven_by_sympy():
    """pq.simulate of the chain driven by the callable and by the same motion in sympy, 3 s at rtol 1e-10:
    the same trajectory (the same kernels and steps, the motions' rows apart by round-off), measured
    1.4e-14 rad, bound 1.4e-13; the callable run's output rows (T, V by the compiled kinematics, the
    motion's callback at each row's t) = the recursive evaluator's energies there, relative to 1 + |E|:
    measured 2.2e-16, bound 100 ε."""
    system = _hub_chain(_spin(OMEGA, A, W))
    runs = [pq.simulate(model, 3.0, rtol=1e-10, atol=1e-12, n_points=31)
            for model in (system, _hub_chain(f"{OMEGA}*t + {A}*sin({W}*t)"))]
    assert np.abs(runs[0].q - runs[1].q).max() <= 1.4e-13
    rows = np.column_stack((runs[0].kinetic, runs[0].potential))
    reference = np.array([system.energy(q, s_dot, t, method="recursive")
                          for q, s_dot, t in zip(runs[0].q, runs[0].s_dot, runs[0].t)])
    error = np.abs(rows - reference).max() / (1 + np.abs(reference).max())
    assert error <= 100 * np.finfo(float).eps, error


class Profile:
    """A Python object numba cannot read: its method gives the hub's motion."""

    def motion(self, t):
        return OMEGA * t, OMEGA, 0.0


def _python_pieces(motion) -> tuple:
    """(warnings raised building the default evaluator of the chain moved by ``motion``, the evaluator)."""
    system = _hub_chain(motion)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        ev = system.evaluator()
    for t, q, s_dot in _states():  # the joint in Python: the reference's s̈, measured ≤ 8.2e-16, bound 100 ε
        reference = system.accelerations(q, s_dot, t, method="recursive")
        error = np.abs(ev.accelerations(q, s_dot, t) - reference).max()
        assert error <= 100 * np.finfo(float).eps * (1 + np.abs(reference).max()), (t, error)
    return [str(w.message) for w in said if issubclass(w.category, PythonPieceWarning)], ev


def test_a_callable_numba_cannot_compile_runs_in_python_named_once():
    """A callable that calls a Python object's method: one PythonPieceWarning naming the joint, the
    callable, why and how to compile it; the default evaluator says the joint runs in Python."""
    profile = Profile()
    said, ev = _python_pieces(lambda t: profile.motion(t))
    assert len(said) == 1, said
    assert "joint 'hub' (Prescribed: numba cannot compile its motion" in said[0] and "<lambda>" in said[0]
    assert "a callable t -> (θ, θ̇, θ̈) written with numpy and math" in said[0]
    assert "joint 'hub' (Prescribed: numba cannot compile" in ev.reason and "in Python" in ev.reason


def test_compiled_values_that_differ_from_the_callables_own_are_caught():
    """θ = 10⁻²⁰ int(10¹⁰ t)² compiles, but numba's int64 square wraps past 2⁶³ (t = 0.37 of the check
    gives 1.4e19) where Python's integers do not: the check against the callable's own values refuses it,
    and the joint runs in Python, named once."""
    said, _ = _python_pieces(lambda t: (1e-20 * int(1e10 * t) ** 2, 2 * t, 2.0))
    assert len(said) == 1 and "differ from its own" in said[0], said


def test_the_hub_beam_path_names_a_callable_hub_motion_it_takes_from_python():
    """The hub-beam path (one RitzBeam on a Prescribed hub) keeps a callable motion's θ, θ̇, θ̈ in Python
    (printing its row would load sympy into ``projeq run``); the default evaluator's reason says so by the
    callable's name, without a warning; a motion in sympy is printed and compiled, and nothing is named."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        callable_hub = pq.scenes.spin_up_beam().evaluator()
    assert callable_hub.name == "hub_beam" and callable_hub.evaluator.interpreted, callable_hub.reason
    assert callable_hub.reason.startswith("one RitzBeam on a prescribed or fixed hub: the compiled kernel, with "
                                          "the hub's motion ") and callable_hub.reason.endswith(" in Python")
    system = pq.scenes.spin_up_beam()
    hub = system.joints[0]
    printed = pq.System(dict(zip(system.names, system.subsystems)),
                        {system.names[0]: pq.Prescribed(hub.joint, "0.5*t**2")})
    assert printed.evaluator().evaluator.interpreted == [] and "in Python" not in printed.evaluator().reason

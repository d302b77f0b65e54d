"""Loads that depend on time stay compiled: the fast evaluator's loop of force laws takes t
(projeq/assembly/loads.py), a load given as a callable (t, q, ṡ) — of a JointForce, Force or
Torque — is compiled by numba (projeq/assembly/generated.py, ``load_callbacks``) and a
``projeq.BodyLoad`` whose statement uses t runs in the loop. Checked against a closed form (the
undamped forced response of a spring-mass oscillator), against the reference evaluators
(recursive and dense, the callables run as Python) and the same kernels interpreted, and the
exact Jacobian against Richardson differences; a callable numba cannot compile is named once."""

import warnings

import numpy as np
import pytest

import projeq as pq
from projeq.assembly import InterpretedWarning, PythonPieceWarning
from projeq.assembly.fast import FastEvaluator

numba = pytest.importorskip("numba")

M, K, A, OMEGA = 2.0, 18.0, 1.5, 2.0  # ω0 = √(k/m) = 3 rad/s


def _no_warning(system):
    """The default evaluator, built with every warning an error: compiled, nothing in Python."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ev = system.evaluator()
    assert ev.name == "fast" and ev.evaluator.interpreted == []
    return ev


def test_a_driven_oscillator_reaches_the_closed_form_compiled():
    """m ẍ = −k x + a sin ωt, the spring and the drive both in the JointForce's callable τ(t, q, ṡ):
    compiled by default with no warning (ẋ in one compiled call); from rest the undamped forced
    response x(t) = (a/m)/(ω0² − ω²) (sin ωt − (ω/ω0) sin ω0 t), ω0² = k/m (S. S. Rao, *Mechanical
    Vibrations*, 5th ed., 2011, §3.3): measured 6.0e-11 m over 5 s at rtol 1e-10, bound 6e-10."""
    k, a, omega = K, A, OMEGA
    system = pq.System({"mass": pq.PointMass(M)}, {"mass": pq.Prismatic(axis="x")},
                       forces=[pq.JointForce("mass", lambda t, q, s_dot: -k * q[0] + a * np.sin(omega * t))])
    ev = _no_warning(system)
    assert ev.state_derivative(0.3, np.array([0.1, 0.2])) is not None
    result = pq.simulate(system, 5.0, rtol=1e-10, atol=1e-12)
    w0 = np.sqrt(K / M)
    x = (A / M) / (w0**2 - OMEGA**2) * (np.sin(OMEGA * result.t) - OMEGA / w0 * np.sin(w0 * result.t))
    error = np.abs(result.q[:, 0] - x).max()
    assert error <= 6e-10, error


class Push(pq.BodyLoad):
    """A force a (cos ωt, sin ωt, 0) at the body's origin and a moment a sin(ωt) v_x about z, body
    coordinates: its statement uses t."""

    def __init__(self, body, a, omega):
        super().__init__(body)
        self.a, self.omega = float(a), float(omega)

    def statement(self, R, r, v, omega, t, m):
        c, s = m.cos(self.omega * t), m.sin(self.omega * t)
        return m.vector([self.a * c, self.a * s, 0.0, 0.0, 0.0, self.a * s * v[0]])


def _arm(rigid_last_link: bool = False) -> pq.System:
    """scenes.flexible_arm() (a RitzBeam last link, or its rigid twin) under loads of t, q and ṡ of every
    kind."""
    base = pq.scenes.flexible_arm(rigid_last_link)
    amp = np.array([0.0, 2.0, 0.5])
    laws = [pq.JointForce("upper", lambda t, q, s_dot: A * np.sin(OMEGA * t) - 0.3 * s_dot[0] + 0.2 * q[2]),
            pq.Force("fore", lambda t, q, s_dot: amp * np.cos(OMEGA * t + q[1]), point=(0.25, 0.0, 0.0)),
            pq.Torque("tip", lambda t, q, s_dot: (0.0, 0.0, 0.2 * np.sin(t)), frame="body"),
            Push("fore", 0.7, 1.3)]
    return pq.System(dict(zip(base.names, base.subsystems)), dict(zip(base.names, base.joints)),
                     gravity=base.gravity, forces=laws, q0=base.q0, s_dot0=base.s_dot0)


@pytest.mark.parametrize("rigid_last_link, bound", [(True, 1e-14), (False, 4e-9)], ids=["rigid twin", "beam"])
def test_time_loads_on_the_flexible_arm_equal_the_reference_evaluators(rigid_last_link, bound):
    """Every load of t on the arm compiled (no warning, ẋ in one call): s̈ at three times and states =
    the same kernels interpreted (the callables as Python; identical, measured 0) = the recursive and the
    dense evaluators, relative to 1 + |s̈|: the rigid twin measured 1.7e-15, bound 1e-14; with the stiff
    beam (|s̈| ~ 1e5) the evaluators differ by 3.9e-10 without any load too, bound 4e-9."""
    system = _arm(rigid_last_link)
    ev = _no_warning(system)
    interpreted = FastEvaluator(system, compiled=False)
    n_e = system.n_q - 3
    rng = np.random.default_rng(5)
    for t in (0.0, 0.7, 2.3):
        q = np.concatenate((rng.uniform(-1, 1, 3), rng.uniform(-1e-3, 1e-3, n_e)))
        s_dot = np.concatenate((rng.uniform(-1, 1, 3), rng.uniform(-1e-2, 1e-2, n_e)))
        reference = system.accelerations(q, s_dot, t, method="recursive")
        compiled = ev.accelerations(q, s_dot, t)
        assert np.array_equal(compiled, interpreted.accelerations(q, s_dot, t))
        x_dot = ev.state_derivative(t, np.concatenate((q, s_dot)))
        for found in (compiled, x_dot[system.n_q:], system.accelerations(q, s_dot, t, method="dense")):
            error = np.abs(found - reference).max() / (1 + np.abs(reference).max())
            assert error <= bound, (t, error)


@pytest.mark.parametrize("rigid_last_link, bound", [(True, 5e-15), (False, 5e-9)], ids=["rigid twin", "beam"])
def test_the_exact_jacobian_of_time_loads_in_one_compiled_call(rigid_last_link, bound):
    """∂ẋ/∂x with the loads' callables of q and ṡ in one compiled call (the complex step through the
    callables' complex callbacks) = the complex step column by column through the recursive evaluator
    (the callables as Python, on complex numbers), relative to 1 + |J|: the rigid twin measured 5.4e-16,
    bound 5e-15 (and Richardson differences of the recursive ẋ: measured 4.5e-12, bound 4.5e-11); with
    the stiff beam measured 4.9e-10 (as its s̈), bound 5e-9."""
    from projeq.analysis.differentiation import exact_jacobian, jacobian
    from projeq.analysis.jacobians import state_jacobian

    system, t = _arm(rigid_last_link), 0.9
    n_e = system.n_q - 3
    rng = np.random.default_rng(8)
    x = np.concatenate((rng.uniform(-1, 1, 3), rng.uniform(-1e-3, 1e-3, n_e), rng.uniform(-1, 1, 3),
                        rng.uniform(-1e-2, 1e-2, n_e)))
    assert system.evaluator().state_jacobian(t, x) is not None  # in one call
    J, how = state_jacobian(system, x, t)
    recursive = system.evaluator("recursive")

    def x_dot(z):
        q, s_dot = z[:system.n_q], z[system.n_q:]
        return np.concatenate((system.q_dot(q, s_dot, t), recursive.accelerations(q, s_dot, t)))

    reference = exact_jacobian(x_dot, x)
    error = np.abs(J - reference).max() / (1 + np.abs(reference).max())
    assert how == "exact" and error <= bound, (how, error)
    if rigid_last_link:
        error = np.abs(J - jacobian(x_dot, x)).max() / (1 + np.abs(reference).max())
        assert error <= 4.5e-11, error


def test_a_coupled_systems_callable_reads_the_systems_own_q():
    """Atwood's machine (joints coupled to the pulley): the callable gets the System's q and ṡ (one
    coordinate), not every joint's own (q_all = (θ, a θ, −a θ)) that the kernel reads; fast = dense at
    three times, measured 8.3e-16, bound 8e-15."""
    system = pq.scenes.atwood()
    system = pq.System(dict(zip(system.names, system.subsystems)), dict(zip(system.names, system.joints)),
                       gravity=system.gravity,
                       forces=[pq.JointForce("pulley", lambda t, q, s_dot: 2.0 * q[-1] - s_dot[-1] + np.sin(t))])
    _no_warning(system)
    for t, q, s_dot in ((0.0, 0.3, -0.2), (0.8, -1.1, 0.5), (2.0, 0.7, 1.3)):
        fast = system.accelerations([q], [s_dot], t, method="fast")
        dense = system.accelerations([q], [s_dot], t, method="dense")
        assert np.abs(fast - dense).max() <= 8e-15 * (1 + np.abs(dense).max()), (t, fast, dense)


class Profile:
    """A Python object numba cannot read: its method gives the drive's profile."""

    def value(self, t):
        return np.sin(OMEGA * t)


def test_a_callable_numba_cannot_compile_runs_in_python_named_once():
    """A callable that calls a Python object's method: numba refuses it, so its law runs in Python,
    with one PythonPieceWarning naming the law, the callable and how to compile it, and the
    reference's s̈ (measured 2.3e-16 of 1 + |s̈|, bound 2e-15); on the flexible arm (whose beam takes no law in Python)
    one InterpretedWarning naming it."""
    profile = Profile()
    law = pq.JointForce("link1", lambda t, q, s_dot: A * profile.value(t))
    chain = pq.scenes.chain(2)
    system = pq.System(dict(zip(chain.names, chain.subsystems)), dict(zip(chain.names, chain.joints)),
                       gravity=chain.gravity, forces=[law])
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        ev = system.evaluator()
    assert [type(w.message) for w in said] == [PythonPieceWarning], [str(w.message) for w in said]
    message = str(said[0].message)
    assert "force law JointForce (numba cannot compile its callable" in message and "<lambda>" in message
    assert "written with numpy and math" in message
    q, s_dot = np.array([0.3, -0.4]), np.array([0.5, 0.1])
    reference = system.accelerations(q, s_dot, 0.6, method="recursive")
    assert np.abs(ev.accelerations(q, s_dot, 0.6) - reference).max() <= 2e-15 * (1 + np.abs(reference).max())
    arm = pq.scenes.flexible_arm()
    arm = pq.System(dict(zip(arm.names, arm.subsystems)), dict(zip(arm.names, arm.joints)), gravity=arm.gravity,
                    forces=[pq.JointForce("upper", lambda t, q, s_dot: A * profile.value(t))])
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        assert arm.evaluator().name == "recursive"
    assert [type(w.message) for w in said] == [InterpretedWarning]
    assert "numba cannot compile its callable" in str(said[0].message)


def test_the_benchmark_runs_quick():
    """benchmarks/time_loads.py --quick: every model compiled with no warning, its ẋ in one call and
    equal to the recursive evaluator's (measured 5.2e-11 of 1 + |ẋ| on the stiff arm, bound 5e-10)."""
    import runpy
    from pathlib import Path

    benchmark = runpy.run_path(str(Path(__file__).parents[2] / "benchmarks" / "time_loads.py"))
    report = benchmark["main"](["--quick"])
    for scene in report.values():
        for check in scene["checks"].values():
            assert check["evaluator"] == "fast" and check["in Python"] == [] and check["one call"]
            assert check["vs recursive"] <= 5e-10, check

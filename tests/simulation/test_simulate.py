"""simulate(): integrators, tolerances, events, dense output, NPZ files, quaternions,
energies, prescribed motion, default states, progress and interruption.

The reference motion is a mathematical pendulum (point mass 1 kg on a 1 m massless rod,
g = 9.81 m/s²) released from rest at θ₀ = 1 rad, whose period is
T = 4 √(ℓ/g) K(sin²(θ₀/2)) with K the complete elliptic integral of the first kind
(parameter m = k²), e.g. Landau & Lifshitz, Mechanics, §11, problem 1.
"""

import warnings

import numpy as np
import pytest
from scipy.integrate import RK45
from scipy.special import ellipk

import projeq as pq
from projeq.assembly.kinematics import forward
from projeq.spatial import quaternion_matrix, rotation

THETA0 = 1.0
EPS = np.finfo(float).eps
PERIOD = 4.0 * np.sqrt(1.0 / 9.81) * ellipk(np.sin(THETA0 / 2) ** 2)


def _pendulum():
    return pq.System(
        {"bob": pq.PointMass(1.0, (0, 0, -1.0))}, {"bob": pq.Revolute(axis="y")}, gravity=(0, 0, -9.81)
    )


@pytest.fixture(scope="module")
def reference():
    """One period at rtol = atol = 1e-13 (DOP853): errors 1e-13 relative, far below what
    the tests below resolve (≥ 1e-5 · 1e-8)."""
    return pq.simulate(
        _pendulum(), PERIOD, [THETA0], [0.0], method="DOP853", rtol=1e-13, atol=1e-13, n_points=21
    )


def test_the_reference_returns_after_one_period(reference):
    """The closed-form period closes the orbit: θ(T) = θ₀ to 3e-14 rad, θ̇(T) = 0 to 7.1e-13 rad/s (measured
    3.0e-15 and 7.1e-14; were 1e-12)."""
    assert reference.q[-1, 0] == pytest.approx(THETA0, abs=3e-14)
    assert reference.s_dot[-1, 0] == pytest.approx(0.0, abs=7.1e-13)


#: bound of the global error over one period in units of rtol × amplitude, per method: 10× the larger
#: of the errors measured at rtol 1e-5 and 1e-8 (DOP853 2.5, Radau 0.16, RK45 1.6 — scipy's class 1.1 —,
#: RK23 5.0: the compiled loop's steps are one segment's, not cut short at the 20 segments' ends, where
#: DOP853 measured 0.026 and Radau 0.0079), 50 where 10× would be more (RK23; BDF 39 at 1e-5, a multistep
#: method whose error estimate is the least sharp; LSODA 27); all were 50
UNITS = {"DOP853": 25.0, "Radau": 1.6, "RK45": 16.0, "RK23": 50.0, "BDF": 50.0, "LSODA": 50.0}


@pytest.mark.parametrize("rtol", [1e-5, 1e-8])
@pytest.mark.parametrize(
    "method",
    ["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA", RK45],
    ids=["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA", "OdeSolver-class"],
)
def test_every_solve_ivp_method_follows_the_reference_to_its_tolerance(reference, method, rtol):
    """Error over one period in units of rtol × amplitude (per component of (θ, θ̇)),
    atol = rtol/100 so that rtol governs. solve_ivp bounds each step's *local* error by the
    tolerance; over a period these add up (as phase error), so the global error may be a
    few tens of units (UNITS: each method's bound, 10× its error measured at the larger of both rtol,
    at most the 50 units of before). The same bound at two tolerances 1000 apart shows that rtol
    reaches the integrator and that the error is proportional to it for every method."""
    result = pq.simulate(
        _pendulum(), PERIOD, [THETA0], [0.0], method=method, rtol=rtol, atol=rtol / 100, n_points=21
    )
    x, x_ref = np.hstack((result.q, result.s_dot)), np.hstack((reference.q, reference.s_dot))
    units = np.abs(x - x_ref) / (rtol * np.abs(x_ref).max(axis=0))
    assert units.max() < UNITS[result.method], units.max()
    assert result.method == getattr(method, "__name__", method)


def _bottom(t, q, s_dot):
    """θ = 0: the bob passes the lowest point."""
    return q[0]


def test_a_terminal_event_stops_the_run(tmp_path):
    """The first passage through θ = 0 ends the run at T/4: status 1, the event time in
    t_events (DOP853 at rtol 1e-10 locates it to 1e-9 s: the root is found on the dense
    output, accurate to the tolerance); the outputs are the requested times before it,
    then the event's own state as the last row (issue 18, item 5), the one in q_events:
    θ = 0 there to the root finder's step 4ε t times |θ̇| ≈ 3.3 rad/s (≈ 1e-15). The event
    fields survive an NPZ file unchanged."""

    def bottom(t, q, s_dot):
        return _bottom(t, q, s_dot)

    bottom.terminal = True
    result = pq.simulate(
        _pendulum(),
        5.0,
        [THETA0],
        [0.0],
        events=bottom,
        method="DOP853",
        rtol=1e-10,
        atol=1e-12,
        n_points=501,
    )
    assert result.status == 1 and result.success
    assert result.t_events[0] == pytest.approx([PERIOD / 4], abs=1e-9)
    assert result.t[-1] == result.t_events[0][0] and np.array_equal(result.q[-1], result.q_events[0][0])
    assert np.array_equal(result.s_dot[-1], result.s_dot_events[0][0])
    assert abs(result.q[-1, 0]) < 1e-14  # measured 3e-16
    assert PERIOD / 4 - 0.01 < result.t[-2] <= PERIOD / 4  # output spacing 5 s / 500
    assert np.all(result.q[:-1, 0] > 0)
    result.save(tmp_path / "run.npz")
    loaded = pq.Result.load(tmp_path / "run.npz")
    for name in ("t_events", "q_events", "s_dot_events"):
        assert len(getattr(loaded, name)) == 1 and np.array_equal(getattr(loaded, name)[0], getattr(result, name)[0])


@pytest.mark.parametrize(
    "direction, crossings", [(-1, [0.25]), (1, [0.75]), (0, [0.25, 0.75])], ids=["falling", "rising", "both"]
)
def test_the_direction_of_an_event_selects_its_crossings(direction, crossings):
    """Released at θ₀ > 0, θ falls through 0 at T/4 and rises through it at 3T/4; a
    non-terminal event with ``direction`` records only the matching crossings (1e-9 s as
    above) and the run goes on to the end."""

    def bottom(t, q, s_dot):
        return _bottom(t, q, s_dot)

    bottom.direction = direction
    result = pq.simulate(
        _pendulum(), PERIOD, [THETA0], [0.0], events=[bottom], method="DOP853", rtol=1e-10, atol=1e-12
    )
    assert result.status == 0 and result.t[-1] == PERIOD
    assert result.t_events[0] == pytest.approx(np.array(crossings) * PERIOD, abs=1e-9)


def test_dense_output_matches_the_output_times_and_t_eval():
    """``sol(t)`` is the integrator's own interpolant, the one that produced the outputs:
    at the output times it gives ``q`` and ``s_dot`` to round-off, and between them it
    gives what a run asking for those times returns (t_eval changes no step, only where
    the interpolant is read; a dense solution changes no step either)."""
    system = _pendulum()
    result = pq.simulate(system, 1.0, [THETA0], [0.0], dense_output=True, n_points=41)
    q, s_dot = result.sol(result.t)
    assert np.abs(q.T - result.q).max() < 1e-14 and np.abs(s_dot.T - result.s_dot).max() < 1e-14
    between = (result.t[:-1] + result.t[1:]) / 2
    other = pq.simulate(system, 1.0, [THETA0], [0.0], t_eval=between)
    assert np.abs(result.sol(between)[0].T - other.q).max() < 1e-14


def test_t_eval_sets_the_output_times(reference):
    """Exactly the requested times, starting after t_start if asked; the values agree
    with the reference at the shared times to 1.6 rtol units (measured 0.16; the bound was 50, as for
    RK45 in the methods' table)."""
    t_eval = reference.t[[2, 5, 13, 20]]
    result = pq.simulate(_pendulum(), PERIOD, [THETA0], [0.0], t_eval=t_eval, rtol=1e-8, atol=1e-10)
    assert np.array_equal(result.t, t_eval)
    assert np.abs(result.q - reference.q[[2, 5, 13, 20]]).max() < 1.6 * 1e-8 * THETA0
    assert result.q.shape == (4, 1) and result.s_dot.shape == (4, 1) and result.kinetic.shape == (4,)


def test_save_and_load_round_trip(tmp_path):
    """Every array and every piece of metadata survives the NPZ file bit for bit; the
    dense output and the System stay in memory only."""

    def bottom(t, q, s_dot):
        return _bottom(t, q, s_dot)

    result = pq.simulate(
        pq.scenes.chain(2), 1.0, events=bottom, dense_output=True, n_points=11, method="DOP853"
    )
    result.save(tmp_path / "run.npz")
    loaded = pq.Result.load(tmp_path / "run.npz")
    for name in ("t", "q", "s_dot", "kinetic", "potential", "constraint_residual"):
        assert np.array_equal(getattr(loaded, name), getattr(result, name)), name
    assert len(loaded.t_events) == 1 and np.array_equal(loaded.t_events[0], result.t_events[0])
    assert len(result.t_events[0]) > 0
    for name in ("nfev", "wall_time", "status", "message", "names", "method"):
        assert getattr(loaded, name) == getattr(result, name), name
    assert loaded.names == ("link1", "link2") and loaded.method == "DOP853"
    assert loaded.sol is None and loaded.system is None


def test_energies_along_the_path(reference):
    """Kinetic ½ m ℓ² θ̇² and potential −m g ℓ cos θ at every output time (exact
    formulas, round-off only), and their sum is conserved to the integration error
    (rtol 1e-13: measured 8.9e-14 of the energy scale, bound 8.9e-13; was 1e-12)."""
    theta, theta_dot = reference.q[:, 0], reference.s_dot[:, 0]
    # the formulas: 100 ε of their scales (measured 0: the same arithmetic; was 1e-13 + 1e-13 relative)
    assert np.allclose(reference.kinetic, 0.5 * theta_dot**2, rtol=0, atol=100 * EPS * 0.5 * 9.81)
    assert np.allclose(reference.potential, -9.81 * np.cos(theta), rtol=0, atol=100 * EPS * 9.81)
    assert reference.energy_drift < 8.9e-13


def test_a_torque_free_body_keeps_its_momenta_and_a_unit_quaternion():
    """A free asymmetric body (principal moments 1, 2, 3 kg m², mass centre at its
    origin) in zero gravity, spinning near its unstable middle axis while drifting: the
    inertial angular momentum R I_c ω, the inertial momentum R m v and the kinetic energy
    stay constant (Euler's equations), the mass centre moves uniformly, and the output
    quaternion has unit norm (normalised output; 1e-15, measured 1.1e-16). DOP853 at rtol 1e-10
    for 10 s, relative errors measured (each bound 10× that, rounded): angular momentum 4.1e-11,
    momentum 2.4e-10, kinetic energy 2.5e-11, the centre's uniform motion 2.3e-11."""
    body = pq.RigidBody(2.0, (0, 0, 0), np.diag([1.0, 2.0, 3.0]))
    system = pq.System({"body": body}, {"body": pq.Free()})
    s_dot0 = np.array([0.1, 0.0, 0.0, 0.01, 2.0, 0.01])
    result = pq.simulate(system, 10.0, s_dot0=s_dot0, method="DOP853", rtol=1e-10, atol=1e-12, n_points=51)
    quats = result.q[:, 3:]
    assert np.abs(np.linalg.norm(quats, axis=1) - 1.0).max() < 1e-15
    R = np.array([quaternion_matrix(quat) for quat in quats])
    L = np.einsum("nij,nj->ni", R, result.s_dot[:, 3:] @ body.I_c.T)
    p = np.einsum("nij,nj->ni", R, body.m * result.s_dot[:, :3])
    error = {"L": np.abs(L - L[0]).max() / np.linalg.norm(L[0]), "p": np.abs(p - p[0]).max() / np.linalg.norm(p[0]),
             "T": np.abs(result.kinetic - result.kinetic[0]).max() / result.kinetic[0],
             "x": np.abs(result.q[:, :3] - np.outer(result.t, p[0] / body.m)).max() / (10.0 * 0.1)}  # / t_end |v|
    bound = {"L": 4e-10, "p": 2.4e-9, "T": 2.5e-10, "x": 2.3e-10}
    assert all(error[k] < bound[k] for k in bound), f"relative errors {error}"
    assert np.ptp(result.s_dot[:, 4]) > 3.0  # ω_y turns over: the body really tumbles


def test_the_initial_quaternion_is_normalised():
    """q0 with a quaternion of norm 2 starts from the same rotation, normalised."""
    system = pq.System({"body": pq.RigidBody(1.0, I_c=np.eye(3))}, {"body": pq.Free()})
    q0 = [0.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0]
    result = pq.simulate(system, 0.1, q0=q0, s_dot0=[0, 0, 0, 0, 0, 1.0], n_points=3)
    assert np.array_equal(result.q[0], [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0])


def test_a_prescribed_joint_follows_its_motion():
    """An arm turned about z by θ(t) = sin t carries a pendulum hinged at its tip: at
    every output time the arm's pose is the rotation by sin t (exactly, round-off only)
    and its kinetic energy ½ (m r² + I_z) θ̇² = cos² t; the pendulum swings freely."""
    arm = pq.Prescribed(pq.Revolute(axis="z"), lambda t: (np.sin(t), np.cos(t), -np.sin(t)))
    system = pq.System(
        {"arm": pq.RigidBody(1.0, (1, 0, 0), np.eye(3)), "bob": pq.PointMass(1.0, (0.5, 0, 0))},
        {"arm": arm, "bob": pq.Revolute(parent="arm", axis="z", r_pn=(2, 0, 0))},
    )
    assert (system.n_q, system.n_s) == (1, 1)  # only the pendulum
    result = pq.simulate(system, 2.0, n_points=11)
    for t, q, s_dot in zip(result.t, result.q, result.s_dot):
        kin = forward(system, q, s_dot, t)
        assert np.allclose(kin.R[0], rotation(np.array([0, 0, 1.0]), np.sin(t)), rtol=0, atol=1e-15)
        assert np.allclose(kin.r[1], kin.R[0] @ [2.0, 0, 0], rtol=0, atol=1e-15)  # the tip carries the hinge
        assert pq.RigidBody(1.0, (1, 0, 0), np.eye(3)).kinetic_energy(kin.y_dot[0]) == pytest.approx(
            np.cos(t) ** 2, rel=0, abs=100 * EPS
        )  # measured 0 (was pytest's default 1e-6 relative)
    assert np.ptp(result.q[:, 0]) > 0.1  # the base motion drives the pendulum


@pytest.mark.parametrize("motion", [lambda t: (np.sin(t), np.cos(t), -np.sin(t)), "sin(t)"], ids=["callable", "sympy"])
def test_a_system_with_only_prescribed_motion_has_nothing_to_integrate(motion):
    """n_s = 0: the run still reports the path's energies, ½ · 2 · cos² t (the compiled ẋ with nothing to
    integrate: solve_ivp, not the compiled loop, whose error norm divided by zero entries)."""
    arm = pq.Prescribed(pq.Revolute(axis="z"), motion)
    system = pq.System({"arm": pq.RigidBody(1.0, (1, 0, 0), np.eye(3))}, {"arm": arm})
    result = pq.simulate(system, 1.0, n_points=5)
    assert result.q.shape == (5, 0) and result.s_dot.shape == (5, 0)
    assert np.allclose(result.kinetic, np.cos(result.t) ** 2, rtol=0, atol=100 * EPS)  # measured 0


def test_the_initial_state_defaults_to_the_systems():
    """Omitted q0 and s_dot0 come from the system: scenes set their own (chain: first
    joint at 0.5 rad, at rest); a system built with q0, s_dot0 starts there."""
    chain = pq.scenes.chain(3)
    result = pq.simulate(chain, 0.05, n_points=3)
    assert np.array_equal(result.q[0], [0.5, 0.0, 0.0]) and np.array_equal(result.s_dot[0], np.zeros(3))
    system = pq.System(
        {"bob": pq.PointMass(1.0, (0, 0, -1.0))}, {"bob": pq.Revolute(axis="y")}, q0=[0.2], s_dot0=[-1.0]
    )
    result = pq.simulate(system, 0.05, n_points=3)
    assert (result.q[0, 0], result.s_dot[0, 0]) == (0.2, -1.0)


def test_progress_is_called_after_each_segment():
    """With the time reached: the end of the compiled loop's first step past the segment's end (a step
    that passes several ends finishes them all: the pendulum's first step, from 0 to 0.133 s, ends the
    first two of four segments), the run's end last."""
    seen = []
    result = pq.simulate(_pendulum(), 0.2, [THETA0], [0.0], n_segments=4, progress=seen.append)
    assert seen[-1] == 0.2 and result.status == 0
    assert np.all(np.diff(seen) > 0) and all(t >= 0.05 * (k + 1) for k, t in enumerate(seen)), seen
    assert len(seen) == 2 and seen[0] > 0.1


def _interrupt_from_progress(t):
    if t > 0.09:
        raise KeyboardInterrupt


class _InterruptingTorque:
    """A torque law that meets Ctrl-C during the third segment (t > 0.12)."""

    def __call__(self, t, q, s_dot):
        if t > 0.12:
            raise KeyboardInterrupt
        return np.zeros(3)


@pytest.mark.parametrize("where", ["between-segments", "inside-a-segment"])
def test_ctrl_c_keeps_what_was_computed(where):
    """KeyboardInterrupt between segments (from the progress callback once past 0.09 s: after the
    first step, which ends the first two of four segments at 0.133 s) or inside one (from a torque law
    past 0.12 s, met by a stage of a step that starts before 0.02 s: scipy's solver steps a law that
    numba does not compile): status 2, the output rows up to the last accepted step kept (up to
    t = 0.13 s and 0.01 s), no exception."""
    forces = [pq.Torque("bob", _InterruptingTorque())] if where == "inside-a-segment" else []
    progress = _interrupt_from_progress if where == "between-segments" else None
    system = pq.System(
        {"bob": pq.PointMass(1.0, (0, 0, -1.0))},
        {"bob": pq.Revolute(axis="y")},
        gravity=(0, 0, -9.81),
        forces=forces,
    )
    result = pq.simulate(system, 0.2, [THETA0], [0.0], n_segments=4, n_points=21, progress=progress)
    assert result.status == 2 and not result.success and "interrupted" in result.message
    np.testing.assert_array_equal(result.t, np.linspace(0.0, 0.2, 21)[:14 if where == "between-segments" else 2])
    assert np.all(np.isfinite(result.q)) and result.q[-1, 0] < THETA0  # it had started to fall


def test_interpolants_are_kept_only_when_asked_for(monkeypatch):
    """dense_output=False: no segment forms a dense solution (~10 KB per step for chain(100),
    and three more evaluations per DOP853 step); dense_output=True keeps every segment's
    interpolants for ``result.sol``. Both join the pendulum's five segments in two calls (the compiled
    loop's, scipy's solver stepped over them: driver.CHUNK_EVALUATIONS)."""
    import weakref

    import projeq.simulation.driver as driver

    solutions, real = [], driver.OdeSolution

    def recording(*args, **kwargs):
        solution = real(*args, **kwargs)
        solutions.append(weakref.ref(solution))
        return solution

    def count_alive(t):  # no reference cycles hold them: released at once, no gc.collect needed
        alive.append(sum(ref() is not None for ref in solutions))

    monkeypatch.setattr(driver, "OdeSolution", recording)
    for dense, expected in ((False, [0] * 2), (True, [1, 2])):
        solutions.clear()
        alive = []
        pq.simulate(_pendulum(), 2.0, [THETA0], [0.0], n_segments=5, dense_output=dense, progress=count_alive)
        assert alive == expected


def test_dense_solution_changes_nothing_but_the_evaluations():
    """The dense solution is formed only where it is needed: without dense_output the same
    steps give the same output rows (to the bit: the same interpolants at the output times,
    the same state at each segment's end), with DOP853's three evaluations per step of its
    interpolant saved on the steps that hold no output time (scipy's DOP853 both times: the compiled
    loop, which a run without dense output would take, agrees to round-off, tests/simulation/test_loop.py)."""
    from scipy.integrate import DOP853

    system = pq.scenes.chain(3)
    runs = [pq.simulate(system, 2.0, method=DOP853, n_points=5, dense_output=dense) for dense in (False, True)]
    np.testing.assert_array_equal(runs[0].q, runs[1].q)
    np.testing.assert_array_equal(runs[0].s_dot, runs[1].s_dot)
    assert runs[0].nfev < runs[1].nfev and runs[1].sol is not None and runs[0].sol is None


def test_default_method_follows_the_measured_fastest_mode():
    """simulate without a method measures ρ(∂ẋ/∂x) at the initial state: a rigid chain gets
    RK45 at a loose tolerance and DOP853 at the default rtol 1e-8 (the eighth order pays there), a
    model with constraint equations RK45 (its partitions make the right-hand side piecewise),
    the flexible arm over 5 s (four bending functions, ρ ≈ 3.1e3 1/s) DOP853 even at a loose
    tolerance, and a beam 10⁶ times stiffer Radau with the exact Jacobian (njev > 0);
    Result.method records each. The flexible arm and its rigid twin run on the compiled kernel
    (no InterpretedWarning)."""
    from projeq.assembly import InterpretedWarning
    from projeq.simulation.driver import default_method

    with warnings.catch_warnings():
        warnings.simplefilter("error", InterpretedWarning)
        assert pq.simulate(pq.scenes.chain(3), 0.05, n_points=2, rtol=1e-5).method == "RK45"
        assert pq.simulate(pq.scenes.chain(3), 0.05, n_points=2).method == "DOP853"
        loop = pq.scenes.four_bar()  # constraint equations: RK45 at the default rtol too (default_method)
        assert default_method(loop.evaluator(), loop, loop.q0, loop.s_dot0, 0.0, 5.0) == "RK45"
        arm = pq.scenes.flexible_arm()
        assert default_method(arm.evaluator(), arm, arm.q0, arm.s_dot0, 0.0, 5.0, rtol=1e-5) == "DOP853"  # 5 s
        assert pq.simulate(arm, 0.02, n_points=2).nfev > 0 and arm.evaluator().name == "fast"
        assert pq.scenes.flexible_arm(rigid_last_link=True).evaluator().name == "fast"
    stiff = pq.System({"beam": pq.RitzBeam(0.8, rho_A=0.8, EI_z=4e7, n_v=4, n_w=0)}, {"beam": pq.Revolute(axis="z")})
    assert default_method(stiff.evaluator(), stiff, np.zeros(stiff.n_q), np.zeros(stiff.n_s), 0.0, 5.0) == "Radau"
    result = pq.simulate(stiff, 0.2, s_dot0=np.r_[0.1, 0, 0, 0, 0], n_points=2)  # ρ t_end = 8e5; a steady turn
    assert result.method == "Radau" and result.njev > 0

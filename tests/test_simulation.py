"""simulate(): methods, events, dense output, NPZ, quaternions, progress and interruption."""

import numpy as np
import pytest

import projeq as pq


def _pendulum():
    return pq.System({"bob": pq.PointMass(1.0, (0, 0, -1.0))}, {"bob": pq.Revolute(axis="y")}, gravity=(0, 0, -9.81))


@pytest.mark.parametrize("method", ["RK45", "RK23", "DOP853", "Radau", "BDF", "LSODA"])
def test_every_solve_ivp_method_gives_the_same_swing(method):
    """All methods agree with a DOP853 reference at rtol 1e-12 to within their tolerance,
    measured in units of rtol × amplitude. rtol 1e-8 bounds local errors; the global error
    over one swing measured here is 0.001 (DOP853, Radau) to 3.5 (RK23) and 26 (BDF, a
    low-order multistep method whose error accumulates): 50 units leave a factor two."""
    system = _pendulum()
    reference = pq.simulate(system, 2.0, [1.0], [0.0], method="DOP853", rtol=1e-12, atol=1e-14, n_points=21)
    result = pq.simulate(system, 2.0, [1.0], [0.0], method=method, rtol=1e-8, atol=1e-10, n_points=21)
    error = np.abs(result.q - reference.q).max() / (1e-8 * np.abs(reference.q).max())
    assert error < 50


def test_terminal_event_stops_the_run():
    """Release at 1 rad; the event θ = 0 (downward crossing) ends the run at a quarter
    period, status 1, with the event time recorded."""

    def bottom(t, q, s_dot):
        return q[0]

    bottom.terminal, bottom.direction = True, -1
    result = pq.simulate(_pendulum(), 5.0, [1.0], [0.0], events=bottom, rtol=1e-10, atol=1e-12)
    assert result.status == 1 and result.success
    assert len(result.t_events[0]) == 1
    assert result.t[-1] <= result.t_events[0][0] + 1e-12


def test_dense_output_matches_the_output_times():
    result = pq.simulate(_pendulum(), 1.0, [0.5], [0.0], dense_output=True, rtol=1e-10, atol=1e-12, n_points=11)
    q, s_dot = result.sol(result.t[5])
    assert np.allclose(q, result.q[5], atol=1e-9) and np.allclose(s_dot, result.s_dot[5], atol=1e-9)


def test_t_eval_is_respected():
    t_eval = np.array([0.0, 0.1, 0.25, 0.7])
    assert np.array_equal(pq.simulate(_pendulum(), 0.7, [0.5], [0.0], t_eval=t_eval).t, t_eval)


def test_save_and_load_round_trip(tmp_path):
    result = pq.simulate(_pendulum(), 0.5, [0.5], [0.0], n_points=11)
    result.save(tmp_path / "r.npz")
    loaded = pq.Result.load(tmp_path / "r.npz")
    for name in ("t", "q", "s_dot", "kinetic", "potential", "constraint_residual"):
        assert np.array_equal(getattr(loaded, name), getattr(result, name))
    assert (loaded.nfev, loaded.names, loaded.message) == (result.nfev, result.names, result.message)


def test_torque_free_body_keeps_its_angular_momentum_and_unit_quaternion():
    """A free asymmetric body in zero gravity: the inertial angular momentum R I_c ω and
    the kinetic energy are constant (Euler's equations), the quaternion stays unit
    (normalised output). DOP853 at rtol 1e-11: 1e-8 relative."""
    body = pq.RigidBody(2.0, (0, 0, 0), np.diag([1.0, 2.0, 3.0]))
    system = pq.System({"body": body}, {"body": pq.Free()})
    s_dot0 = np.array([0.1, 0.0, 0.0, 0.3, 2.0, 0.2])  # spin near the unstable middle axis
    result = pq.simulate(system, 5.0, s_dot0=s_dot0, method="DOP853", rtol=1e-11, atol=1e-12, n_points=51)
    quats = result.q[:, 3:]
    assert np.allclose(np.linalg.norm(quats, axis=1), 1.0, atol=1e-14)
    from projeq.spatial import quaternion_matrix

    L = np.array([quaternion_matrix(qt) @ (body.I_c @ s[3:]) for qt, s in zip(quats, result.s_dot)])
    assert np.abs(L - L[0]).max() < 1e-8 * np.linalg.norm(L[0])
    assert result.energy_drift < 1e-8
    assert np.ptp(result.s_dot[:, 3]) > 0.5  # it does tumble


def test_prescribed_joint_follows_its_motion():
    """A body on a prescribed rotation θ = sin t: its pose at every output time is that
    rotation, whatever the dynamics (the system has no minimal velocity)."""
    joint = pq.Prescribed(pq.Revolute(axis="z"), lambda t: (np.sin(t), np.cos(t), -np.sin(t)))
    system = pq.System({"a": pq.RigidBody(1.0, (1, 0, 0), np.eye(3))}, {"a": joint})
    assert system.n_s == 0
    kinetic, _ = system.energy([], [], t=0.0)
    assert kinetic == pytest.approx(0.5 * (1.0 + 1.0) * 1.0)  # ½ (m r² + I) θ̇², θ̇(0) = 1


def test_default_state_and_progress_callback():
    """Omitted initial conditions come from the system (scenes set them); progress is
    called once per finished segment with the time reached."""
    system = pq.scenes.chain(3)
    seen = []
    result = pq.simulate(system, 0.2, n_segments=4, progress=seen.append)
    assert np.allclose(result.q[0], system.q0)
    assert np.allclose(seen, [0.05, 0.1, 0.15, 0.2])


def test_ctrl_c_keeps_what_was_computed():
    """KeyboardInterrupt during the run (here from the progress callback after the second
    segment): status 2, the first two segments are kept."""

    def interrupt(t):
        if t > 0.09:
            raise KeyboardInterrupt

    result = pq.simulate(_pendulum(), 0.2, [0.5], [0.0], n_segments=4, progress=interrupt)
    assert result.status == 2 and not result.success
    assert result.t[-1] == pytest.approx(0.1)

"""The Whipple bicycle scene (issue 4, item 5): contact kinematics, nonlinear simulation,
bad input. Its eigenvalues against an independent KanesMethod derivation are in
``test_whipple_eigenvalues.py``."""

import numpy as np
import pytest

import projeq as pq
from projeq.constraints.partitioned import POSITION_TOLERANCE
from projeq.scenes.bicycle import BENCHMARK, Contacts, bicycle_parameters, upright_pitch, whipple_bicycle
from projeq.spatial import rotation

RTOL = 1e-8
E = np.eye(3)


def _wheel_poses(contacts, q):
    """Inertial centre and orientation of the rear and the front wheel (their rotations
    about the frame's and the fork's y-axis added to Contacts' frame and fork poses)."""
    lean, frame, fork, rear_centre, front_centre, n = contacts._poses(q)
    return rear_centre, frame @ rotation(E[1], q[5]), front_centre, fork @ rotation(E[1], q[7])


def test_no_slip_rows_are_the_contact_points_velocities():
    """A(q) q̇ (Contacts.A, assembled from angular-velocity Jacobians) equals the time
    derivative of the wheels' *material* contact points, obtained by moving the body-fixed
    points along q + ε q̇ (central differences, step 1e-6: error ~1e-12 truncation and
    ~1e-10 round-off: measured 1.08e-10, bound 1.1e-9, was 1e-8), at a random, not upright, configuration.
    The contact points are P = (x, y, 0) and Q = c_F + r_F n of the module docstring."""
    contacts = Contacts(bicycle_parameters())
    rng = np.random.default_rng(7)
    q, q_dot = 0.3 * rng.standard_normal(8), rng.standard_normal(8)
    lean, frame, fork, rear_centre, front_centre, n = contacts._poses(q)
    c_R, R_R, c_F, R_F = _wheel_poses(contacts, q)
    P_body = R_R.T @ (np.array([q[0], q[1], 0.0]) - c_R)
    Q_body = R_F.T @ (front_centre + contacts.r_F * n - c_F)

    def material_points(eps):
        c_R, R_R, c_F, R_F = _wheel_poses(contacts, q + eps * q_dot)
        return np.concatenate((c_R + R_R @ P_body, c_F + R_F @ Q_body))

    h = 1e-6
    velocity = (material_points(h) - material_points(-h)) / (2 * h)
    mismatch = np.abs(contacts.A(q, 0.0) @ q_dot - velocity[[0, 1, 3, 4]]).max()
    assert mismatch < 1.1e-9, mismatch
    # the front contact's height: Φ(q) = z_Q, and on the ground in the upright configuration
    assert contacts.phi(q, 0.0)[0] == pytest.approx(front_centre[2] + contacts.r_F * n[2], abs=1e-15)
    assert abs(upright_pitch(0.0, 0.0)) < 1e-14  # MJPR's geometry: front wheel touches at θ = 0


def test_weaving_run_conserves_energy_and_keeps_both_contacts():
    """2 s of the benchmark bicycle at 4 m/s (below MJPR's weave speed ≈ 4.3 m/s, so the
    weave grows) after a roll-rate kick of 0.5 rad/s. No forces do work (rolling without
    slip, gravity conservative): T + V is conserved; the drift is accumulated local
    error: 8.8e-11 here, 3.2e-11 at roll rate 0.3 rad/s, 3.8e-10 at 3.5 m/s, bound 3.8e-9 (10× the
    largest; was 100 rtol = 1e-6). Φ = 0 (front contact on the ground) is restored by the
    Gauss–Newton projection to POSITION_TOLERANCE · max(1, |q|); the no-slip rows hold to
    round-off because the dependent velocities are solved from them (100 ε · max|q̇|, measured
    1.3e-16; was 1e-12)."""
    bike = whipple_bicycle(speed=4.0, roll_rate=0.5)
    r = pq.simulate(bike, 2.0, method="DOP853", rtol=RTOL, atol=RTOL * 1e-2, n_points=41)
    assert r.success
    assert r.energy_drift < 3.8e-9, r.energy_drift
    bound = POSITION_TOLERANCE * np.maximum(1.0, np.abs(r.q).max(axis=1))
    assert np.all(np.abs(r.constraint_residual[:, 0]) <= bound)
    q_dot = np.array([bike.q_dot(q, s) for q, s in zip(r.q, r.s_dot)])
    no_slip = np.abs(r.constraint_residual[:, 1:]).max() / np.abs(q_dot).max()
    assert no_slip < 100 * np.finfo(float).eps, no_slip
    roll = r.q[:, 3]
    assert roll.max() > 0.02 and roll.min() < -0.02  # it really weaves: the roll changes sign
    assert r.q[-1, 0] > 7.0  # and rides forward about v t


@pytest.mark.parametrize("params, match", [
    ({"wheelbase": 1.0}, "params: unknown"),
    ({"r_F": -0.35}, "params: r_F"),
    ({"lam": 2.0}, "params: lam"),
    ({"m_B": float("nan")}, r"params\['m_B'\]"),
], ids=["unknown-name", "negative-radius", "tilt-beyond-90deg", "nan-mass"])
def test_bad_parameters_are_named(params, match):
    with pytest.raises(ValueError, match=match):
        whipple_bicycle(params)


def test_a_configuration_without_ground_contact_is_rejected():
    """At 80° roll and 80° steer no pitch within ±0.5 rad brings the front wheel down."""
    with pytest.raises(ValueError, match="roll, steer"):
        whipple_bicycle(roll=1.4, steer=1.4)


def test_benchmark_values_are_mjpr_table_1():
    """Spot check of the defaults against MJPR (2007) Table 1 (as quoted in issue 4)."""
    assert (BENCHMARK["w"], BENCHMARK["c"], BENCHMARK["lam"]) == (1.02, 0.08, np.pi / 10)
    assert (BENCHMARK["m_B"], BENCHMARK["I_Bxz"], BENCHMARK["I_Hxz"]) == (85.0, 2.4, -0.00756)

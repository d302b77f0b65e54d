"""Unilateral contacts: lift-off where the solver's normal force vanishes (issue 4, item 3)."""

import numpy as np

import projeq as pq
from projeq.constraints.reactions import contact_event, reactions
from projeq.scenes.mechanisms import bar_on_wall, sphere_on_sphere

RTOL, ATOL = 1e-9, 1e-11


def _lift_off(system, row, t_end):
    r = pq.simulate(system, t_end, rtol=RTOL, atol=ATOL, n_points=41, dense_output=True,
                    events=contact_event(system, row))
    assert r.status == 1, r.message  # stopped by the contact event, not by t_end
    q, s_dot = r.sol(r.t_events[0][0])
    return r, q, s_dot


def test_sphere_rolling_off_a_sphere_leaves_at_cos_theta_10_17():
    """Lagrange seminars, Seminar 5, Problem 19: a solid sphere rolling without slipping off a fixed
    sphere leaves it where the normal force vanishes, cos θ = 10/17 when started at rest at
    the top. Started at rest at θ0, energy gives (a + b) θ̇² = (10/7) g (cos θ0 − cos θ), so
    the same derivation gives cos θ = (10/17) cos θ0 (θ0 = 0.1 shortens the run)."""
    theta0 = 0.1
    system = sphere_on_sphere(a=0.1, b=1.0, theta0=theta0)
    r, q, s_dot = _lift_off(system, 0, 5.0)
    cos_theta = q[1] / np.hypot(q[0], q[1])
    # the event root sits on the integrated trajectory: error of the order of rtol
    # measured 1.5e-10 (4e-10 before): 10× the larger of the two contacts' errors
    assert abs(cos_theta - 10 / 17 * np.cos(theta0)) < 2e-9
    lam = reactions(system, r)[:, 0]
    assert np.all(lam[:-1] > 0)  # the sphere pushes on the support until it lifts off


def test_bar_sliding_down_a_wall_leaves_it_at_cos_theta_2_3():
    """Lagrange seminars, Seminar 5, Problem 20: a uniform bar sliding down a frictionless wall and
    floor loses the wall where the wall's normal force vanishes, cos θ = 2/3 from rest near
    the upright position; from rest at tilt θ0 the same energy argument gives
    cos θ = (2/3) cos θ0."""
    theta0 = 0.2
    system = bar_on_wall(l=0.5, theta0=theta0)
    r, q, s_dot = _lift_off(system, 0, 5.0)
    # ψ = −θ; event root on the integrated trajectory (measured 1.9e-10; 1.3e-10 before)
    assert abs(np.cos(q[2]) - 2 / 3 * np.cos(theta0)) < 2e-9
    floor = reactions(system, r)[:, 1]
    assert np.all(floor > 0)  # the floor keeps pushing up


def test_the_result_ends_where_the_sphere_leaves():
    """A terminal event's exact state is the Result's last row (issue 18, item 5), read
    from ``result.q[-1]`` without dense output: the sphere leaves where the normal force λ
    vanishes. Closed form (Lagrange seminars, Seminar 5, Problem 19, there from the top):
    rolling, v = (a + b) θ̇ = a ω, and I = (2/5) m a² give T = (7/10) m v², so energy from rest
    at θ0 gives v² = (10/7) g (a + b)(cos θ0 − cos θ); the radial equation
    m v²/(a + b) = m g cos θ − N with N = 0 gives cos θ = (10/17) cos θ0. The same state is in
    ``t_events``/``q_events``/``s_dot_events``, and λ vanishes there. The root sits on the
    integrated trajectory: 2e-9 in θ (measured 1.9e-10; was 1e-8 = 10 rtol)."""
    theta0 = 0.1
    system = sphere_on_sphere(a=0.1, b=1.0, theta0=theta0)
    r = pq.simulate(system, 5.0, rtol=RTOL, atol=ATOL, n_points=41, events=contact_event(system, 0))
    assert r.status == 1 and r.t[-1] == r.t_events[0][0] < 5.0
    assert np.array_equal(r.q[-1], r.q_events[0][0]) and np.array_equal(r.s_dot[-1], r.s_dot_events[0][0])
    theta = np.arccos(r.q[-1, 1] / np.hypot(r.q[-1, 0], r.q[-1, 1]))
    error = theta - np.arccos(10 / 17 * np.cos(theta0))
    assert abs(error) < 2e-9, error
    lam = reactions(system, r)[:, 0]
    assert abs(lam[-1]) < 1e-8 and np.all(lam[:-1] > 0)  # N, with m g = 9.81 N (measured 1.5e-9)

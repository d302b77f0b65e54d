"""Bad input for non-holonomic systems (the issue's "Bad input" list).

- a user-defined joint whose F has the wrong shape, or depends on symbols that are not
  coordinates, time or declared parameters (named in the message), or on the speeds; a
  parameter that is a coordinate;
- K(q) singular at the start: Barhorst's Euler angles at tilt q2 = π/2
  (Barhorst §3.2, eq. 96, "the singularity near q2 = π/2"); the knife-edge disc's
  F at ϕ = π/2 (Orsino (2020) slide 31: the 1/cos²ϕ of the Hamiltonian);
- initial rates q̇₀ that violate the constraints they are meant to satisfy.
"""

import numpy as np
import pytest
import sympy as sp

import projeq as pq
from projeq.constraints.nonholonomic import check_configuration, initial_speeds

x, y, k, u = sp.symbols("x y k u")


def particle_joint(F, K=None, **kw):
    K = sp.Matrix([[1], [y**2]]) if K is None else K
    return pq.UserJoint.from_sympy([x, y], [u], sp.eye(3), [x, y, 0], F, K, **kw)


def test_F_of_the_wrong_shape():
    with pytest.raises(ValueError, match=r"^F: expected shape \(6, 1\), got \(5, 1\)"):
        particle_joint(sp.Matrix([1, y**2, 0, 0, 0]))
    with pytest.raises(ValueError, match=r"^F: .*shape \(6, 1\)"):
        pq.UserJoint.from_functions(
            2, 1, lambda q, t: (np.eye(3), np.array([q[0], q[1], 0.0])),
            lambda q, t: np.ones((5, 1)), lambda q, t: np.array([[1.0], [q[1] ** 2]]),
        )


def test_F_with_unknown_symbols_names_them():
    with pytest.raises(ValueError, match=r"^F: depends on \['k'\], which are not coordinates \['x', 'y'\]"):
        particle_joint(sp.Matrix([1, k * y**2, 0, 0, 0, 0]))
    particle_joint(sp.Matrix([1, k * y**2, 0, 0, 0, 0]), K=sp.Matrix([[1], [k * y**2]]), parameters={k: 1.0})
    with pytest.raises(ValueError, match=r"^parameters: \['y'\] are coordinates, minimal velocities or time"):
        particle_joint(sp.Matrix([1, y**2, 0, 0, 0, 0]), parameters={y: 1.0})
    with pytest.raises(ValueError, match=r"^F: depends on the minimal velocities \['u'\]"):
        particle_joint(sp.Matrix([1, u * y, 0, 0, 0, 0]))
    with pytest.raises(ValueError, match=r"^constraints: depends on \['k'\]"):
        xd, yd = sp.symbols("xd yd")
        particle_joint(sp.Matrix([1, y**2, 0, 0, 0, 0]), constraints=[yd - k * xd], q_dot=[xd, yd])


def test_F_inconsistent_with_K_is_refused():
    """The pose (x, y) and F must describe the same motion as q̇ = K ṡ."""
    with pytest.raises(ValueError, match="^F: the relative twist"):
        particle_joint(sp.Matrix([1, y, 0, 0, 0, 0]))


def test_singular_K_of_barhorsts_euler_angles():
    """Eq. (96): K has sec q2, singular at the tilt q2 = π/2 (disk flat on the plane)."""
    with pytest.raises(ValueError, match=r"^K: q̇ = K\(q\) ṡ is singular at q0 = \[0.0, 1.570796"):
        pq.scenes.rolling_disk(q0=(0.0, np.pi / 2, 0.0, 0.0, 0.0))
    system = pq.scenes.rolling_disk()
    with pytest.raises(ValueError, match=r"K\(q\) .*'disk' at q = \[0.0, -1.570796"):
        check_configuration(system, [0.0, -np.pi / 2, 0.0, 0.0, 0.0])
    check_configuration(system, [0.0, 1.5, 0.0, 0.0, 0.0])  # 86°: regular


@pytest.mark.parametrize("inertia, match", [
    ("ring", r"^inertia: expected 'disk', 'hoop' or a pair \(I, J\)"),
    ((1e-6,), r"^inertia: expected 'disk', 'hoop' or a pair \(I, J\)"),
    ((0.0, 1e-6), r"^inertia: I and J must be positive"),
    ((1e-6, 3e-6), r"^inertia: J = 3e-06 exceeds 2 I = 2e-06"),
])
def test_rolling_disk_inertia_is_checked(inertia, match):
    """The disk's moments: a known shape name or (I, J) with 0 < J ≤ 2 I (triangle inequality)."""
    with pytest.raises(ValueError, match=match):
        pq.scenes.rolling_disk(inertia=inertia)


def test_singular_F_of_the_knife_edge_disc_at_flat_tilt():
    """Slides 29–31: at ϕ = ±π/2 the ψ̇- and θ̇-directions of ω coincide (n̂z = ê2), F loses
    rank and the mass matrix is singular; the scene refuses to start there."""
    with pytest.raises(ValueError, match=r"F\(q\) loses rank .*'disc' at q = \[0.0, 0.0, 0.0, 1.570796"):
        pq.scenes.knife_edge_disc(q0=(0.0, 0.0, 0.0, np.pi / 2, 0.0))


@pytest.mark.parametrize("distance", [1e-11, 1e-9])
def test_knife_edge_disc_near_flat_tilt_is_singular(distance):
    """Slide 29: F's ψ̇- and θ̇-columns differ by O(cos ϕ), so cond F ≈ 2.8 / (π/2 − ϕ) (measured:
    2.83e11 at 1e-11 rad); a tilt 1e-11 and 1e-9 rad from flat (cond 2.8e11, 2.8e9) must still
    be refused as singular at the start (threshold 1e10, far above any regular pose)."""
    if distance < 1e-10:
        with pytest.raises(ValueError, match=r"F\(q\) loses rank \(condition number 2.8\de\+11\)"):
            pq.scenes.knife_edge_disc(q0=(0.0, 0.0, 0.0, np.pi / 2 - distance, 0.0))
    else:  # cond 2.8e9 < 1e10: a pose one may start from (the run's own monitor stops it early)
        pq.scenes.knife_edge_disc(q0=(0.0, 0.0, 0.0, np.pi / 2 - distance, 0.0))


def test_a_singular_joint_behind_another_is_refused_by_name():
    """check_configuration evaluates each joint's F(q) with that joint's own minimal velocities: the
    knife-edge disc 1e-11 rad from flat (cond F 2.8e11, slide 29) beside a pendulum whose revolute joint
    comes first (the disc's ṡ start at index 1) is refused naming 'disc', as the disc alone is. A mutant
    that sized the disc's ṡ by stop + start instead of stop − start survived the disc alone (issue 37,
    item 8)."""
    from projeq.constraints.nonholonomic import check_configuration

    disc = pq.scenes.knife_edge_disc()
    system = pq.System({"pendulum": pq.PointMass(1.0), "disc": disc.subsystems[0]},
                       {"pendulum": pq.Revolute(axis="y"), "disc": disc.joints[0]}, gravity=(0, 0, -9.81))
    q = np.zeros(system.n_q)
    q[1 + 3] = np.pi / 2 - 1e-11  # the disc's tilt ϕ
    with pytest.raises(ValueError, match=r"F\(q\) loses rank \(condition number 2.8\de\+11\) for the joint of 'disc'"):
        check_configuration(system, q)


def test_knife_edge_disc_started_near_flat_stops_within_few_evaluations():
    """Passes if the disc started 1e-4 rad from flat (issue 20: 460k evaluations, never finished
    its first segment) stops with a SimulationError naming the coordinate singularity within a few
    thousand evaluations (measured: 2405 by the compiled loop; bound 5000), the rows computed
    before the stop kept: its spin rates grow like 1/(π/2 − ϕ) as ϕ → π/2 (slide 29) and the run
    is stopped once cond F passes 1e5 (checked every MONITOR_EVERY = 200 evaluations), about 3e-5
    rad from flat, at t = 0.0134 s. Counted in evaluations, not seconds: a cold numba cache
    compiles the loop inside a timed call."""
    system = pq.scenes.knife_edge_disc(q0=(0.0, 0.0, 0.0, np.pi / 2 - 1e-4, 0.0))
    with pytest.raises(pq.SimulationError, match=r"approaches a coordinate singularity at t = .*condition number 1") \
            as stopped:
        pq.simulate(system, 10.0, n_points=2001)
    result = stopped.value.result
    assert 0 < result.nfev < 5000
    assert np.array_equal(result.t, [0.0, 0.005, 0.01])  # the output times before t = 0.0134 s
    assert np.isfinite(result.q).all() and abs(result.q[-1, 3] - np.pi / 2) < 1e-4


def test_initial_rates_violating_the_constraints():
    """Slide 30's rolling constraints and Barhorst's ẏ − y² ẋ = 0: rates that violate them
    are refused with the residual; rates that satisfy them give the minimal velocities."""
    # the tolerance is relative to the rates: 1e-8 (1 + max |q̇|) = 2e-8
    with pytest.raises(ValueError, match=r"^q_dot: the initial rates violate the velocity constraints: residual \[1\. 0\.\] "
                                         r"\(tolerance 2e-08\)"):
        pq.scenes.knife_edge_disc(q_dot0=(1.0, 0.0, 0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"residual \[-4\.\]"):
        pq.scenes.barhorst_particle(q_dot0=(1.0, 0.0))  # ẏ − y² ẋ = 0 − 4·1 at (2, 2)
    system = pq.scenes.knife_edge_disc()
    s_dot = np.array([0.3, -0.2, 1.1])
    q_dot = system.q_dot(system.q0, s_dot)
    # the speeds from q̇ to round-off (measured 4.4e-16; allclose's default atol 1e-8 applied before)
    assert np.allclose(initial_speeds(system, system.q0, q_dot), s_dot, rtol=1e-14, atol=0)
    built = pq.scenes.knife_edge_disc(q_dot0=q_dot)
    assert np.allclose(built.s_dot0, s_dot, rtol=1e-14, atol=0)
    particle = pq.scenes.barhorst_particle(q_dot0=(1.0, 4.0))
    assert np.allclose(particle.s_dot0, [1.0], rtol=0, atol=100 * np.finfo(float).eps)


@pytest.mark.parametrize("kwargs, message", [
    ({"m_ecc": -0.001}, r"^m_ecc: must not be negative, got -0.001"),
    ({"m_ecc": np.nan}, r"^m_ecc: non-finite entries"),
    ({"drag": np.nan}, r"^drag: non-finite entries"),
    ({"R": -0.015}, r"^R: must be positive, got -0.015"),
    ({"m_ecc": 0.0, "ecc": (0.0, 0.0, 0.01)}, r"^ecc: the eccentric mass's position .* is given, but m_ecc = 0"),
], ids=["m_ecc-negative", "m_ecc-nan", "drag-nan", "R-negative", "ecc-without-mass"])
def test_rolling_disk_parameters_are_not_silently_dropped(kwargs, message):
    """Passes if each is a ValueError naming the parameter. Before, m_ecc = −1 g or NaN failed
    `m_ecc > 0` and gave the symmetric disk (the system of m_ecc = 0, without its "mass"),
    drag = NaN failed `drag > 0` and gave no drag, R < 0 a disc of negative radius, and
    ecc with m_ecc = 0 was ignored."""
    assert "mass" not in pq.scenes.rolling_disk(m_ecc=0.0).names  # the system the bad masses gave
    with pytest.raises(ValueError, match=message):
        pq.scenes.rolling_disk(**kwargs)


def test_knife_edge_disc_radius_must_be_positive():
    """Passes if a negative radius is refused by name (before: a disc with its centre below the
    plane it rolls on, z_G = −r cos ϕ > 0, accepted)."""
    with pytest.raises(ValueError, match=r"^r: must be positive, got -1.0"):
        pq.scenes.knife_edge_disc(r=-1.0)

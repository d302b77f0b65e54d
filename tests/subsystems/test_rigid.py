"""Rigid subsystems (docs/theory.md §3): Gauss terms M_n, G_n ẏ_n, Q_n against independent physics.

docs/theory.md §3, with ẏ = (v_O, ω) in the body frame, origin O, r_c = O → mass centre:

    M = [[m E, −m r̃_c], [m r̃_c, I_O]],  G ẏ = [m ω̃ v_c ; m r̃_c ω̃ v_c + ω̃ I_c ω],  Q = [f ; r̃_c f]

is checked against the Newton–Euler equations about the mass centre written out below
(momentum p = m v_c, angular momentum L = I_c ω, both rates in the moving body frame as in
B(10): ṗ + ω̃ p − f, L̇ + ω̃ L − M_c, then the moment carried to O by r̃_c), against
B(10)'s own form Σ [(∂v_c/∂ẏ)ᵀ (∂ω/∂ẏ)ᵀ] [...], and the planar body against the spatial
one restricted to its plane.

Tolerance 100 ε relative to the largest term of the identity: both sides are sums of a
few dozen products of the same data (masses up to 1e2, offsets and rates O(1)), so only
round-off is left: measured at most 3.9e-16 relative over 1000 hypothesis draws (M = Mᵀ, the
Gauss form, König's T, V, planar = spatial T); the bound was 1e-10.
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from strategies import random_inertia, random_mass, random_rotation

import projeq as pq
from projeq.subsystems.rigid import RigidGroup

RTOL = 100 * np.finfo(float).eps  # algebraic identity: round-off (module docstring)
PLANES = ("xy", "yz", "zx", "xz")
seeds = st.integers(0, 2**32 - 1)


def _body(rng, kind=pq.RigidBody):
    m = random_mass(rng)
    return kind(m, rng.uniform(-0.5, 0.5, 3), random_inertia(rng, m))


def _assert_close(got, expected, scale):
    err = np.abs(np.asarray(got) - np.asarray(expected)).max()
    assert err <= RTOL * scale, f"|difference| = {err:.3g} > {RTOL:g} · {scale:.3g}"


def newton_euler(m, r_c, I_c, twist, accel, g_body):
    """Residual [force ; moment about O] of a rigid body by Newton–Euler about its mass centre.

    Everything in body coordinates; the body frame turns with ω, so the inertial rates of
    p and L have the components ṗ + ω × p and L̇ + ω × L (B(10)). Gravity m g acts at the
    mass centre (no moment about it). The moment equation about the mass centre is
    carried to O by adding r_c × (force residual).
    """
    v_O, omega = twist[:3], twist[3:]
    a_O, alpha = accel[:3], accel[3:]
    v_c = v_O + np.cross(omega, r_c)  # r_c is fixed in the body
    p = m * v_c
    p_dot = m * (a_O + np.cross(alpha, r_c))
    L = I_c @ omega
    L_dot = I_c @ alpha  # I_c is constant in body coordinates
    force = p_dot + np.cross(omega, p) - m * g_body
    moment_c = L_dot + np.cross(omega, L)
    return np.concatenate((force, moment_c + np.cross(r_c, force)))


def _random_motion(rng, n=6):
    return rng.uniform(-2, 2, n), rng.uniform(-2, 2, n), rng.uniform(-10, 10, 3)


@given(seeds)
def test_gauss_terms_equal_newton_euler_about_the_mass_centre(seed):
    """M ÿ − h = M ÿ + G ẏ − Q equals the Newton–Euler residual (docs/theory.md §3) at a random
    state, acceleration, orientation and gravity."""
    rng = np.random.default_rng(seed)
    body = _body(rng)
    twist, accel, gravity = _random_motion(rng)
    R = random_rotation(rng)
    M, h = body.gauss_terms(twist, R, gravity)
    expected = newton_euler(body.m, body.r_c, body.I_c, twist, accel, R.T @ gravity)
    _assert_close(M @ accel - h, expected, body.m * 100 + np.abs(body.I_c).max() * 10)


@pytest.mark.parametrize("term", ["M", "G", "Q"])
@given(seed=seeds)
def test_each_gauss_term_separately(term, seed):
    """Stage by stage: M alone (ẏ = 0, g = 0), G ẏ alone (ÿ = 0, g = 0) and Q alone
    (ẏ = ÿ = 0) each equal the matching part of the Newton–Euler residual."""
    rng = np.random.default_rng(seed)
    body = _body(rng)
    twist, accel, gravity = _random_motion(rng)
    zero = np.zeros(6)
    twist, accel, gravity = {
        "M": (zero, accel, np.zeros(3)),
        "G": (twist, zero, np.zeros(3)),
        "Q": (zero, zero, gravity),
    }[term]
    M, h = body.gauss_terms(twist, np.eye(3), gravity)
    expected = newton_euler(body.m, body.r_c, body.I_c, twist, accel, gravity)
    _assert_close(M @ accel - h, expected, body.m * 100 + np.abs(body.I_c).max() * 10)


@given(seeds)
def test_mass_matrix_is_the_projection_of_the_mass_centre_momenta(seed):
    """B(10): M = Jᵀ diag(m E, I_c) J with J = ∂(v_c, ω)/∂ẏ = [[E, −r̃_c], [0, E]]."""
    rng = np.random.default_rng(seed)
    body = _body(rng)
    J = np.eye(6)
    J[:3, 3:] = -np.array(
        [[0, -body.r_c[2], body.r_c[1]], [body.r_c[2], 0, -body.r_c[0]], [-body.r_c[1], body.r_c[0], 0]]
    )
    D = np.zeros((6, 6))
    D[:3, :3], D[3:, 3:] = body.m * np.eye(3), body.I_c
    M, _ = body.gauss_terms(np.zeros(6), np.eye(3), np.zeros(3))
    _assert_close(M, J.T @ D @ J, np.abs(M).max())


@pytest.mark.parametrize("kind", [pq.RigidBody, pq.PlanarBody], ids=["spatial", "planar"])
@given(seed=seeds)
def test_mass_matrix_is_symmetric_positive_definite(kind, seed):
    """M_n = M_nᵀ and its eigenvalues are positive (a body with mass and a regular inertia
    tensor). Symmetric to round-off, not bitwise: I_c = R diag Rᵀ is itself symmetric only
    to a few ε, and I_O = I_c − m r̃_c r̃_c inherits that."""
    rng = np.random.default_rng(seed)
    body = _body(rng, kind)
    M, _ = body.gauss_terms(np.zeros(body.n_y), np.eye(3), np.zeros(3))
    assert np.abs(M - M.T).max() <= RTOL * np.abs(M).max()
    assert np.linalg.eigvalsh(M).min() > 0.0


@pytest.mark.parametrize("plane", PLANES)
@given(seed=seeds)
def test_planar_body_equals_the_spatial_body_restricted_to_its_plane(plane, seed):
    """docs/theory.md §3: for ẏ in the plane (the out-of-plane twist components zero), the planar
    body's (M, h) are the spatial body's in-plane rows and columns, at a random
    orientation and gravity (any direction: its in-plane part is what acts)."""
    rng = np.random.default_rng(seed)
    m = random_mass(rng)
    r_c, I_c = rng.uniform(-0.5, 0.5, 3), random_inertia(rng, m)
    planar, spatial = pq.PlanarBody(m, r_c, I_c, plane), pq.RigidBody(m, r_c, I_c)
    rows = {"xy": [0, 1, 5], "yz": [1, 2, 3], "zx": [2, 0, 4], "xz": [0, 2, 4]}[plane]
    y_dot, gravity, R = rng.uniform(-2, 2, 3), rng.uniform(-10, 10, 3), random_rotation(rng)
    twist = np.zeros(6)
    twist[rows] = y_dot
    M, h = planar.gauss_terms(y_dot, R, gravity)
    M6, h6 = spatial.gauss_terms(twist, R, gravity)
    scale = m * 100 + np.abs(I_c).max() * 10
    _assert_close(M, M6[np.ix_(rows, rows)], scale)
    _assert_close(h, h6[rows], scale)
    assert planar.kinetic_energy(y_dot) == pytest.approx(spatial.kinetic_energy(twist), rel=RTOL, abs=0)


@given(seeds)
def test_planar_body_in_xy_equals_the_plane_rigid_body_equations(seed):
    """An independent 2-D derivation for the x–y plane, ẏ = (v_x, v_y, ω), r_c = (c_x, c_y):
    v_c = (v_x − ω c_y, v_y + ω c_x), p = m v_c, and in the frame turning with ω

        m (a_x − α c_y) − ω p_y − m g_x = h-residual₁,   m (a_y + α c_x) + ω p_x − m g_y = ₂,
        I_zz α + (r_c × force residual)_z = ₃   (I_zz about the mass centre).
    """
    rng = np.random.default_rng(seed)
    m, r_c = random_mass(rng), rng.uniform(-0.5, 0.5, 3)
    I_zz = m * rng.uniform(0.01, 0.3)
    body = pq.PlanarBody(m, r_c, I_zz, "xy")
    (vx, vy, w), (ax, ay, alpha) = rng.uniform(-2, 2, (2, 3))
    g = np.append(rng.uniform(-10, 10, 2), 0.0)
    cx, cy = r_c[:2]
    px, py = m * (vx - w * cy), m * (vy + w * cx)
    fx = m * (ax - alpha * cy) - w * py - m * g[0]
    fy = m * (ay + alpha * cx) + w * px - m * g[1]
    expected = np.array([fx, fy, I_zz * alpha + cx * fy - cy * fx])
    M, h = body.gauss_terms(np.array([vx, vy, w]), np.eye(3), g)
    _assert_close(M @ np.array([ax, ay, alpha]) - h, expected, m * 100)


@given(seeds)
def test_point_mass_has_no_rotary_inertia(seed):
    """A PointMass is a rigid body with I_c = 0: M = [[m E, −m r̃], [m r̃, −m r̃ r̃]] of rank 3
    and its Gauss terms are Newton's law for the particle at r_c (Newton–Euler with I_c = 0)."""
    rng = np.random.default_rng(seed)
    m, r_c = random_mass(rng), rng.uniform(-1, 1, 3)
    bob = pq.PointMass(m, r_c)
    assert np.array_equal(bob.I_c, np.zeros((3, 3)))
    twist, accel, gravity = _random_motion(rng)
    M, h = bob.gauss_terms(twist, np.eye(3), gravity)
    assert np.linalg.matrix_rank(M, tol=1e-10 * m) == 3
    _assert_close(M @ accel - h, newton_euler(m, r_c, np.zeros((3, 3)), twist, accel, gravity), m * 100)


def test_rigid_group_equals_each_body_alone():
    """``RigidGroup`` (stacked evaluation) gives every body's own (M_n, h_n), for spatial and
    planar bodies (the group the kinematics module uses)."""
    rng = np.random.default_rng(5)
    for kind in (pq.RigidBody, pq.PlanarBody):
        bodies = [_body(rng, kind) for _ in range(4)]
        group = RigidGroup(bodies)
        y_dot = rng.uniform(-2, 2, (4, bodies[0].n_y))
        R = np.array([random_rotation(rng) for _ in range(4)])
        gravity = rng.uniform(-10, 10, 3)
        H = group.h(y_dot, R, gravity)
        for k, body in enumerate(bodies):
            M, h = body.gauss_terms(y_dot[k], R[k], gravity)
            assert np.array_equal(group.M[k], M)
            _assert_close(H[k], h, body.m * 100)


@given(seeds)
def test_kinetic_and_potential_energy(seed):
    """½ ẏᵀ M ẏ = ½ m v_c² + ½ ωᵀ I_c ω (König) and V = −m g · (r + R r_c)."""
    rng = np.random.default_rng(seed)
    body = _body(rng)
    twist, _, gravity = _random_motion(rng)
    v_c = twist[:3] + np.cross(twist[3:], body.r_c)
    T = 0.5 * body.m * v_c @ v_c + 0.5 * twist[3:] @ body.I_c @ twist[3:]
    assert body.kinetic_energy(twist) == pytest.approx(T, rel=RTOL, abs=0)
    R, r = random_rotation(rng), rng.uniform(-2, 2, 3)
    assert body.potential_energy(R, r, gravity) == pytest.approx(
        -body.m * gravity @ (r + R @ body.r_c), rel=RTOL, abs=RTOL * body.m * 100
    )

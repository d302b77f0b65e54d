"""Spatial kinematics (projeq.spatial): spin matrices, rotations, quaternions, chain matrices.

Notation of docs/theory.md §1 and §4: ``skew(a) b = a × b``; ``A_np`` rotates p- into n-coordinates;
``T_np = [[A_np, −A_np r̃_pn], [0, A_np]]`` carries the twist (v, ω) of a frame p to the
twist of a frame n rigidly attached to it (Bremer B(15): ẏ_n = T_np ẏ_p + F_n ṡ_n,
T_31 = T_32 T_21).

Tolerances: the algebraic identities are compared to 100 ε relative — each entry is a
handful of products of O(1) numbers, so round-off is a few ε: measured ≤ 1.6e-15 (det R − 1)
and ≤ 1.3e-15 relative (every ``_close``) over the hypothesis draws (was 1e-12). Derivative
checks say in their docstrings how they are differentiated and what error that leaves.
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from projeq.spatial import (
    axis_spin,
    chain_matrix,
    cross,
    cross_motion,
    quaternion_matrix,
    quaternion_rate_matrix,
    rodrigues,
    rotation,
    rotation_x,
    rotation_y,
    rotation_z,
    skew,
    skew_stack,
    unit_axis,
    vee,
)

RTOL = 100 * np.finfo(float).eps  # a few ε of round-off in O(1) products, measured ≤ 1.6e-15 (module docstring)
seeds = st.integers(0, 2**32 - 1)


def _unit(rng):
    v = rng.standard_normal(3)
    return v / np.linalg.norm(v)


def _quaternion(rng):
    quat = rng.standard_normal(4)
    return quat / np.linalg.norm(quat)


def _close(a, b, scale=1.0, rtol=RTOL):
    return np.abs(np.asarray(a) - np.asarray(b)).max() <= rtol * max(scale, np.abs(b).max(), 1e-300)


# -- spin matrices -----------------------------------------------------------------------
@given(seeds)
def test_skew_times_b_is_the_cross_product(seed):
    """ã b = a × b (docs/theory.md §1), against numpy's cross product; ã is skew-symmetric."""
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-10, 10, (2, 3))
    assert _close(skew(a) @ b, np.cross(a, b), np.abs(a).max() * np.abs(b).max())
    assert np.array_equal(skew(a).T, -skew(a))


@given(seeds)
def test_cross_matches_numpy_for_vectors_and_stacks(seed):
    """``cross`` (a hand-written a × b) equals ``np.cross`` on vectors and row-wise on stacks."""
    rng = np.random.default_rng(seed)
    a, b = rng.uniform(-10, 10, (2, 5, 3))
    assert _close(cross(a[0], b[0]), np.cross(a[0], b[0]), 100.0)
    assert _close(cross(a, b), np.cross(a, b), 100.0)


def test_skew_stack_is_skew_row_by_row():
    """``skew_stack`` on a (2, 4, 3) stack equals ``skew`` applied to every 3-vector."""
    a = np.random.default_rng(3).standard_normal((2, 4, 3))
    S = skew_stack(a)
    assert S.shape == (2, 4, 3, 3)
    for i in range(2):
        for j in range(4):
            assert np.array_equal(S[i, j], skew(a[i, j]))


def test_vee_inverts_skew():
    """vee(ã) = a."""
    a = np.array([0.3, -1.2, 2.5])
    assert _close(vee(skew(a)), a)


@pytest.mark.parametrize(
    "axis, expected",
    [("x", (1, 0, 0)), ("-y", (0, -1, 0)), ("z", (0, 0, 1)), ((3.0, 0.0, 4.0), (0.6, 0.0, 0.8))],
    ids=["x", "minus-y", "z", "vector"],
)
def test_unit_axis(axis, expected):
    """Named axes and vectors become unit 3-vectors."""
    assert _close(unit_axis(axis), np.array(expected, dtype=float))


# -- rotations --------------------------------------------------------------------------------
@given(seeds)
def test_rotation_is_proper_orthonormal_and_fixes_its_axis(seed):
    """Rodrigues' R(e, φ): RᵀR = E, det R = 1, R e = e, and R(e, a) R(e, b) = R(e, a + b)."""
    rng = np.random.default_rng(seed)
    e, (a, b) = _unit(rng), rng.uniform(-np.pi, np.pi, 2)
    R = rotation(e, a)
    assert _close(R.T @ R, np.eye(3))
    assert abs(np.linalg.det(R) - 1.0) <= RTOL
    assert _close(R @ e, e)
    assert _close(R @ rotation(e, b), rotation(e, a + b))


@pytest.mark.parametrize("axis, R", [(0, rotation_x), (1, rotation_y), (2, rotation_z)], ids=["x", "y", "z"])
def test_rotations_about_the_coordinate_axes_are_rodrigues(axis, R):
    """R_x, R_y, R_z (written out) equal Rodrigues' R(e, φ) about e_x, e_y, e_z, and
    ``rodrigues`` with a precomputed (ẽ, ẽ²) equals ``rotation``."""
    e = np.eye(3)[axis]
    for phi in np.linspace(-3.0, 3.0, 7):
        assert _close(R(phi), rotation(e, phi))
        assert np.array_equal(rodrigues(axis_spin(e), phi), rotation(e, phi))


def test_rotation_about_z_by_a_quarter_turn():
    """R(e_z, π/2) maps e_x to e_y (right-hand rule; columns = rotated axes)."""
    assert _close(rotation(np.array([0.0, 0.0, 1.0]), np.pi / 2) @ [1.0, 0.0, 0.0], np.array([0.0, 1.0, 0.0]))


@given(seeds)
def test_quaternion_matrix_is_proper_orthonormal(seed):
    """The rotation of a random unit quaternion: RᵀR = E and det R = 1."""
    R = quaternion_matrix(_quaternion(np.random.default_rng(seed)))
    assert _close(R.T @ R, np.eye(3))
    assert abs(np.linalg.det(R) - 1.0) <= RTOL


@given(seeds)
def test_quaternion_matrix_equals_rodrigues(seed):
    """q = (cos φ/2, sin φ/2 e) is the rotation R(e, φ); q and −q are the same rotation."""
    rng = np.random.default_rng(seed)
    e, phi = _unit(rng), rng.uniform(-np.pi, np.pi)
    quat = np.concatenate(([np.cos(phi / 2)], np.sin(phi / 2) * e))
    assert _close(quaternion_matrix(quat), rotation(e, phi))
    assert _close(quaternion_matrix(-quat), rotation(e, phi))


@given(seeds)
def test_quaternion_rate_matrix_gives_the_body_angular_velocity(seed):
    """q̇ = Γ(q) ω with ω in body coordinates must give Ṙ = R ω̃ (body angular velocity).

    Ṙ along q̇ is taken by complex step, Im R(q + iε q̇)/ε with ε = 1e-30: R is a quadratic
    polynomial in q, so this is the exact directional derivative to round-off (1e-12)."""
    rng = np.random.default_rng(seed)
    quat, omega = _quaternion(rng), rng.uniform(-3, 3, 3)
    q_dot = quaternion_rate_matrix(quat) @ omega
    R_dot = np.imag(quaternion_matrix(quat + 1e-30j * q_dot)) / 1e-30
    assert _close(R_dot, quaternion_matrix(quat) @ skew(omega), np.abs(omega).max())


@given(seeds)
def test_quaternion_rate_keeps_the_norm(seed):
    """qᵀ Γ(q) = 0 (q̇ is tangent to the unit sphere) and ΓᵀΓ = E/4 (Γ has full rank)."""
    quat = _quaternion(np.random.default_rng(seed))
    G = quaternion_rate_matrix(quat)
    assert _close(quat @ G, np.zeros(3), 1.0)
    assert _close(G.T @ G, np.eye(3) / 4)


# -- chain matrices ---------------------------------------------------------------------------
@given(seeds)
def test_chain_matrix_moves_a_twist_to_a_rigidly_attached_frame(seed):
    """ẏ_n = T_np ẏ_p for n rigidly attached to p: v_n = A_np (v_p + ω_p × r_pn) and
    ω_n = A_np ω_p (the velocity of the point O_n of the rigid body p)."""
    rng = np.random.default_rng(seed)
    A_np, r_pn = rotation(_unit(rng), rng.uniform(-np.pi, np.pi)), rng.uniform(-2, 2, 3)
    v_p, omega_p = rng.uniform(-2, 2, (2, 3))
    expected = np.concatenate((A_np @ (v_p + np.cross(omega_p, r_pn)), A_np @ omega_p))
    assert _close(chain_matrix(A_np, r_pn) @ np.concatenate((v_p, omega_p)), expected, 10.0)


@given(seeds)
def test_chain_matrices_compose(seed):
    """T_31 = T_32 T_21 (B(15)) for three rigidly connected frames: A_31 = A_32 A_21 and
    r_13 = r_12 + A_12 r_23 (all offsets in the first frame of their subscript)."""
    rng = np.random.default_rng(seed)
    A_21, A_32 = (rotation(_unit(rng), rng.uniform(-np.pi, np.pi)) for _ in range(2))
    r_12, r_23 = rng.uniform(-2, 2, (2, 3))
    T_31 = chain_matrix(A_32 @ A_21, r_12 + A_21.T @ r_23)
    assert _close(chain_matrix(A_32, r_23) @ chain_matrix(A_21, r_12), T_31, 4.0)


def test_chain_matrix_on_stacks_equals_one_by_one():
    """``chain_matrix`` on a stack of 5 (A, r) equals it applied to each."""
    rng = np.random.default_rng(7)
    A = np.array([rotation(_unit(rng), rng.uniform(-3, 3)) for _ in range(5)])
    r = rng.standard_normal((5, 3))
    T = chain_matrix(A, r)
    for k in range(5):
        assert np.array_equal(T[k], chain_matrix(A[k], r[k]))


def _derivative(f, x0, h=1e-3):
    """Fourth-order central difference f′(x0) = [8(f(x+h) − f(x−h)) − (f(x+2h) − f(x−2h))]/12h.

    Error h⁴/30 |f⁽⁵⁾| + ~1.5 ε |f|/h: for the trigonometric T(θ) below with |θ̇| ≤ 2 that is
    ≲ 1e-12 + 3e-13, so 1e-10 relative is a bound with margin."""
    return (8 * (f(x0 + h) - f(x0 - h)) - (f(x0 + 2 * h) - f(x0 - 2 * h))) / (12 * h)


@pytest.mark.parametrize("kind", ["revolute", "prismatic"])
@given(seed=seeds)
def test_cross_motion_is_the_derivative_of_the_chain_matrix(kind, seed):
    """u × w = Ṫ_np ẏ_p (docs/theory.md §4, kinematics.forward) with u = T_np ẏ_p, w = F ṡ the joint's
    relative twist. The joint frame sits at r_pn with orientation A_pJ; a revolute turns the
    child by θ about e (A_pn = A_pJ R(e, θ), offset fixed), a prismatic slides it by x along e
    (A_pn = A_pJ, r_pn = r_0 + A_pJ e x). ẏ_p is held fixed and Ṫ_np ẏ_p = dT/dθ θ̇ ẏ_p is
    differentiated numerically (see ``_derivative``)."""
    rng = np.random.default_rng(seed)
    e, A_pJ = _unit(rng), rotation(_unit(rng), rng.uniform(-3, 3))
    r0, y_p = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 6)
    x0, x_dot = rng.uniform(-1, 1), rng.uniform(-2, 2)

    def T(x):
        if kind == "revolute":
            return chain_matrix((A_pJ @ rotation(e, x)).T, r0)
        return chain_matrix(A_pJ.T, r0 + A_pJ @ e * x)

    w = np.concatenate((np.zeros(3), e)) if kind == "revolute" else np.concatenate((e, np.zeros(3)))
    T_dot_y_p = _derivative(lambda x: T(x) @ y_p, x0) * x_dot
    got = cross_motion(T(x0) @ y_p, w * x_dot)
    assert np.abs(got - T_dot_y_p).max() <= 1e-10 * max(1.0, np.abs(T_dot_y_p).max())


def test_cross_motion_on_stacks_equals_one_by_one():
    """Row-wise ``cross_motion`` on (4, 6) stacks equals it on each pair of twists."""
    u, w = np.random.default_rng(11).standard_normal((2, 4, 6))
    got = cross_motion(u, w)
    for k in range(4):
        assert np.array_equal(got[k], cross_motion(u[k], w[k]))


# -- complex safety: complex-step derivatives through the module ---------------------------
# Im f(x + iε ẋ)/ε with ε = 1e-30 is the exact directional derivative to round-off (no
# subtraction): measured ≤ 6e-16 relative over 300 seeds (rotation, chain matrix, cross
# products), so COMPLEX_RTOL = 1e-14 still catches a float-only buffer (whose imaginary
# part is lost: an error of O(1)) or a wrong derivative.
STEP = 1e-30
COMPLEX_RTOL = 1e-14


@given(seeds)
def test_complex_step_of_rodrigues_is_the_analytic_derivative(seed):
    """R(e, φ) = exp(φ ẽ), so dR/dφ = ẽ R: the complex step through ``rotation``,
    ``rodrigues`` and ``rotation_x/y/z`` gives it."""
    rng = np.random.default_rng(seed)
    e, phi = _unit(rng), rng.uniform(-np.pi, np.pi)
    R_dot = np.imag(rotation(e, phi + 1j * STEP)) / STEP
    assert _close(R_dot, skew(e) @ rotation(e, phi), rtol=COMPLEX_RTOL)
    assert _close(np.imag(rodrigues(axis_spin(e), phi + 1j * STEP)) / STEP, R_dot, rtol=COMPLEX_RTOL)
    for axis, R in enumerate((rotation_x, rotation_y, rotation_z)):
        E = skew(np.eye(3)[axis])
        assert _close(np.imag(R(phi + 1j * STEP)) / STEP, E @ R(phi), rtol=COMPLEX_RTOL)


@given(seeds)
def test_complex_step_of_the_chain_matrix_is_its_analytic_derivative(seed):
    """T(φ) = chain_matrix(A(φ), r(φ)) with A = R(e, φ)ᵀ, r = r₀ + φ v: the complex step
    gives Ṫ = [[Ȧ, −Ȧ r̃ − A ṽ], [0, Ȧ]] with Ȧ = −Aẽ (dRᵀ/dφ = (ẽ R)ᵀ = −Rᵀ ẽ); on stacks too."""
    rng = np.random.default_rng(seed)
    e, phi = _unit(rng), rng.uniform(-np.pi, np.pi)
    r0, v = rng.uniform(-2, 2, (2, 3))
    A, A_dot = rotation(e, phi).T, -rotation(e, phi).T @ skew(e)
    expected = np.zeros((6, 6))
    expected[:3, :3] = expected[3:, 3:] = A_dot
    expected[:3, 3:] = -A_dot @ skew(r0 + phi * v) - A @ skew(v)
    z = phi + 1j * STEP
    T_dot = np.imag(chain_matrix(rotation(e, z).T, r0 + z * v)) / STEP
    assert _close(T_dot, expected, 4.0, rtol=COMPLEX_RTOL)
    stack = np.imag(chain_matrix(np.array([rotation(e, z).T] * 2), np.array([r0 + z * v] * 2))) / STEP
    assert np.array_equal(stack, np.array([T_dot, T_dot]))


@given(seeds)
def test_complex_step_through_cross_products(seed):
    """d/dε of a(ε) × b(ε) = ȧ × b + a × ḃ, through ``cross`` (vectors and stacks),
    ``skew_stack`` and ``cross_motion`` (bilinear: the complex step is exact)."""
    rng = np.random.default_rng(seed)
    a, a_dot, b, b_dot = rng.uniform(-3, 3, (4, 4, 6))
    expected = cross_motion(a_dot, b) + cross_motion(a, b_dot)
    got = np.imag(cross_motion(a + 1j * STEP * a_dot, b + 1j * STEP * b_dot)) / STEP
    assert _close(got, expected, 10.0, rtol=COMPLEX_RTOL)
    u, u_dot, w, w_dot = (x[..., :3] for x in (a, a_dot, b, b_dot))
    got = np.imag(cross(u + 1j * STEP * u_dot, w + 1j * STEP * w_dot)) / STEP
    assert _close(got, cross(u_dot, w) + cross(u, w_dot), 10.0, rtol=COMPLEX_RTOL)
    got = np.imag(cross(u[0] + 1j * STEP * u_dot[0], w[0])) / STEP
    assert _close(got, cross(u_dot[0], w[0]), 10.0, rtol=COMPLEX_RTOL)
    assert _close(np.imag(skew_stack(u + 1j * STEP * u_dot)) / STEP, skew_stack(u_dot), rtol=COMPLEX_RTOL)

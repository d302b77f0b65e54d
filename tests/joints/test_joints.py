"""Joints (docs/theory.md §4): the relative kinematics (A, r, F⁶, w = F⁶ ṡ + f⁶, ζ = Ḟ⁶ ṡ + ḟ⁶) of
every joint type, checked against derivatives of the joint's own pose and twist, and the
two ways of defining a user joint against each other.

For a joint with coordinates q_n, minimal velocities ṡ_n and q̇_n = K ṡ_n + k:

- the relative twist w must be the time derivative of the pose (A, r) along q̇
  (``projeq.joints.pose_twist_mismatch``): v = Aᵀ ṙ, ω̃ = Aᵀ Ȧ;
- ζ must be the time derivative of w = F ṡ + f along (q̇, t) at *fixed* ṡ — the joint's own
  part of ζ_n = Ṫ_np ẏ_p + Ḟ_n ṡ_n + ḟ_n (docs/theory.md §4);
- ``UserJoint.from_sympy`` (symbolic ζ) and ``UserJoint.from_functions`` (complex-step ζ)
  must describe the same joint, e.g. Bremer's car B(6), B(11).

Every joint kind of ``tests/strategies.py`` is covered, one test case each.
"""

import warnings

import numpy as np
import pytest
import strategies as S
import sympy as sp
from hypothesis import given
from hypothesis import strategies as st

import projeq as pq
from projeq.joints import pose_twist_mismatch
from projeq.assembly.kinematics import forward
from projeq.spatial import chain_matrix

seeds = st.integers(0, 2**32 - 1)
EPS = np.finfo(float).eps
KINDS = sorted(set(S.SPATIAL_KINDS) | {"car_sympy", "prescribed_prismatic", "planar_xz"})


def _joint(kind, rng):
    """One joint of ``kind`` with random axis, placement and parameters (parent: ground)."""
    if kind == "car_sympy":
        return S.car_joint_sympy()
    if kind == "prescribed_prismatic":
        return S._prescribed(pq.Prismatic(None, S.unit_vector(rng)), rng)
    if kind == "planar_xz":
        return pq.Planar(None, "xz")
    return S.spatial_joint(kind, None, rng)


def _state(joint, rng):
    q = joint.normalized(rng.uniform(-1, 1, joint.n_q))
    return q, rng.uniform(-2, 2, joint.n_s), float(rng.uniform(0, 3))


def _d_dt(f, h=1e-3):
    """Fourth-order central difference of τ ↦ f(τ) at τ = 0:
    [8 (f(h) − f(−h)) − (f(2h) − f(−2h))] / 12h, error h⁴/30 |f⁽⁵⁾| + 1.5 ε |f| / h.
    The joints' twists are trigonometric with rates ≤ ~4 (|ṡ| ≤ 2, prescribed ω ≤ 2), so
    the error is ≲ 1e-12·4⁵/30 + 3e-13 ≈ 4e-11 relative: checks use 1e-9."""
    return (8 * (f(h) - f(-h)) - (f(2 * h) - f(-2 * h))) / (12 * h)


@pytest.mark.parametrize("kind", KINDS)
@given(seed=seeds)
def test_twist_is_the_derivative_of_the_pose(kind, seed):
    """F ṡ + f = (Aᵀ ṙ, (Aᵀ Ȧ)^∨) along q̇ = K ṡ + k (``pose_twist_mismatch``).

    pose_twist_mismatch uses central differences of step 1e-7: truncation ~1e-14, round-off
    ~ε (|A| + |r|)/1e-7 ≈ 4e-9 for |r| ≤ 2. Measured ≤ 2.7e-9 (1 + |w|) over 13000 examples (1000 of the
    "thorough" profile per kind); the bound 2.7e-8 (1 + |w|) is 10 times that (was 1e-7), and any wrong
    K or F (an O(1) error) fails."""
    rng = np.random.default_rng(seed)
    joint = _joint(kind, rng)
    q, s_dot, t = _state(joint, rng)
    w = joint.relative(q, s_dot, t).w
    assert pose_twist_mismatch(joint, q, s_dot, t) <= 2.7e-8 * (1.0 + np.abs(w).max())


@pytest.mark.parametrize("kind", KINDS)
@given(seed=seeds)
def test_zeta_is_the_derivative_of_the_twist_at_fixed_velocities(kind, seed):
    """ζ = Ḟ ṡ + ḟ = d/dt (F(q, t) ṡ + f(q, t)) along (q̇, 1) with ṡ held fixed (docs/theory.md §4),
    by the fourth-order difference of ``_d_dt`` along q(τ) = normalized(q + τ q̇), t + τ: measured ≤ 6.2e-12
    of the scale over 13000 examples (1000 of the "thorough" profile per kind); the bound is 10 times
    that (was 1e-9)."""
    rng = np.random.default_rng(seed)
    joint = _joint(kind, rng)
    q, s_dot, t = _state(joint, rng)
    q_dot = joint.q_dot(q, s_dot, t)
    rel = joint.relative(q, s_dot, t)
    numeric = _d_dt(lambda tau: joint.relative(joint.normalized(q + tau * q_dot), s_dot, t + tau).w)
    scale = max(1.0, np.abs(rel.w).max(), np.abs(rel.zeta).max())
    assert np.abs(rel.zeta - numeric).max() <= 6.2e-11 * scale


@pytest.mark.parametrize("kind", KINDS)
@given(seed=seeds)
def test_relative_kinematics_have_consistent_shapes_and_rotation(kind, seed):
    """A is a proper rotation (to 100 ε: measured 8.9e-16 and 1.1e-15 over 650 draws; were 1e-12), F is
    6 × n_s, w = F ṡ + f has 6 entries, K is n_q × n_s."""
    rng = np.random.default_rng(seed)
    joint = _joint(kind, rng)
    q, s_dot, t = _state(joint, rng)
    rel = joint.relative(q, s_dot, t)
    assert np.abs(rel.A.T @ rel.A - np.eye(3)).max() <= 100 * np.finfo(float).eps
    assert abs(np.linalg.det(rel.A) - 1.0) <= 100 * np.finfo(float).eps
    assert rel.F.shape == (6, joint.n_s) and rel.w.shape == (6,) and rel.zeta.shape == (6,)
    assert rel.r.shape == (3,)
    assert joint.K(q, t).shape == (joint.n_q, joint.n_s)


# -- sympy and callables: the same joint -----------------------------------------------
def _sympy_car():
    """Bremer's car B(6), B(11): A = R_z(γ), r = (x, y, 0), F⁶ = [e_x, 0; 0, e_z], K(γ)."""
    x, y, g = q = sp.symbols("x y gamma")
    s = sp.symbols("v_x omega_z")
    A = sp.Matrix([[sp.cos(g), -sp.sin(g), 0], [sp.sin(g), sp.cos(g), 0], [0, 0, 1]])
    F = sp.Matrix([[1, 0], [0, 0], [0, 0], [0, 0], [0, 0], [0, 1]])
    K = sp.Matrix([[sp.cos(g), 0], [sp.sin(g), 0], [0, 1]])
    return pq.UserJoint.from_sympy(q, s, A, [x, y, 0], F, K), S.car_joint()


def _rot_sym(axis, angle):
    c, s = sp.cos(angle), sp.sin(angle)
    return {
        "x": sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]]),
        "y": sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
        "z": sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
    }[axis]


def _sympy_spherical():
    """The Cardan ball joint of strategies.spherical_joint, F depending on q (ζ ≠ 0)."""
    a, b, c = q = sp.symbols("a b c")
    s = sp.symbols("u0:3")
    A = _rot_sym("z", a) * _rot_sym("y", b) * _rot_sym("x", c)
    F = sp.zeros(6, 3)
    F[3:, 0] = _rot_sym("x", c).T * _rot_sym("y", b).T * sp.Matrix([0, 0, 1])
    F[3:, 1] = _rot_sym("x", c).T * sp.Matrix([0, 1, 0])
    F[3, 2] = 1
    return pq.UserJoint.from_sympy(q, s, A, [0, 0, 0], F, sp.eye(3)), S.spherical_joint()


def _sympy_turntable(spin=1.3):
    """The rheonomic slider of strategies.turntable_joint: f(q, t) = (0, Ω x, 0, 0, 0, Ω)."""
    (x,) = q = [sp.Symbol("x")]
    t = sp.Symbol("t")
    A = _rot_sym("z", spin * t)
    F = sp.Matrix([1, 0, 0, 0, 0, 0])
    f = sp.Matrix([0, spin * x, 0, 0, 0, spin])
    joint = pq.UserJoint.from_sympy(q, [sp.Symbol("v")], A, A * sp.Matrix([x, 0, 0]), F, sp.eye(1), f=f, t=t)
    return joint, S.turntable_joint(spin)


def _sympy_screw(pitch=0.3):
    """A screw about z: R_z(θ), r = (0, 0, pitch θ), F⁶ = (0, 0, pitch, 0, 0, 1)."""
    (th,) = q = [sp.Symbol("theta")]
    F = sp.Matrix([0, 0, pitch, 0, 0, 1])
    return pq.UserJoint.from_sympy(
        q, [sp.Symbol("w")], _rot_sym("z", th), [0, 0, pitch * th], F, sp.eye(1)
    ), S.screw_joint((0.0, 0.0, 1.0), pitch)


PAIRS = {
    "car": _sympy_car,
    "spherical": _sympy_spherical,
    "turntable": _sympy_turntable,
    "screw": _sympy_screw,
}


@pytest.fixture(scope="module", params=sorted(PAIRS))
def joint_pair(request):
    return request.param, PAIRS[request.param]()


@pytest.mark.parametrize("seed", range(5), ids=lambda s: f"state{s}")
def test_from_sympy_equals_from_functions(joint_pair, seed):
    """The same joint written as sympy expressions and as numpy callables gives the same
    (A, r, F, w, ζ), K and q̇ at random states: both are exact formulas (ζ symbolic vs
    complex step, exact to round-off), so they agree to 100 ε relative (measured ≤ 1.7e-16, K and q̇
    exactly; was 1e-12)."""
    _, (symbolic, numeric) = joint_pair
    eps = np.finfo(float).eps
    rng = np.random.default_rng(seed)
    q, s_dot, t = _state(symbolic, rng)
    a, b = symbolic.relative(q, s_dot, t), numeric.relative(q, s_dot, t)
    for field in ("A", "r", "F", "w", "zeta"):
        x, y = getattr(a, field), getattr(b, field)
        assert np.shape(x) == np.shape(y), field
        assert np.abs(x - y).max(initial=0.0) <= 100 * eps * max(1.0, np.abs(y).max(initial=0.0)), field
    assert np.abs(symbolic.K(q, t) - numeric.K(q, t)).max() <= 100 * eps
    assert np.abs(symbolic.q_dot(q, s_dot, t) - numeric.q_dot(q, s_dot, t)).max() <= 100 * eps * max(
        1.0, np.abs(s_dot).max()
    )


def test_car_joint_is_bremers_functional_matrix():
    """B(11): for the car with the mass centre at distance c along the body x-axis, the
    velocities (v_cx, v_cy, ω_z) of the mass centre are [[1, 0], [0, c], [0, 1]] ṡ."""
    c = 1.2
    system = pq.System({"car": pq.PlanarBody(1200.0, (c, 0.0, 0.0), 3228.0, "xy")}, {"car": S.car_joint()})
    q = np.array([0.4, -0.3, 0.8])
    J = np.empty((3, 2))
    for k in range(2):
        twist = forward(system, q, np.eye(2)[k], 0.0).twist[0]
        v_c = twist[:3] + np.cross(twist[3:], (c, 0.0, 0.0))
        J[:, k] = (v_c[0], v_c[1], twist[5])
    assert np.abs(J - np.array([[1.0, 0.0], [0.0, c], [0.0, 1.0]])).max() <= 1e-15


def test_prescribed_motion_as_sympy_expression_equals_callable():
    """Prescribed(motion=sp.sin(2t)) and the callable t ↦ (sin 2t, 2 cos 2t, −4 sin 2t) give the
    same relative kinematics, and ζ carries F θ̈ (docs/theory.md §4)."""
    t_sym = sp.Symbol("t")
    inner = pq.Revolute(None, (0.0, 0.6, 0.8))
    a = pq.Prescribed(inner, motion=sp.sin(2 * t_sym))
    b = pq.Prescribed(inner, motion=lambda t: (np.sin(2 * t), 2 * np.cos(2 * t), -4 * np.sin(2 * t)))
    for t in (0.0, 0.7, 2.1):
        ra, rb = a.relative(np.zeros(0), np.zeros(0), t), b.relative(np.zeros(0), np.zeros(0), t)
        for x, y in zip(ra, rb):
            assert np.abs(x - y).max(initial=0.0) <= 1e-14
        assert np.abs(ra.zeta - np.array([0, 0, 0, 0, 0.6, 0.8]) * (-4 * np.sin(2 * t))).max() <= 1e-14


# -- chain matrices from the tree's poses ---------------------------------------------------
@pytest.mark.parametrize("planar", [False, True], ids=["spatial", "planar"])
@given(data=st.data())
def test_chain_matrices_equal_those_of_the_absolute_poses(planar, data):
    """T_np from ``kinematics.forward`` equals S_n T⁶(A_np, r_pn) S_pᵀ built from the absolute
    poses alone: A_np = R_nᵀ R_p, r_pn = R_pᵀ (r_n − r_p) (docs/theory.md §4; composing the joint frame
    and the joint's relative pose must give the same frames), and ẏ_n = T_np ẏ_p + F_n ṡ_n + S_n f_n."""
    tree = data.draw(S.trees(max_n=8, planar=planar, forces=False), label="tree")
    system = tree.system
    kin = forward(system, tree.q, tree.s_dot, tree.t)
    for n, p in enumerate(system.parent):
        A_np = kin.R[n].T @ kin.R[p]
        r_pn = kin.R[p].T @ (kin.r[n] - kin.r[p])
        S_n = np.eye(6) if system.S[n] is None else system.S[n]
        S_p = np.eye(6) if system.S[p] is None else system.S[p]
        expected = S_n @ chain_matrix(A_np, r_pn) @ S_p.T
        scale = max(1.0, np.abs(expected).max(initial=0.0))
        # measured ≤ 1.1e-15 and 3.5e-16 of the scale (was 1e-12)
        assert np.abs(kin.T[n] - expected).max(initial=0.0) <= 100 * EPS * scale, f"T of {system.names[n]}"
        joint = system.joints[n]
        f = joint.relative(system._q_get[n](tree.q), np.zeros(joint.n_s), tree.t).w
        chain = kin.T[n] @ kin.y_dot[p] + kin.F[n] @ system._s_get[n](tree.s_dot) + S_n @ f
        assert np.abs(kin.y_dot[n] - chain).max() <= 100 * EPS * max(1.0, np.abs(kin.y_dot[n]).max()), (
            system.names[n]
        )


def test_a_prescribed_motion_takes_the_complex_step():
    """Prescribed.angles at a complex t keeps the imaginary parts, so the complex step through a
    complex-safe motion gives its rates exactly: Im θ(t + ih)/h = θ̇ and Im θ̇(t + ih)/h = θ̈ for
    the spin-up's hub motion (closed form in scenes.elastic.spin_up_motion), during and after the
    manoeuvre; the default scene's energy check then needs no differences (no DifferencesWarning)."""
    from projeq.analysis.differentiation import DifferencesWarning
    from projeq.scenes.elastic import spin_up_motion
    from projeq.simulation.integrators import conserves_energy

    joint = pq.Prescribed(pq.Revolute(axis="z"), spin_up_motion(4.0, 15.0))
    for t in (3.0, 20.0):
        stepped, exact = joint.angles(complex(t, 1e-30)), joint.angles(t)
        assert np.imag(stepped[0]) / 1e-30 == pytest.approx(exact[1], rel=1e-14, abs=0)  # measured 1.9e-16
        assert np.imag(stepped[1]) / 1e-30 == pytest.approx(exact[2], rel=1e-14, abs=1e-15)
    system = pq.scenes.spin_up_beam()
    with warnings.catch_warnings():
        warnings.simplefilter("error", DifferencesWarning)
        assert not conserves_energy(system, system.q0, system.s_dot0)  # driven: dE/dt ≠ 0

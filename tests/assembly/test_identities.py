"""Identities from physics and from the structure of the Projection Equation, at single
random states of random trees (STYLE §4.8 habits 3 and 10).

- Kinetic energy: ½ ṡᵀ M ṡ = Σ_n ½ ẏ_nᵀ M_n ẏ_n for scleronomic systems (docs/theory.md §5,
  M = Σ J_nᵀ M_n J_n with ẏ_n = J_n ṡ).
- The functional matrix J_n = ∂ẏ_n/∂ṡ of the chain (J_n = T_np J_p + F_n P_n, docs/theory.md §5,
  B(15)) is the coefficient matrix of ẏ_n in ṡ (Bremer B(11): "nothing but the coefficient
  matrix of the cartesian velocities w.r.t. the minimal velocities").
- Power balance: d(T + V)/dt = ṡᵀ Q_nc along the motion (q̇ = K ṡ, s̈ from the evaluator),
  zero for a conservative system; also for non-holonomic ṡ.
- The chain's accelerations: ÿ_n = T_np ÿ_p + F_n s̈_n + ζ_n (docs/theory.md §4) is the time
  derivative of ẏ_n along (q̇, s̈, t).
- Evaluator reuse: a workspace overwritten by every call gives bit-identical answers.
- ``scenes.chain(n, planar=True)`` equals ``planar=False`` (docs/theory.md §3: a planar body is the
  spatial one restricted to its plane).
"""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from strategies import random_state, trees

import projeq as pq
from projeq.assembly import EVALUATORS
from projeq.assembly.kinematics import forward, gauss_terms

any_plane = st.booleans()


def _scleronomic_trees(max_n=10, forces=True):
    return any_plane.flatmap(
        lambda planar: trees(max_n=max_n, planar=planar, scleronomic=True, forces=forces)
    )


def _chain_J(system, kin):
    """J_n = T_np J_p + F_n P_n, root to leaves (docs/theory.md §5)."""
    J = {-1: np.zeros((0, system.n_s))}
    for n, p in enumerate(system.parent):
        cols, P = system.joint_s_columns(n)
        J[n] = kin.T[n] @ J[p]
        J[n][:, cols] += kin.F[n] @ P
    return J


# -- kinetic energy and the functional matrix -----------------------------------------------
@given(_scleronomic_trees(max_n=12))
def test_kinetic_energy_from_M_equals_the_sum_over_subsystems(tree):
    """½ ṡᵀ M(q) ṡ = Σ ½ ẏ_nᵀ M_n ẏ_n (``System.energy``) for scleronomic systems.
    Both sides add the same positive terms (ṡᵀ J_nᵀ M_n J_n ṡ = ẏ_nᵀ M_n ẏ_n), so there is
    no cancellation: round-off is ~N ε relative; bound 3.2e-14, 10× the largest measured over 1000
    trees (3.2e-15; was 1e-10)."""
    system = tree.system
    kinetic, _ = system.energy(tree.q, tree.s_dot, tree.t)
    from_M = 0.5 * tree.s_dot @ system.mass_matrix(tree.q, tree.t) @ tree.s_dot
    assert abs(from_M - kinetic) <= 3.2e-14 * abs(kinetic), (from_M - kinetic) / kinetic


@given(any_plane.flatmap(lambda planar: trees(max_n=10, planar=planar, forces=False)))
def test_functional_matrix_is_the_coefficient_matrix_of_the_velocities(tree):
    """Column k of J_n (from the chain recurrence) equals ẏ_n(ṡ = e_k) − ẏ_n(ṡ = 0), computed
    by ``kinematics.forward`` with unit vectors (the subtraction removes the rheonomic part
    f). ẏ is exactly linear in ṡ, so the only error is round-off: 100 ε relative (measured ≤ 9.8e-16 over
    1000 trees; was 1e-12). Also
    M = Σ J_nᵀ M_n J_n with these J_n equals ``System.mass_matrix`` (1e-10, sums of
    positive-definite terms)."""
    system, q, t = tree.system, tree.q, tree.t
    rest = forward(system, q, np.zeros(system.n_s), t)
    J = _chain_J(system, rest)
    M_n, _ = gauss_terms(system, rest, q, np.zeros(system.n_s), t)
    columns = [forward(system, q, e_k, t) for e_k in np.eye(system.n_s)]
    M = np.zeros((system.n_s, system.n_s))
    for n in range(len(system.names)):
        coefficients = np.zeros((len(rest.y_dot[n]), system.n_s))
        for k, kin in enumerate(columns):
            coefficients[:, k] = kin.y_dot[n] - rest.y_dot[n]
        scale = max(1.0, np.abs(J[n]).max(initial=0.0))
        error = np.abs(coefficients - J[n]).max(initial=0.0) / scale
        assert error <= 100 * np.finfo(float).eps, (system.names[n], error)
        M += coefficients.T @ M_n[n] @ coefficients
    if system.n_s:
        M_sys = system.mass_matrix(q, t)
        assert np.abs(M - M_sys).max() <= 1e-10 * np.abs(M_sys).max()


# -- the chain's accelerations ----------------------------------------------------------------
H = 1e-3  # step of the fourth-order difference below


def _d_dt(f, h=H):
    """Fourth-order central difference of τ ↦ f(τ) at 0:
    [8 (f(h) − f(−h)) − (f(2h) − f(−2h))] / 12h, error ≈ h⁴/30 |f⁽⁵⁾| + 1.5 ε |f| / h."""
    return (8 * (f(h) - f(-h)) - (f(2 * h) - f(-2 * h))) / (12 * h)


@given(any_plane.flatmap(lambda planar: trees(max_n=8, planar=planar, forces=False)))
def test_chain_accelerations_are_the_derivative_of_the_velocities(tree):
    """ÿ_n = T_np ÿ_p + F_n s̈_n + ζ_n (docs/theory.md §4, with ζ_n = Ṫ_np ẏ_p + Ḟ_n ṡ_n + ḟ_n from
    ``kinematics.forward``) equals d/dt ẏ_n along the straight path (q + τ q̇, ṡ + τ s̈,
    t + τ) for an arbitrary s̈ — a check of every ζ_n, the cross-motion term included.

    Error of ``_d_dt``: truncation h⁴/30 |ẏ⁽⁵⁾| ≲ h⁴ Ω⁵/30 |ẏ| with Ω the fastest rate (the
    largest twist or q̇ entry, ≲ 6 for ≤ 8 bodies with |ṡ| ≤ 1) and round-off ≈ 3e-13 |ẏ|.
    Tolerance (1e-10 + h⁴ Ω⁵/3) relative to max(1, |ÿ|, |ẏ|): ten times the truncation
    estimate (the largest error seen in 500 examples was 1.5e-11)."""
    system, q, s_dot, t = tree.system, tree.q, tree.s_dot, tree.t
    s_ddot = tree.rng.uniform(-1, 1, system.n_s)
    q_dot = system.q_dot(q, s_dot, t)
    kin = forward(system, q, s_dot, t)
    y_ddot = {-1: np.zeros(0)}
    for n, p in enumerate(system.parent):
        cols, P = system.joint_s_columns(n)
        y_ddot[n] = kin.T[n] @ y_ddot[p] + kin.F[n] @ (P @ s_ddot[cols]) + kin.zeta[n]

    def y_dot(tau):
        k = forward(system, system.normalized(q + tau * q_dot), s_dot + tau * s_ddot, t + tau)
        return np.concatenate([k.y_dot[n] for n in range(len(system.names))])

    numeric = _d_dt(y_dot)
    chain = np.concatenate([y_ddot[n] for n in range(len(system.names))])
    omega = max(1.0, np.abs(np.concatenate(kin.twist[:-1])).max(), np.abs(q_dot).max(initial=0.0))
    scale = max(1.0, np.abs(chain).max(), np.abs(y_dot(0.0)).max())
    assert np.abs(chain - numeric).max() <= (1e-10 + H**4 * omega**5 / 3) * scale


# -- power balance --------------------------------------------------------------------------
def _nonconservative_power(system, kin, q, s_dot, t):
    """ṡᵀ Q_nc: the power of the loads that have no potential in ``System.energy`` —
    body forces and torques, joint forces, and the dampers of springs."""
    power = 0.0
    for law in system.forces:
        if isinstance(law, pq.Force):
            n = law.index
            f = law.force(t, q, s_dot)
            f_body = kin.R[n].T @ f if law.frame == "world" else f
            v, omega = kin.twist[n][:3], kin.twist[n][3:]
            power += f_body @ (v + np.cross(omega, law.point))
        elif isinstance(law, pq.Torque):
            n = law.index
            tau = law.torque(t, q, s_dot)
            power += (kin.R[n].T @ tau if law.frame == "world" else tau) @ kin.twist[n][3:]
        elif isinstance(law, pq.JointSpring):
            s_n = system.joint_s_dot_getter(law.index)(s_dot)
            power -= law.damping * s_n @ s_n
        elif isinstance(law, pq.JointForce):
            power += law.generalized_force(t, q, s_dot) @ system.joint_s_dot_getter(law.index)(s_dot)
        elif isinstance(law, pq.SpringDamper):
            ends = []
            for n, point in zip(law.index, law.points):
                if n < 0:
                    ends.append((point, np.zeros(3)))
                else:
                    v, omega = kin.twist[n][:3], kin.twist[n][3:]
                    ends.append((kin.r[n] + kin.R[n] @ point, kin.R[n] @ (v + np.cross(omega, point))))
            d = ends[1][0] - ends[0][0]
            length_rate = d @ (ends[1][1] - ends[0][1]) / np.linalg.norm(d)
            power -= law.damping * length_rate**2
        else:
            pytest.fail(f"no power formula for {law!r}")
    return power


def _power_balance(tree):
    """(d(T + V)/dt by central differences, ṡᵀ Q_nc, tolerance).

    The central difference of step h = 1e-6 along (q̇, s̈, 1) (q renormalised: that moves a
    unit quaternion by O(h²) on both sides alike, which cancels) has two errors:

    - truncation h²/6 |E‴|, with E‴ ~ Ω² P for the fastest rate Ω ≲ 1e2 s⁻¹ of these
      systems (1e-2 kg bodies on stiff springs) and P ~ P_ref = Σ_k |ṡ_k| (|(M s̈)_k| + |b_k|),
      the size of the individual powers that cancel in the balance: ≲ 2e-9 P_ref;
    - round-off of E = T + V, a few ε (|T| + |V|), divided by 2h.

    Tolerance 2e-8 P_ref + 12 ε (|T| + |V|)/h: over 1000 examples of the "thorough" profile
    (test_power_balance_with_nonconservative_loads) the error stayed at ≤ 1/11 of it (was
    1e-7 P_ref + 50 ε (|T| + |V|)/h, 46× the largest error),
    and a missing or wrong load term (an error of order P_ref) fails by orders of magnitude.
    """
    system, q, s_dot, t = tree.system, tree.q, tree.s_dot, tree.t
    s_ddot = system.accelerations(q, s_dot, t)
    q_dot = system.q_dot(q, s_dot, t)
    h = 1e-6

    def energy(tau):
        T, V = system.energy(system.normalized(q + tau * q_dot), s_dot + tau * s_ddot, t + tau)
        return T + V

    rate = (energy(h) - energy(-h)) / (2 * h)
    kin = forward(system, q, s_dot, t)
    power = _nonconservative_power(system, kin, q, s_dot, t)
    M, b = system.gauss_form(q, s_dot, t)
    P_ref = np.abs(s_dot) @ (np.abs(M @ s_ddot) + np.abs(b)) if system.n_s else 0.0
    T, V = system.energy(q, s_dot, t)
    tol = 2e-8 * P_ref + 12 * np.finfo(float).eps * (abs(T) + abs(V)) / h
    return rate, power, tol


@given(_scleronomic_trees(max_n=10, forces="conservative"))
def test_energy_is_conserved_without_dissipation(tree):
    """d(T + V)/dt = 0 along the motion: gravity, undamped joint springs and spring-dampers,
    scleronomic joints (holonomic and not — the car joint does no work)."""
    rate, power, tol = _power_balance(tree)
    assert power == 0.0
    assert abs(rate) <= tol, f"d(T + V)/dt = {rate:.3g}, tolerance {tol:.3g}"


@given(_scleronomic_trees(max_n=10, forces=True))
def test_power_balance_with_nonconservative_loads(tree):
    """d(T + V)/dt = ṡᵀ Q_nc: the power of body forces and torques, joint forces and the
    dampers (``_nonconservative_power``) is the rate of the mechanical energy."""
    rate, power, tol = _power_balance(tree)
    assert abs(rate - power) <= tol, (
        f"d(T + V)/dt = {rate:.6g} but the loads deliver {power:.6g} (tol {tol:.3g})"
    )


# -- evaluator reuse ------------------------------------------------------------------------
@pytest.mark.parametrize("method", ["recursive", "dense"])
@given(tree=any_plane.flatmap(lambda planar: trees(max_n=12, planar=planar)))
def test_same_inputs_twice_give_bit_identical_results(method, tree):
    """The cached evaluator overwrites its workspace: calling it twice with the same
    (q, ṡ, t) returns the same bits."""
    system = tree.system
    first = system.accelerations(tree.q, tree.s_dot, tree.t, method=method)
    second = system.accelerations(tree.q, tree.s_dot, tree.t, method=method)
    assert np.array_equal(first, second)


@pytest.mark.parametrize("method", ["recursive", "dense"])
@given(tree=any_plane.flatmap(lambda planar: trees(max_n=12, planar=planar)))
def test_alternating_states_equal_a_fresh_evaluator(method, tree):
    """Alternating two states A, B, A, B on one evaluator: every answer is bit-identical to
    that of a fresh evaluator (nothing of the previous call leaks into the next)."""
    system = tree.system
    state_a = (tree.q, tree.s_dot, tree.t)
    state_b = random_state(system, tree.rng)
    used = system.evaluator(method)
    for state in (state_a, state_b, state_a, state_b):
        fresh = EVALUATORS[method](system).accelerations(*state)
        assert np.array_equal(used.accelerations(*state), fresh)


# -- planar chain = spatial chain -----------------------------------------------------------
@pytest.mark.parametrize("seed", range(3), ids=lambda s: f"state{s}")
@pytest.mark.parametrize("n", [1, 2, 5, 12], ids=lambda n: f"{n}-links")
def test_planar_chain_equals_spatial_chain(n, seed):
    """``scenes.chain(n, planar=True)`` (PlanarBody in the z–x plane) and ``planar=False``
    (RigidBody) have the same M, energies and s̈ (both evaluators) at random states, to
    1e-12 relative: the same physics by different arithmetic; κ(M) ≤ 3e3 for n ≤ 12, so
    round-off stays below 2e-13."""
    planar, spatial = pq.scenes.chain(n, planar=True), pq.scenes.chain(n, planar=False)
    rng = np.random.default_rng(seed)
    q, s_dot = rng.uniform(-np.pi, np.pi, n), rng.uniform(-2, 2, n)
    M_p, M_s = planar.mass_matrix(q), spatial.mass_matrix(q)
    assert np.abs(M_p - M_s).max() <= 1e-12 * np.abs(M_s).max()
    assert planar.energy(q, s_dot) == pytest.approx(spatial.energy(q, s_dot), rel=1e-12)
    for method in ("recursive", "dense"):
        a, b = planar.accelerations(q, s_dot, method=method), spatial.accelerations(q, s_dot, method=method)
        assert np.abs(a - b).max() <= 1e-12 * max(1.0, np.abs(b).max()), method


@given(any_plane.flatmap(lambda planar: trees(max_n=10, planar=planar, forces=False)))
def test_q_dot_is_K_s_dot(tree):
    """System.q_dot (q̇ = ṡ in one step for the identity joints, joint by joint elsewhere)
    equals the block-diagonal K(q) ṡ assembled joint by joint (docs/theory.md §3), to round-off."""
    system, q, s_dot, t = tree.system, tree.q, tree.s_dot, tree.t
    expected = system.K(q, t) @ s_dot
    np.testing.assert_allclose(system.q_dot(q, s_dot, t), expected, rtol=0, atol=1e-14 * np.max(np.abs(expected), initial=1.0))

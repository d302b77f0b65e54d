"""Rank and mobility along a run (Result.rank, Result.mobility): the numerical rank of the
constraint matrix and the degrees of freedom at each output time, checked on the IFToMM problems
whose rank is known in closed form (M. González, D. Dopico, U. Lugrís, J. Cuadrado, "A
benchmarking system for MBS simulation software", Multibody System Dynamics 16 (2006) 179–190):
Bricard's mechanism (A04: five closure rows of rank 4 everywhere, mobility 1 — Bricard, "Mémoire
sur la théorie de l'octaèdre articulé", 1897) and the double four-bar (A02, N = 2: four rows of
rank 4, mobility 1, except where the bars lie horizontal, rank 2 and mobility 3).
"""

import io

import numpy as np
import pytest
from scipy.optimize import brentq

import projeq as pq
from projeq.analysis.differentiation import richardson
from projeq.constraints.tangent import ratio_rate
from projeq.scenes.iftomm import bricard, n_four_bar, parallelogram_motion


def test_bricard_keeps_rank_4_of_5_rows_and_mobility_1_along_the_run():
    """Over 0.4 s of Bricard's motion the five closure rows have rank 4 and the mechanism one degree
    of freedom at every output time (Grübler's count, 5 − 5 = 0, would say none)."""
    system = bricard()
    r = pq.simulate(system, 0.4, n_points=9, rtol=1e-8, atol=1e-10)
    assert system.n_c == 5 and r.rank.shape == r.mobility.shape == r.t.shape
    assert np.all(r.rank == 4) and np.all(r.mobility == 1)
    assert np.ptp(r.q[:, 0]) > 0.01  # it moved


@pytest.fixture(scope="module")
def through_the_first_singular_position():
    """The double four-bar over 0.8 s, which passes the horizontal once (θ0 from π/2 through 0 at
    0.714 s), with an output at the time of the singular position the run's own event found."""
    system = n_four_bar(2)
    first = pq.simulate(system, 0.8, n_points=2, rtol=1e-9, atol=1e-11, events=[system.singular_positions()])
    (t_singular,) = first.t_events[0]
    t_eval = np.union1d(np.linspace(0.0, 0.8, 17), [t_singular])
    return system, t_singular, pq.simulate(system, 0.8, t_eval=t_eval, rtol=1e-9, atol=1e-11)


def test_the_double_four_bar_drops_to_rank_2_only_at_its_singular_position(through_the_first_singular_position):
    """The rank history is 4 (mobility 1) at every output but the one at the singular position,
    where it is 2 (mobility 3, the benchmark's N + 1); that time is where the parallelogram
    motion (one coordinate, no constraint equations) has its cranks horizontal, to 1e-6 s."""
    system, t_singular, r = through_the_first_singular_position
    at = r.t == t_singular
    assert np.count_nonzero(at) == 1
    assert np.all(r.rank[~at] == 4) and np.all(r.mobility[~at] == 1)
    assert r.rank[at][0] == 2 and r.mobility[at][0] == 3
    horizontal = brentq(lambda t: parallelogram_motion([0.0, t], 2)[-1, 1], 0.1, 1.0, xtol=1e-12)
    assert abs(t_singular - horizontal) < 3e-9  # measured 2.4e-10 (the event's root against brentq's)


def test_the_rank_history_is_saved_and_files_without_it_still_load(through_the_first_singular_position):
    """Result.save keeps rank and mobility (NPZ arrays); a file written before they were recorded
    (no such arrays) loads with them empty."""
    _, _, r = through_the_first_singular_position
    buffer = io.BytesIO()
    r.save(buffer)
    buffer.seek(0)
    loaded = pq.Result.load(buffer)
    assert np.array_equal(loaded.rank, r.rank) and np.array_equal(loaded.mobility, r.mobility)
    buffer.seek(0)
    with np.load(buffer) as data:
        older = {name: data[name] for name in data.files if name not in ("rank", "mobility")}
    buffer = io.BytesIO()
    np.savez(buffer, **older)
    buffer.seek(0)
    loaded = pq.Result.load(buffer)
    assert loaded.rank.size == loaded.mobility.size == 0 and np.array_equal(loaded.q, r.q)


def test_a_tree_without_constraint_equations_has_no_rank_history():
    r = pq.simulate(pq.scenes.chain(2), 0.1, n_points=3)
    assert r.rank.size == r.mobility.size == 0


def test_ratio_rate_of_a_rotated_diagonal_matrix():
    """A(t) = R(ωt) diag(3, 2 − t, 1 + t²) R(−2ωt)ᵀ (rotations about z and x keep the singular
    values): ρ = σ₃/σ₁ = (1 + t²)/3 while 1 + t² < 2 − t, so dρ/dt = 2t/3 in closed form, and the
    formula σ̇_i = u_iᵀ Ȧ v_i gives it to round-off whatever the rotations."""
    omega, t = 0.7, 0.3

    def R(angle, axis):
        c, s = np.cos(angle), np.sin(angle)
        i, j = [k for k in range(3) if k != axis]
        out = np.eye(3, dtype=complex)
        out[[i, i, j, j], [i, j, i, j]] = c, -s, s, c
        return out

    def A(t):
        return R(omega * t, 2) @ np.diag([3.0, 2.0 - t, 1.0 + t * t]) @ R(-2 * omega * t, 0).T

    A_dot = np.imag(A(t + 1e-30j)) / 1e-30  # the complex step: Ȧ exact
    assert ratio_rate(A(t).real, A_dot, 3) == pytest.approx(2 * t / 3, rel=1e-14, abs=0)  # measured 7e-16


def test_the_singular_position_event_is_the_exact_rate_of_the_ratio():
    """The event of the double four-bar (A02, N = 2) on its way to the singular position: dρ/dt
    (Ȧ_s by the complex step) against Richardson's difference of ρ(q + ε q̇, t + ε) (h = 1e-4,
    truncation ~1e-13): to 1e-10."""
    system = n_four_bar(2)
    event, acting = system.singular_positions(), system.tree.n_s - system.n_s

    def ratio(q, t):
        sigma = np.linalg.svd(system.constraint_matrix(q, t)[0], compute_uv=False)
        return sigma[acting - 1] / sigma[0]

    r = pq.simulate(system, 0.7, n_points=8, rtol=1e-9, atol=1e-11)
    for q, s_dot, t in zip(r.q[1:], r.s_dot[1:], r.t[1:]):
        q_dot = system.q_dot(q, s_dot, t)
        expected = richardson(lambda e: ratio(q + e * q_dot, t + e), 1e-4)
        assert event(t, q, s_dot) == pytest.approx(expected, rel=1e-10)

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
    assert abs(t_singular - horizontal) < 1e-6


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

"""The peer comparisons of benchmarks/peers.py (projeq.studies.bench_peers) compute the same
accelerations as projeq before they time anything: tiny versions, each skipped when its peer
is not installed (the CI installs only projeq[test])."""

import numpy as np
import pytest

from projeq.studies import bench_peers


@pytest.mark.parametrize("peer, module", [("pinocchio", "pinocchio"), ("mujoco", "mujoco"), ("mujoco_smooth", "mujoco")])
def test_chain_peers_compute_projeqs_accelerations(peer, module):
    """s̈ of scenes.chain(4) at a random state by Pinocchio's ABA (Featherstone 2008, ch. 7),
    MuJoCo's mj_forward and MuJoCo's smooth dynamics alone: the same chain as projeq's default
    evaluator to round-off (all are exact recursions of the same equations; the bound
    SAME_S_DDOT is κ(M) ε for MuJoCo's factorisation, a few ε per link for ABA)."""
    pytest.importorskip(module)
    q, s_dot = np.random.default_rng(3).uniform(-1, 1, (2, 4))
    funcs = bench_peers.chain_peers(4)
    s_ddot = {name: funcs[name](q, s_dot) for name in ("projeq", peer)}
    deviation = bench_peers.checked(s_ddot, "projeq")[peer]
    assert deviation < 1e-12
    assert np.abs(s_ddot["projeq"]).max() > 1.0  # a state that moves: the comparison is not of zeros


def test_the_check_refuses_a_peer_that_computes_something_else():
    """The check before the timing fails, naming the peer, when its s̈ is not projeq's: Pinocchio's
    chain(4) at a state 0.1 rad away from projeq's."""
    pytest.importorskip("pinocchio")
    q, s_dot = np.random.default_rng(3).uniform(-1, 1, (2, 4))
    funcs = bench_peers.chain_peers(4)
    with pytest.raises(AssertionError, match="pinocchio: s̈ differs from projeq's"):
        bench_peers.checked({"projeq": funcs["projeq"](q, s_dot), "pinocchio": funcs["pinocchio"](q + 0.1, s_dot)}, "projeq")


def test_rolling_disk_equals_sympys_kanes_method_disc():
    """projeq's uniform rolling disk (scenes.rolling_disk with m_ecc = 0) and the rolling disc
    of sympy.physics.mechanics' documentation (KanesMethod, lean-frame speeds), lambdified:
    the angular acceleration in the disk frame, projeq's s̈, agrees to round-off at a
    generic state (tilted, turning, rolling) — a second, independent derivation."""
    row = bench_peers.rolling_disk_row(budget=0.0, q=(0.7, -0.3, 1.1, 0.2, -0.1), s_dot=(1.5, 12.0, -2.0))
    assert row["deviation"]["sympy"] < 1e-12
    assert row["seconds"]["projeq"] > 0 and row["seconds"]["sympy"] > 0

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
    SAME_S_DDOT is κ(M) ε for MuJoCo's factorisation, a few ε per link for ABA). Measured 6.4e-16
    (Pinocchio) and 4.4e-15 (MuJoCo, both): the bound is 4.4e-14 (was 1e-12)."""
    pytest.importorskip(module)
    q, s_dot = np.random.default_rng(3).uniform(-1, 1, (2, 4))
    funcs = bench_peers.chain_peers(4)
    s_ddot = {name: funcs[name](q, s_dot) for name in ("projeq", peer)}
    deviation = bench_peers.checked(s_ddot, "projeq")[peer]
    assert deviation < 4.4e-14
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
    assert row["deviation"]["sympy"] < 100 * np.finfo(float).eps  # measured 2.1e-16 (was 1e-12)
    assert row["seconds"]["projeq"] > 0 and row["seconds"]["sympy"] > 0


def test_spin_up_tip_equals_exudyns_ancf_cable():
    """The first 2 s of the spin-up beam (Ωs = 4 rad/s): projeq's in-plane tip deflection and
    Exudyn's nonlinear ANCF cable (8 elements, generalized-α, h = 2e-3 s; Gerstmayr's
    absolute nodal coordinates, a second, independent formulation) agree within 1e-5 m. The
    models differ by geometric terms cubic in the deflection (exact curvature, extension):
    2.9e-4 m at the 0.47 m of the full 20 s run (benchmarks/exudyn_spin_up.py), so about
    (0.07/0.47)³ · 2.9e-4 ≈ 1e-6 m at the 0.07 m reached here (measured 1.7e-6 m, with
    Exudyn's coarser mesh)."""
    pytest.importorskip("exudyn")
    times = (1.0, 2.0)
    exudyn_tip, _ = bench_peers.exudyn_tip_deflection(4.0, times, n_elements=8, h=2e-3)
    tip, _, _ = bench_peers.projeq_tip_deflection(4.0, times, method="Radau", rtol=1e-7, atol=1e-9)
    assert np.abs(tip).max() > 0.05  # the beam has deflected
    assert np.abs(tip - exudyn_tip).max() < 1e-5


def test_bench_offers_the_peer_comparison(capsys):
    from projeq.cli.commands import main

    assert main(["bench", "--help"]) == 0
    assert "--peers" in capsys.readouterr().out

"""Parameter sweeps (projeq.sweep, module projeq.simulation.sweep): same numbers on every executor, physics, failures, Ctrl-C."""

import concurrent.futures as cf
import sys
import time
import types

import numpy as np
import pytest

from projeq.simulation.sweep import sweep

sweep_module = sys.modules["projeq.simulation.sweep"]

G = 9.81
T_END = 0.5
M1 = [1.0, 1.5, 3.0]


def atwood_angle(m1, m2=1.0, pulley_mass=0.5, a=0.1, t=T_END):
    """Pulley angle of the scene ``atwood`` released from rest: mass 1 sinks with
    ẍ = (m1 − m2) g / (m1 + m2 + I/a²) (Problem 1, eq. (4) of
    ../shared/seeds/003_13b1ca6faae9f37e.txt), I = ½ M a², and θ = −x/a (the scene's docstring)."""
    x_ddot = (m1 - m2) * G / (m1 + m2 + 0.5 * pulley_mass)
    return -0.5 * x_ddot * t**2 / a


def atwood_sweep(executor):
    return sweep("atwood", grid={"m1": M1}, outputs=["q0", "energy_drift"], executor=executor, t_end=T_END,
                 progress=False, rtol=1e-10, atol=1e-12)


@pytest.fixture(scope="module")
def on_processes():
    with cf.ProcessPoolExecutor(2) as pool:
        return atwood_sweep(pool)


def test_sweep_matches_the_closed_form(on_processes):
    """Constant acceleration: the integrator at rtol 1e-10 reproduces θ(t) = −½ ẍ t²/a to
    ~1e-10 relative; 1e-8 leaves a margin of 100 over the requested tolerance."""
    assert on_processes["m1"].tolist() == M1 and on_processes["status"].tolist() == [0, 0, 0]
    assert np.allclose(on_processes["q0"], [atwood_angle(m) for m in M1], rtol=1e-8, atol=1e-12)
    # a conservative system: energy drift at the level of the requested tolerance
    assert on_processes["energy_drift"].max() < 1e-8


def test_dask_local_cluster_gives_the_same_numbers(on_processes):
    """A dask.distributed LocalCluster of 2 thread workers (processes=False: spawning worker
    processes costs seconds here) runs the same deterministic simulations: equal bits."""
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, processes=False, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            on_dask = atwood_sweep(client)
    for column in ("q0", "energy_drift", "status"):
        assert np.array_equal(on_dask[column], on_processes[column])


def test_failed_points_are_reported_not_dropped():
    """n = 0 links is rejected by the scene: that row says so, the other row is computed."""
    table = sweep("chain", grid={"n": [0, 1]}, outputs=["q0"], executor=cf.ThreadPoolExecutor(2),
                  t_end=0.1, progress=False)
    assert table["status"].tolist() == [-1, 0]
    assert np.isnan(table["q0"][0]) and np.isfinite(table["q0"][1])
    assert table["error"][0].startswith("ValueError: n:") and table["error"][1] == ""


def test_samples_and_saved_table(tmp_path):
    """Explicit samples keep their order; CSV and NPZ hold the same numbers as the table."""
    table = sweep("double_pendulum", samples=[{"m1": 2.0, "l2": 0.5}, {"m1": 1.0, "l2": 1.0}], outputs=["q1"],
                  executor=cf.ThreadPoolExecutor(2), t_end=0.1, progress=False)
    csv, npz = table.save(tmp_path / "study")
    rows = np.genfromtxt(csv, delimiter=",", names=True, usecols=(0, 1, 2, 3))
    assert rows["m1"].tolist() == [2.0, 1.0]
    assert np.array_equal(rows["q1"], table["q1"])  # repr of floats round-trips exactly
    assert np.array_equal(np.load(npz)["q1"], table["q1"])


def test_ctrl_c_keeps_the_running_point_and_cancels_the_others(monkeypatch):
    """A KeyboardInterrupt while the first of three points runs on a one-thread pool: the
    running point is waited for and kept, the two not started are marked interrupted."""

    def interrupted(futures):  # sweep's wait for the next finished point
        first = next(iter(futures))
        while not (first.running() or first.done()):
            time.sleep(1e-3)
        raise KeyboardInterrupt

    monkeypatch.setattr(sweep_module, "_finished", interrupted)
    with cf.ThreadPoolExecutor(1) as pool:
        table = sweep("chain", grid={"n": [1, 2, 3]}, outputs=["q0"], executor=pool, t_end=0.05, progress=False)
    assert table["status"].tolist() == [0, -1, -1] and table["error"] == ["", "interrupted", "interrupted"]
    assert np.isfinite(table["q0"][0])


def test_outputs_of_a_run_without_a_completed_step_are_nan():
    """A run interrupted in its first segment has no time points: its outputs are NaN."""
    empty = types.SimpleNamespace(t=np.empty(0), q=np.empty((0, 1)))
    assert np.isnan(sweep_module.output_value(empty, "q0")) and np.isnan(sweep_module.output_value(empty, "t_reached"))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"grid": {"m1": [1.0]}, "samples": [{"m1": 1.0}]}, "grid, samples"),
        ({}, "grid, samples"),
        ({"grid": {"mass": [1.0]}}, "mass: unknown parameter"),
        ({"grid": {"m1": [1.0]}, "outputs": ["speed"]}, "outputs: unknown output"),
        ({"grid": {"m1": [1.0]}, "executor": "local"}, "executor:"),
        ({"samples": {"m1": [1.0, 2.0], "m2": [1.0]}}, "samples: all columns"),
    ],
    ids=["both", "neither", "parameter", "output", "executor", "ragged-samples"],
)
def test_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        sweep("atwood", **kwargs)


def test_unknown_scene_suggests_the_closest():
    with pytest.raises(ValueError, match="did you mean 'atwood'"):
        sweep("atwod", grid={"m1": [1.0]})


def test_a_closed_dask_client_is_refused_before_any_work():
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, processes=False, dashboard_address=None) as cluster:
        client = distributed.Client(cluster)
        client.close()
        with pytest.raises(ValueError, match="executor: the Dask client is not connected"):
            sweep("atwood", grid={"m1": [1.0]}, executor=client)

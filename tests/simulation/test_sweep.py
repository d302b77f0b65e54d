"""Parameter sweeps (projeq.sweep, module projeq.simulation.sweep): same numbers on every executor, physics, failures, Ctrl-C."""

import concurrent.futures as cf
import errno
import os
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
    the Lagrange seminars), I = ½ M a², and θ = −x/a (the scene's docstring)."""
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
    """Constant acceleration: θ(t) = −½ ẍ t²/a is a quadratic, which the Runge–Kutta steps reproduce
    exactly: round-off only, 100 ε (measured 9.2e-16 relative and an energy drift of 2.8e-16; were
    1e-8 + 1e-12 and 1e-8)."""
    assert on_processes["m1"].tolist() == M1 and on_processes["status"].tolist() == [0, 0, 0]
    exact = [atwood_angle(m) for m in M1]
    assert np.allclose(on_processes["q0"], exact, rtol=100 * np.finfo(float).eps, atol=0)
    # a conservative system: energy drift at round-off
    assert on_processes["energy_drift"].max() < 100 * np.finfo(float).eps


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


def test_points_are_appended_as_they_finish_and_resume_runs_only_the_rest(tmp_path, monkeypatch):
    """With path, each finished point is in path.csv before the sweep returns (checked while
    the third point runs); the final CSV (input order) and NPZ agree. resume=True on a table
    missing one point and holding a failed one runs exactly those two and keeps the others
    bit for bit."""
    seen = []
    real_run_point = sweep_module.run_point

    def watching(scene, parameters, *args):
        if parameters["n"] == 3:  # the two before it have finished (one thread): the main thread appends them
            deadline = time.monotonic() + 5.0
            while len(sweep_module.SweepTable.load(tmp_path / "chains")["n"]) < 2 and time.monotonic() < deadline:
                time.sleep(0.01)
            seen.append(sweep_module.SweepTable.load(tmp_path / "chains")["n"].tolist())
        return real_run_point(scene, parameters, *args)

    monkeypatch.setattr(sweep_module, "run_point", watching)
    grid = {"n": [1, 2, 3]}
    with cf.ThreadPoolExecutor(1) as pool:
        table = sweep("chain", grid=grid, outputs=["q0", "wall_time"], executor=pool, t_end=0.05, progress=False,
                      path=tmp_path / "chains")
    assert seen == [[1, 2]]
    saved = np.load(tmp_path / "chains.npz", allow_pickle=True)
    for name in ("n", "q0", "wall_time", "status"):
        assert np.array_equal(sweep_module.SweepTable.load(tmp_path / "chains.csv")[name], saved[name])

    lines = (tmp_path / "chains.csv").read_text().splitlines()
    failed = lines[2].split(",")[:-2] + ["-1", "ValueError: on purpose"]
    (tmp_path / "chains.csv").write_text("\n".join([lines[0], lines[1], ",".join(failed)]) + "\n")  # n = 3 lost
    ran = []
    monkeypatch.setattr(sweep_module, "run_point", lambda scene, p, *args: ran.append(p["n"]) or real_run_point(scene, p, *args))
    with cf.ThreadPoolExecutor(1) as pool:
        resumed = sweep("chain", grid=grid, outputs=["q0", "wall_time"], executor=pool, t_end=0.05, progress=False,
                        path=tmp_path / "chains", resume=True)
    assert sorted(ran) == [2, 3] and resumed["status"].tolist() == [0, 0, 0]
    assert resumed["wall_time"][0] == table["wall_time"][0]  # kept, not run again
    assert np.array_equal(resumed["q0"], table["q0"])  # the same deterministic runs


def test_a_cut_off_last_line_is_left_out_and_a_foreign_file_is_named(tmp_path):
    """A process killed while appending leaves a line without its newline: the loader reads
    the whole lines; a file that is not a sweep table is refused by name."""
    (tmp_path / "t.csv").write_text("m1,q0,status,error\n1.0,-2.5,0,\n2.0,-3")
    assert sweep_module.SweepTable.load(tmp_path / "t")["m1"].tolist() == [1.0]
    (tmp_path / "u.csv").write_text("t,q0\n0,1\n")
    with pytest.raises(ValueError, match="u.csv' is not a sweep table"):
        sweep_module.SweepTable.load(tmp_path / "u.csv")


def test_an_append_that_fails_is_undone(tmp_path, monkeypatch):
    """A full disk during an append: the partial line is cut off again (the file keeps whole
    rows), a warning says the points stay in memory, later appends are skipped."""
    log = sweep_module._Log(tmp_path / "t.csv", ["m1", "status", "error"], [[1.0, 0, ""]])
    real_write = os.write

    def half_then_full(fd, data):
        real_write(fd, data[: len(data) // 2])
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "write", half_then_full)
    with pytest.warns(RuntimeWarning, match="cannot append to .*No space left on device"):
        log.append([2.0, 0, ""])
    log.append([3.0, 0, ""])
    assert (tmp_path / "t.csv").read_text() == "m1,status,error\n1.0,0,\n"


def test_a_scene_that_cannot_reach_the_workers_is_refused_before_any_work():
    """A build function defined inside a function cannot be pickled for a worker process."""
    from projeq.scenes import Scene, build_scene

    local = Scene(lambda n=1: build_scene("chain", n=n), "a chain built by a lambda", 0.1)
    with pytest.raises(ValueError, match="scene: cannot be sent to worker processes"):
        sweep(local, grid={"n": [1]}, workers=1)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"grid": {"m1": []}}, "grid: m1 has no values"),
        ({"samples": []}, "samples: expected at least one point"),
        ({"grid": {"m1": [1.0]}, "resume": True}, "resume: needs path"),
        ({"grid": {"m1": [1.0]}, "workers": 0}, "workers: expected a positive number"),
        ({"grid": {"m1": [1.0]}, "workers": 2, "executor": cf.ThreadPoolExecutor(1)}, "workers: only for the default"),
    ],
    ids=["empty-axis", "no-samples", "resume-without-path", "workers", "workers-and-executor"],
)
def test_more_bad_input(kwargs, match):
    with pytest.raises(ValueError, match=match):
        sweep("atwood", **kwargs)


def test_a_point_interrupted_before_its_integration_started_is_status_2():
    """Ctrl-C on a worker while it builds the scene or simulate checks and chooses (before the run's
    segments, which turn it into a partial result): the point is interrupted (status 2, no outputs),
    as one stopped mid-run; before, the KeyboardInterrupt escaped and the point was marked not run."""
    from projeq.scenes import SCENES

    class Interrupted:
        def build(self, **parameters):
            raise KeyboardInterrupt

    status, values, message = sweep_module.run_point(Interrupted(), {}, ["q0"], 1.0, {})
    assert status == 2 and np.isnan(values).all() and message == "interrupted before its integration started"
    assert sweep_module.run_point(SCENES["atwood"], {}, ["q0"], 0.01, {})[0] == 0

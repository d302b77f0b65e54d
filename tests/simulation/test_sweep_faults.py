"""Sweeps that never hang or mislead (issue 37, item 6): a user's scene reaches Dask workers, or
the sweep fails within 30 s naming the module they cannot import; resume refuses a table made
with other settings; a lost scheduler fails the points it held, with the reason, and the table is
kept; bad options and outputs are refused before the first point runs."""

import concurrent.futures as cf
import sys
import threading

import numpy as np
import pytest

from projeq.scenes import resolve_scene
from projeq.simulation.sweep import SweepTable, sweep

sweep_module = sys.modules["projeq.simulation.sweep"]


class LostScheduler(cf.Executor):
    """An executor whose scheduler is lost after ``served`` tasks: it runs those at once, the
    next one's future is cancelled (as a Dask client cancels its futures when it loses the
    scheduler) and it refuses any further task."""

    def __init__(self, served: int):
        self.served, self.submitted = served, 0

    def submit(self, fn, /, *args, **kwargs):
        self.submitted += 1
        if self.submitted > self.served + 1:
            raise RuntimeError("the client is closed: its scheduler is gone")
        future = cf.Future()
        if self.submitted <= self.served:
            future.set_result(fn(*args, **kwargs))
        else:  # cancelled as an executor does: waiters are told
            future.cancel()
            future.set_running_or_notify_cancel()
        return future


def test_a_lost_scheduler_fails_the_points_it_held_and_keeps_the_table(tmp_path):
    """Passes if, the scheduler lost after the first of four points, the sweep returns (before:
    concurrent.futures.CancelledError out of sweep, the running points unrecorded) with the first
    point computed, the cancelled one and the two refused ones status −1 with the reason, and the
    table written."""
    table = sweep("atwood", grid={"m1": [1.0, 1.5, 2.0, 2.5]}, outputs=["q0"], executor=LostScheduler(1),
                  t_end=0.05, progress=False, path=tmp_path / "lost")
    assert table["status"].tolist() == [0, -1, -1, -1] and np.isfinite(table["q0"][0])
    assert table["error"][1].startswith("cancelled by the executor while it ran or waited (a Dask scheduler lost?)")
    assert table["error"][2] == table["error"][3] == ("not run: the executor refused it (RuntimeError: the client is "
                                                      "closed: its scheduler is gone)")
    assert SweepTable.load(tmp_path / "lost")["status"].tolist() == [0, -1, -1, -1]


def test_resume_refuses_a_table_made_with_other_settings(tmp_path):
    """Passes if resume=True over a table made with another t_end or rtol (before: its values kept
    as the answer) or without the record of its settings is a ValueError naming what differs, and
    the same settings resume (nothing runs again)."""
    def run(**options):
        return sweep("atwood", grid={"m1": [1.0, 2.0]}, outputs=["q0"], executor=cf.ThreadPoolExecutor(1),
                     progress=False, path=tmp_path / "table", resume=True, **options)

    first = run(t_end=0.05, rtol=1e-9)
    with pytest.raises(ValueError, match=r"^resume: .*table.csv' was made with other settings \(t_end 0.05 there, "
                                         r"0.1 now\)"):
        run(t_end=0.1, rtol=1e-9)
    with pytest.raises(ValueError, match=r"\(options\['rtol'\] 1e-09 there, 1e-08 now\)"):
        run(t_end=0.05, rtol=1e-8)
    again = run(t_end=0.05, rtol=1e-9)
    assert np.array_equal(again["q0"], first["q0"])
    (tmp_path / "table.json").unlink()
    with pytest.raises(ValueError, match=r"^resume: .*table.csv' has no readable record of the scene, end time and "
                                         r"options it was made with"):
        run(t_end=0.05, rtol=1e-9)


@pytest.mark.parametrize("grid, options, words", [
    ({"m1": [1.0, 2.0]}, {"rtol": -1.0}, r"^rtol: must be positive, got -1.0"),
    ({"m1": [1.0, 2.0]}, {"evaluator": "fastest"}, r"^evaluator: unknown evaluator 'fastest'"),
    ({"m1": [1.0, 2.0]}, {"outputs": ["q99"]}, r"^outputs: 'q99' asks for q\[99\], but the models of the first and "
                                               r"last points have 1 and 1 entries \(q0 … q0\)"),
    ({"m1": [-1.0, 0.0]}, {}, r"^grid: neither the first nor the last point can be built \(\{'m1': -1.0\}: "
                              r"ValueError: m1: must be positive"),
], ids=["rtol", "evaluator", "q99", "no-point-builds"])
def test_options_and_outputs_are_checked_before_the_first_point_runs(grid, options, words):
    """Passes if each is a ValueError naming the option before any point runs (before: every point
    ran and failed alike)."""
    ran = []

    class Counting(cf.ThreadPoolExecutor):
        def submit(self, *args, **kwargs):
            ran.append(args)
            return super().submit(*args, **kwargs)

    with pytest.raises(ValueError, match=words):
        sweep("atwood", grid=grid, executor=Counting(1), t_end=0.05, progress=False, **options)
    assert ran == []


USER_SCENE = '''
import projeq as pq
{imports}

def build(m: float = 1.0):
    """A pendulum of the user's own file."""
    return pq.System({{"bob": pq.PointMass(m, (0.0, 0.0, -{length}))}}, {{"bob": pq.Revolute(axis="y")}},
                     gravity=(0.0, 0.0, -9.81), q0=[0.3])
'''


@pytest.fixture(scope="module")
def dask_processes():
    """A Dask LocalCluster of one worker process (spawned: it imports nothing of this process's
    modules) and its client, shared by this module's tests (~3 s to start)."""
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            yield client


def _in_time(call, seconds: float):
    """call() in a daemon thread, its result within ``seconds`` or a test failure (not a hang)."""
    outcome = []
    thread = threading.Thread(target=lambda: outcome.append(_caught(call)), daemon=True)
    thread.start()
    thread.join(seconds)
    if not outcome:
        pytest.fail(f"the sweep did not return within {seconds} s")
    value, exc = outcome[0]
    if exc is not None:
        raise exc
    return value


def _caught(call):
    try:
        return call(), None
    except BaseException as exc:  # noqa: BLE001 - raised again in the test's thread
        return None, exc


def test_a_users_scene_reaches_dask_workers(dask_processes, tmp_path):
    """Passes if a scene from the user's file (FILE.py:FUNCTION), which Dask workers cannot
    import, runs on them (sent by value) and gives the numbers of local threads (before: the
    workers failed to load the task and sweep never returned)."""
    (tmp_path / "my_scene.py").write_text(USER_SCENE.format(imports="", length="1.0"))
    scene = resolve_scene(f"{tmp_path / 'my_scene.py'}:build")
    grid = {"m": [1.0, 2.0]}
    on_dask = _in_time(lambda: sweep(scene, grid=grid, outputs=["q0"], executor=dask_processes, t_end=0.02,
                                     progress=False, evaluator="recursive"), 30)
    on_threads = sweep(scene, grid=grid, outputs=["q0"], executor=cf.ThreadPoolExecutor(1), t_end=0.02,
                       progress=False, evaluator="recursive")
    assert on_dask["status"].tolist() == [0, 0] and np.array_equal(on_dask["q0"], on_threads["q0"])


def test_a_module_the_workers_cannot_import_is_named(dask_processes, tmp_path, monkeypatch):
    """Passes if a user's scene importing a module of its own directory, importable here (on
    sys.path) but not on the workers, is a ValueError naming that module before any point runs,
    within 30 s."""
    (tmp_path / "helpers_of_mine.py").write_text("LENGTH = 1.0\n")
    (tmp_path / "uses_helpers.py").write_text(USER_SCENE.format(imports="import helpers_of_mine", length="helpers_of_mine.LENGTH"))
    monkeypatch.syspath_prepend(str(tmp_path))
    scene = resolve_scene(f"{tmp_path / 'uses_helpers.py'}:build")

    def refused():
        with pytest.raises(ValueError, match=r"^executor: the Dask workers cannot load the scene \(ModuleNotFoundError: "
                                             r"No module named 'helpers_of_mine'\)"):
            sweep(scene, grid={"m": [1.0, 2.0]}, executor=dask_processes, t_end=0.1, progress=False)

    _in_time(refused, 30)

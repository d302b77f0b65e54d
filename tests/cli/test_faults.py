"""Faults injected into ``projeq run`` and ``projeq sweep``: what is on disk afterwards.

SIGTERM to a running sweep or run, the main process killed outright, a worker process killed
(as the out-of-memory killer does), a failing point with a multi-line message, and a write
that fails (a full disk). Every test looks at the files left: each one complete and loadable
under its final name, or absent; and at the processes left: none.
"""

import errno
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import projeq as pq
from projeq.cli.commands import main
from projeq.scenes import SCENES, Scene, build_scene
from projeq.simulation.sweep import SweepTable


def faulty(k: int = 0, kill: int = -1, fail: int = -1, slow: int = -1):
    """A scene for fault injection: a one-link chain, except that point ``k == kill`` kills
    its own process (SIGKILL, as the out-of-memory killer does), ``k == fail`` raises an
    error whose message has a comma and two lines, and ``k == slow`` drives its link with a
    motor torque that takes 20 ms per call once the integration has left t = 0 (seconds per
    simulated second, whatever the evaluator's speed and the machine's load; the set-up's
    calls at t = 0, the integrator's choice among them, stay fast)."""
    if k == kill:
        os.kill(os.getpid(), signal.SIGKILL)
    if k == fail:
        raise ValueError("bad point, on purpose\nsecond line of the message")
    system = build_scene("chain", n=1)
    if k != slow:
        return system
    return pq.System(dict(zip(system.names, system.subsystems)), dict(zip(system.names, system.joints)),
                     gravity=system.gravity, forces=[pq.JointForce("link1", _sluggish_torque)], q0=system.q0)


def _sluggish_torque(t, q, s_dot):
    """No torque; after 20 ms for t > 0, the first time saying on stdout (the sweep's, which
    the pool's workers share) that the slow point is integrating."""
    global _integrating
    if t > 0:
        if not _integrating:
            _integrating = True
            print("slow point integrating", flush=True)
        time.sleep(0.02)
    return np.zeros(1)


_integrating = False  # in a worker: the slow point has said that it integrates


FAULTY = Scene(faulty, "a chain with injected faults", 0.05)

# The child process: the fault scene registered, Python's SIGINT handler (a shell may start
# background jobs with SIGINT ignored), and a line on stdout once there is something to keep.
_CHILD = """
import signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)
import projeq.simulation.driver, projeq.simulation.sweep
from projeq.cli.commands import main
from projeq.scenes import SCENES
from tests.cli.test_faults import FAULTY
SCENES["faulty"] = FAULTY
simulate, append = projeq.simulation.driver.simulate, projeq.simulation.sweep._Log.append

def reporting_simulate(system, t_end, progress=None, **options):  # projeq run passes a progress bar
    def report(t):
        progress(t)
        print("segment done", flush=True)
    return simulate(system, t_end, progress=progress and report, **options)

def reporting_append(log, row):  # a finished point appended to sweep_SCENE.csv
    append(log, row)
    print("point done", flush=True)

projeq.simulation.driver.simulate, projeq.simulation.sweep._Log.append = reporting_simulate, reporting_append
sys.exit(main(sys.argv[1:]))
"""
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def start(argv) -> subprocess.Popen:
    """``projeq argv`` in a child process, in its own process group (its workers join it)."""
    return subprocess.Popen([sys.executable, "-c", _CHILD, *argv], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, cwd=ROOT)


def signalled(argv, signum) -> tuple[int, str]:
    """Send ``signum`` to the child alone (as ``kill PID`` does) once it reports progress;
    its exit code and stderr."""
    child = start(argv)
    assert child.stdout.readline().endswith("done\n")
    os.kill(child.pid, signum)
    _, err = child.communicate(timeout=120)
    return child.returncode, err


def group_is_empty(pgid: int, timeout: float = 5.0) -> bool:
    """True once no process of the group ``pgid`` is left (waiting up to ``timeout`` s)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            os.killpg(pgid, 0)
        except ProcessLookupError:
            return True
        time.sleep(0.1)
    return False


def sweep_argv(tmp_path, grid, *extra):
    return ["sweep", "faulty", "--grid", grid, "--t-end", "1", "--outputs", "q0,wall_time", "--workers", "2",
            "--out", str(tmp_path), "--quiet", *extra]


def loaded(tmp_path) -> tuple[SweepTable, dict]:
    """The sweep table from its CSV (SweepTable.load) and from its NPZ (numpy alone), checked equal."""
    table, npz = SweepTable.load(tmp_path / "sweep_faulty"), np.load(tmp_path / "sweep_faulty.npz", allow_pickle=True)
    for name in ("k", "status", "q0", "wall_time"):
        assert np.array_equal(table[name], npz[name], equal_nan=name != "k" and name != "status")
    assert list(table["error"]) == list(npz["error"])
    return table, npz


def test_sigterm_to_a_sweep_keeps_the_finished_points_and_stops_the_workers(tmp_path):
    """SIGTERM to the main process only, once point 0 has finished while the slow point 1
    integrates: the running points are told (SIGINT) and return their partial results (status 2; a
    point told while it builds its model, before its integration, says so), the points not started are
    marked interrupted, the table is written complete (CSV and NPZ
    agree), exit 1 without a traceback, and no worker process is left."""
    child = start(sweep_argv(tmp_path, "k=0:5:6", "--set", "slow=1"))
    said = set()
    while len(said) < 2:  # point 0 finished, and point 1 inside its integration, in either order
        line = child.stdout.readline()
        assert line, f"the sweep ended before both lines: {said}, stderr: {child.communicate(timeout=120)[1][-2000:]}"
        said.add(line)
    assert said == {"point done\n", "slow point integrating\n"}
    os.kill(child.pid, signal.SIGTERM)
    _, err = child.communicate(timeout=120)
    assert child.returncode == 1 and "Traceback" not in err
    assert group_is_empty(child.pid)
    table, _ = loaded(tmp_path)
    assert table["k"].tolist() == [0, 1, 2, 3, 4, 5]
    assert table["status"][0] == 0 and np.isfinite(table["q0"][0])
    assert table["status"][1] == 2 and table["error"][1] == ""  # stopped, with its partial result (maybe no step)
    # finished, running (stopped in its integration, or told before it started it: a CI run met that), or not started
    for status, error in zip(table["status"][2:], table["error"][2:]):
        assert (status, error) in ((0, ""), (2, ""), (2, "interrupted before its integration started"),
                                   (-1, "interrupted"))


def test_a_killed_sweep_keeps_its_finished_points_and_resume_runs_the_rest(tmp_path, monkeypatch, capsys):
    """SIGKILL to the main process (a crash, nothing runs after it): every point finished
    before it is in sweep_faulty.csv, whole lines, loadable; the idle workers notice that
    their parent is gone and exit. ``--resume`` then runs only the other points: the kept
    rows come back bit for bit (their wall times would differ if they ran again)."""
    child = start(sweep_argv(tmp_path, "k=0:7:8"))
    assert child.stdout.readline() == "point done\n"
    os.kill(child.pid, signal.SIGKILL)
    child.communicate(timeout=60)
    assert group_is_empty(child.pid)
    crashed = SweepTable.load(tmp_path / "sweep_faulty")
    assert 1 <= len(crashed["k"]) <= 8 and set(crashed["status"]) == {0}
    assert not (tmp_path / "sweep_faulty.npz").exists()  # written only once complete

    monkeypatch.setitem(SCENES, "faulty", FAULTY)
    assert main(sweep_argv(tmp_path, "k=0:7:8", "--resume")) == 0
    table, _ = loaded(tmp_path)
    assert table["k"].tolist() == list(range(8)) and set(table["status"]) == {0}
    for k, wall_time, q0 in zip(crashed["k"], crashed["wall_time"], crashed["q0"]):
        assert table["wall_time"][k] == wall_time and table["q0"][k] == q0


def test_a_killed_worker_fails_only_its_point_and_the_sweep_goes_on(tmp_path):
    """Point 2 kills its worker process, which breaks the pool and the neighbour point in
    flight with it: a new pool runs those two again one at a time, so point 2 (killing its
    worker again) is marked failed with the reason, every other point is computed and the
    table written; exit 1; no process left."""
    child = start(sweep_argv(tmp_path, "k=0:5:6", "--set", "kill=2"))
    _, err = child.communicate(timeout=120)
    assert child.returncode == 1 and group_is_empty(child.pid)
    table, _ = loaded(tmp_path)
    assert table["status"].tolist() == [0, 0, -1, 0, 0, 0]
    assert table["error"][2].startswith("worker process died (killed by SIGKILL, as the out-of-memory killer does) "
                                        "twice while running this point, the second time alone")
    assert "point k=2, kill=2 failed: worker process died" in err


def test_a_failing_point_is_one_quoted_line(tmp_path, monkeypatch, capsys):
    """A point whose error message holds a comma and a line break: the CSV keeps one line per
    point (the message on one line, quoted), and the table loads back with the message."""
    monkeypatch.setitem(SCENES, "faulty", FAULTY)
    assert main(sweep_argv(tmp_path, "k=0:2:3", "--set", "fail=1")) == 1
    lines = (tmp_path / "sweep_faulty.csv").read_text().splitlines()
    assert len(lines) == 4 and lines[2].endswith('"ValueError: bad point, on purpose second line of the message"')
    table, _ = loaded(tmp_path)
    assert table["status"].tolist() == [0, -1, 0]
    assert table["error"][1] == "ValueError: bad point, on purpose second line of the message"


def _full_disk(*args, **kwargs):
    raise OSError(errno.ENOSPC, "No space left on device")


def test_a_run_whose_files_cannot_be_completed_leaves_none_under_a_final_name(tmp_path, monkeypatch, capsys):
    """The disk fills while chain.npz is written (half a file, then ENOSPC), or the final
    rename fails: exit 1 with the reason, no file under its final name, no temporary left."""
    real_savez = np.savez

    def half_then_full(path, *args, **kwargs):
        real_savez(path, *args, **kwargs)
        with open(path, "r+b") as stream:
            stream.truncate(os.path.getsize(path) // 2)
        _full_disk()

    monkeypatch.setattr(np, "savez", half_then_full)
    assert main(["run", "chain", "--set", "n=1", "--t-end", "0.1", "--out", str(tmp_path), "--quiet"]) == 1
    assert "No space left on device" in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []

    monkeypatch.setattr(np, "savez", real_savez)
    monkeypatch.setattr(os, "replace", _full_disk)
    assert main(["run", "chain", "--set", "n=1", "--t-end", "0.1", "--out", str(tmp_path), "--quiet"]) == 1
    assert list(tmp_path.iterdir()) == []


def test_a_sweep_whose_table_cannot_be_completed_keeps_the_appended_points(tmp_path, monkeypatch, capsys):
    """The final renames of the sweep table fail (the CSV in input order, the NPZ): no NPZ
    under its name, no temporary left, and the CSV still holds every point as it was
    appended while the sweep ran (loadable)."""
    monkeypatch.setitem(SCENES, "faulty", FAULTY)
    renamed = []

    def replace_once(source, target):  # the sweep's record and the table's header go in, the final CSV and NPZ do not
        renamed.append(target)
        return os.rename(source, target) if len(renamed) <= 2 else _full_disk()

    monkeypatch.setattr(os, "replace", replace_once)
    assert main(sweep_argv(tmp_path, "k=0:3:4")) == 1
    assert "No space left on device" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sweep_faulty.csv", "sweep_faulty.json"]
    table = SweepTable.load(tmp_path / "sweep_faulty")
    assert sorted(table["k"].tolist()) == [0, 1, 2, 3] and set(table["status"]) == {0}


def test_sigterm_to_a_run_writes_the_trajectory_so_far(tmp_path):
    """SIGTERM (not Ctrl-C) to ``projeq run``: exit 1, and the trajectory up to the last
    finished segment (1 % of the run) is written and loads back, with status 2."""
    code, err = signalled(["run", "chain", "--set", "n=1", "--t-end", "1000", "--out", str(tmp_path), "--quiet"],
                          signal.SIGTERM)
    assert code == 1 and "interrupted at t = " in err and "Traceback" not in err
    saved = pq.Result.load(next(tmp_path.rglob("chain.npz")))
    assert saved.status == 2 and 10.0 <= saved.t[-1] < 1000.0
    assert not list(tmp_path.glob(".*"))  # no temporary file left


@pytest.mark.parametrize(
    "argv, message",
    [
        (["chain", "--grid", "n=1:3:3", "--grid", "n=4:5:2"], "--grid: n is given twice"),
        (["chain", "--grid", "n=1:3:3", "--set", "n=2"], "--grid: n is also given in --set"),
        (["chain", "--grid", "n=1:2:3"], "repeats the values [2] after rounding to integers (n is an integer)"),
        (["atwood", "--grid", "m1=2:2:2"], "repeats the values [2.0]"),
        (["atwood", "--grid", "m1=1:2:400", "--grid", "m2=1:2:300"],
         "--grid: 120,000 points (400 x 300) is more than 100,000; give --allow-large"),
        (["atwood", "--grid", "m1=1:nan:3"], "--grid: expected NAME=A:B:N"),
        (["chain", "--grid", "n=1:3:3", "--outputs", "q0", "--resume"], "resume: "),
        (["chain", "--grid", "n=1:3:3", "--rtol", "-1"], "rtol: must be positive, got -1.0"),
        (["chain", "--grid", "n=1:3:3", "--outputs", "q99"],
         "outputs: 'q99' asks for q[99], but the models of the first and last points have 1 and 3 entries"),
        (["chain", "--grid", "n=-4:0:3"], "grid: neither the first nor the last point can be built"),
        (["spin_up_beam", "--grid", "family=1:2:2"], "--grid: family is not a number (its default is 'polynomial')"),
    ],
    ids=["twice", "grid-and-set", "integer-repeats", "float-repeats", "huge", "nan", "resume-other-sweep",
         "rtol-negative", "output-q99", "no-point-builds", "text-parameter"],
)
def test_the_grid_is_checked_before_any_work(argv, message, tmp_path, capsys):
    """Each refusal names the option and the problem (exit 2), and nothing is run or
    written: an earlier table in --out (here of another sweep) is left as it was. A negative
    rtol, an output no model has, a grid none of whose ends can be built and a text parameter
    swept as numbers were found only after every point had run and failed (issue 37)."""
    earlier = "n,energy_drift,status,error\n7,0.0,0,\n"
    (tmp_path / f"sweep_{argv[0]}.csv").write_text(earlier)
    assert main(["sweep", *argv, "--out", str(tmp_path)]) == 2
    assert message in capsys.readouterr().err
    assert (tmp_path / f"sweep_{argv[0]}.csv").read_text() == earlier


def test_the_sweep_says_how_many_points_it_runs(tmp_path, capsys):
    argv = ["sweep", "atwood", "--grid", "m1=1:2:2", "--grid", "m2=1:2:2", "--t-end", "0.05", "--workers", "1",
            "--out", str(tmp_path)]
    assert main(argv) == 0
    assert capsys.readouterr().out.startswith("sweep atwood: 4 points on 1 local processes")


@pytest.mark.parametrize("api", ["cli", "python"])
def test_a_large_sweep_says_how_long_it_will_take(api, tmp_path, capsys, monkeypatch):
    """A sweep with more points than ESTIMATE_ABOVE (lowered to 3 here) runs its first two
    points in the main process, the second timed, and prints "N points, about T (≈ t per point
    × N / W workers)" before the others start; their rows are kept (the table is complete, in
    order), and a small sweep prints no estimate."""
    import concurrent.futures as cf
    import re

    import projeq.simulation.sweep as sweep_module

    monkeypatch.setattr(sweep_module, "ESTIMATE_ABOVE", 3)
    if api == "cli":
        argv = ["sweep", "atwood", "--grid", "m1=1:2:2", "--grid", "m2=1:2:2", "--t-end", "0.05", "--workers", "1",
                "--out", str(tmp_path)]
        assert main(argv) == 0
        table, workers = SweepTable.load(tmp_path / "sweep_atwood"), "1 worker"
    else:
        with cf.ThreadPoolExecutor(2) as pool:
            table = sweep_module.sweep("atwood", grid={"m1": [1.0, 2.0], "m2": [1.0, 2.0]}, executor=pool,
                                       t_end=0.05, progress=True)
        workers = "2 workers"
    out = capsys.readouterr().out
    assert re.search(r"^4 points, about \S+ (s|min|h|days) \(≈ \S+ s per point × 4 / " + workers + r"\)$", out, re.M), out
    assert table["status"].tolist() == [0, 0, 0, 0] and table["m1"].tolist() == [1.0, 1.0, 2.0, 2.0]
    with cf.ThreadPoolExecutor(1) as pool:
        sweep_module.sweep("atwood", grid={"m1": [1.0, 2.0]}, executor=pool, t_end=0.05)
    assert "points, about" not in capsys.readouterr().out


def test_a_lost_dask_scheduler_fails_the_points_it_held_exit_1_no_traceback(tmp_path, capsys, monkeypatch):
    """Passes if a Dask scheduler lost after the first point (the client's futures cancelled, its
    submissions refused: tests/simulation/test_sweep_faults.LostScheduler, behind a client) ends
    the sweep with exit 1, each lost point named on stderr with the reason, no traceback, and the
    table written (before: a concurrent.futures.CancelledError traceback, the running points
    unrecorded)."""
    pytest.importorskip("cloudpickle")  # the scene goes to Dask workers by value
    import projeq.cli.sweep
    from tests.simulation.test_sweep_faults import LostScheduler

    class Client:  # what sweep uses of a dask.distributed.Client
        status = "running"

        def get_executor(self):
            return LostScheduler(2)  # the check that a worker loads the scene, then the first point

        def close(self, timeout=None):
            raise OSError("the scheduler is gone")

    monkeypatch.setattr(projeq.cli.sweep, "_dask_client", lambda address, timeout: Client())
    argv = ["sweep", "atwood", "--grid", "m1=1:2:3", "--scheduler", "tcp://lost:8786", "--t-end", "0.05",
            "--out", str(tmp_path), "--quiet"]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err and "point m1=1.5 failed: cancelled by the executor" in err
    assert "point m1=2.0 failed: not run: the executor refused it" in err
    assert SweepTable.load(tmp_path / "sweep_atwood")["status"].tolist() == [0, -1, -1]

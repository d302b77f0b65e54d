"""Parameter sweeps: one simulation per parameter point, run in parallel, gathered in a table.

``sweep(scene, grid=..., outputs=...)`` runs every point on a process pool (default), on any
:class:`concurrent.futures.Executor`, or on a Dask cluster given a
``dask.distributed.Client`` (``pip install "projeq[dask]"``). A point whose build or run
fails is kept in the table with ``status = -1`` and its error message, never dropped.

Nothing is lost under faults:

- with ``path``, each finished point is appended to ``path.csv`` as it completes (one
  complete line per point, an append that fails is undone), so a crash loses only the
  points in flight; at the end ``path.csv`` (in input order) and ``path.npz`` are written
  under temporary names and renamed (:func:`projeq.simulation.export.written_atomically`).
  ``resume=True`` keeps the finished points of an earlier ``path.csv`` and runs the rest;
- the default pool holds one point per worker. A worker process that dies (killed, or by
  the out-of-memory killer) breaks it: a new pool runs the points that were in flight again,
  one at a time, so only a point that kills its worker again is marked failed, with the
  reason, and the sweep goes on;
- Ctrl-C on a terminal reaches the whole process group: the pool's workers are started with
  :func:`interruptible_worker`, so a point being simulated stops and returns what it has
  (``status`` 2, outputs at the time reached, see :func:`projeq.simulate`) while idle workers
  stay quiet, and :func:`sweep` gathers those partial points before it returns. A
  KeyboardInterrupt that reaches only the main process (``projeq sweep`` turns SIGTERM into
  one) is passed on to the workers of the default pool, which are stopped before
  :func:`sweep` returns.
"""

from __future__ import annotations

import ast
import concurrent.futures as cf
import csv
import io
import itertools
import json
import os
import pickle
import signal
import sys
import threading
import time
import warnings
from collections import deque
from pathlib import Path

import numpy as np

from projeq.checks import finite_array
from projeq.scenes import Scene, check_names, get_scene
from projeq.simulation.driver import SimulationError, check_arguments, check_options
from projeq.simulation.export import written_atomically
from projeq.studies.table import Table, csv_cells, csv_line

#: Outputs every sweep can ask for by name: a function of the Result.
BUILTIN_OUTPUTS = {
    "t_reached": lambda r: r.t[-1],
    "energy_drift": lambda r: r.energy_drift,
    "constraint_residual": lambda r: np.abs(r.constraint_residual).max() if r.constraint_residual.size else 0.0,
    "wall_time": lambda r: r.wall_time,
    "nfev": lambda r: r.nfev,
}


def _column(name: str):
    """(array name, index) of a ``q<i>`` / ``s_dot<i>`` output, None for a built-in one."""
    if name in BUILTIN_OUTPUTS:
        return None
    if "." in name:  # a coordinate or velocity by name: "bob1.angle", "bob1.angle_dot"
        return "named", name
    for prefix in ("s_dot", "q"):
        if name.startswith(prefix) and name[len(prefix):].isdigit():
            return prefix, int(name[len(prefix):])
    raise ValueError(f"outputs: unknown output {name!r}; expected one of {', '.join(BUILTIN_OUTPUTS)}, q<i>, s_dot<i> "
                     "or a coordinate or velocity by name (subsystem.coordinate)")


def output_value(result, name: str) -> float:
    """A named output of a Result: a :data:`BUILTIN_OUTPUTS` key, or ``q<i>`` / ``s_dot<i>``
    for the final value of coordinate / minimal velocity i, or that of a coordinate or
    velocity by name (``"bob1.angle"``, :meth:`projeq.system.Model.coordinates`); NaN when no time step was
    completed (a run interrupted or failed in its first segment)."""
    if not len(result.t):
        return np.nan
    column = _column(name)
    if column is None:
        return float(BUILTIN_OUTPUTS[name](result))
    if column[0] == "named":
        column = _named_column(result.coordinates, result.velocities, name)
    values = getattr(result, column[0])
    if column[1] >= values.shape[1]:
        raise ValueError(f"outputs: {name!r} asks for {column[0]}[{column[1]}], but this point's model has "
                         f"{values.shape[1]} ({column[0]}0 … {column[0]}{values.shape[1] - 1})")
    return float(values[-1, column[1]])


def _named_column(coordinates, velocities, name: str) -> tuple[str, int]:
    """("q", i) or ("s_dot", i) of the coordinate or velocity called ``name``; ValueError
    listing the names."""
    for array, named in (("q", coordinates), ("s_dot", velocities)):
        names = [n for n, _ in named]
        if name in names:
            return array, names.index(name)
    raise ValueError(f"outputs: no coordinate or velocity {name!r}; the model's are "
                     f"{[n for n, _ in coordinates] + [n for n, _ in velocities]}")


INTERRUPT_GRACE = 10.0  # s to wait, after Ctrl-C, for the running points to return their partial results
PARENT_POLL = 0.5  # s between a worker's checks that the main process is alive
# a sweep of more points than this (to run) with progress on first runs one of them here, timed,
# and says how long the rest will take before they start
ESTIMATE_ABOVE = 1000
_simulating = False  # in a pool worker: True while run_point simulates


def _interrupt_a_running_point(signum, frame):
    global _simulating
    if _simulating:  # once: a second SIGINT must not break the partial result being assembled
        _simulating = False
        raise KeyboardInterrupt


def interruptible_worker() -> None:
    """Initializer of a process-pool worker: SIGINT (Ctrl-C) stops the point it simulates
    (which :func:`projeq.simulate` turns into a partial result, status 2) and is ignored
    while the worker waits for work, so no worker dies with a traceback; SIGTERM ends the
    worker (whatever handler it inherited from the main process), and so does the death of
    the main process (a worker waiting for work would otherwise wait for ever)."""
    signal.signal(signal.SIGINT, _interrupt_a_running_point)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    threading.Thread(target=_exit_with_parent, args=(os.getppid(),), daemon=True).start()


def _exit_with_parent(parent: int) -> None:
    """Exit this process once its parent has gone (it is re-parented: ``getppid`` changes)."""
    while os.getppid() == parent:
        time.sleep(PARENT_POLL)
    os._exit(1)


def run_point(scene: Scene, parameters: dict, outputs, t_end: float, options: dict):
    """Simulate one point; returns (status, output values, error message). Runs on a worker.
    A SimulationError keeps its Result's status (−1 failed, 4 non-finite state); Ctrl-C before the
    integration started (building the scene, simulate's checks and choice of method, which
    simulate does not turn into a partial result) is status 2 too, with no outputs."""
    from projeq.simulation.driver import simulate

    global _simulating
    try:
        _simulating = True
        result = simulate(scene.build(**parameters), t_end, **options)
        return result.status, [output_value(result, o) for o in outputs], ""
    except KeyboardInterrupt:
        return 2, [np.nan] * len(outputs), "interrupted before its integration started"
    except Exception as exc:  # noqa: BLE001 - a failed point is reported in the table, never dropped
        status = exc.result.status if isinstance(exc, SimulationError) else -1
        return status, [np.nan] * len(outputs), _one_line(exc)
    finally:
        _simulating = False


def _one_line(exc: BaseException) -> str:
    return " ".join(f"{type(exc).__name__}: {exc}".splitlines())


def run_shipped_point(shipped: bytes, parameters: dict, outputs, t_end: float, options: dict):
    """:func:`run_point` of a scene sent by value (:func:`ship`), on a Dask worker: a scene the
    worker cannot load (a module it cannot import) is this point's failure, named."""
    try:
        scene = _unship(shipped)
    except Exception as exc:  # noqa: BLE001 - reported in the table, never a worker's death
        return -1, [np.nan] * len(outputs), f"the worker cannot load the scene: {_one_line(exc)}"
    return run_point(scene, parameters, outputs, t_end, options)


def ship(scene: Scene) -> bytes:
    """``scene`` pickled by value where workers may not have its code: the module of its build
    function, unless it is projeq's or an installed package's (a user's file, loaded by
    :func:`projeq.scenes.resolve_scene`, or a module of the user's own), goes with it (cloudpickle,
    which Dask brings), so that Dask workers need only projeq."""
    import cloudpickle

    module = sys.modules.get(getattr(scene.build, "__module__", None) or "")
    by_value = module is not None and _users(module)
    if by_value:
        cloudpickle.register_pickle_by_value(module)
    try:
        return cloudpickle.dumps(scene)
    finally:
        if by_value:
            cloudpickle.unregister_pickle_by_value(module)


def _users(module) -> bool:
    """A module of the user's: not projeq's, the standard library's or an installed package's."""
    path = getattr(module, "__file__", None) or ""
    return (module.__name__.partition(".")[0] != "projeq" and bool(path)
            and not any(part in Path(path).parts for part in ("site-packages", "dist-packages"))
            and not path.startswith(sys.base_prefix + os.sep))


def _unship(shipped: bytes) -> Scene:
    import cloudpickle

    return cloudpickle.loads(shipped)


WORKERS_ANSWER = 30.0  # s within which a Dask worker must load the scene before the sweep starts


def _check_workers(pool, shipped: bytes) -> None:
    """ValueError unless a Dask worker loads the shipped scene within :data:`WORKERS_ANSWER` s:
    naming the module it cannot import, or saying that no worker answered (workers without
    projeq or cloudpickle cannot even read the task: they would never return it)."""
    future = pool.submit(_unship, shipped)
    try:
        future.result(timeout=WORKERS_ANSWER)
    except cf.TimeoutError:
        future.cancel()
        raise ValueError(f"executor: no Dask worker loaded the scene within {WORKERS_ANSWER:g} s; do the workers "
                         "run, with projeq and cloudpickle installed (the same versions as here)?") from None
    except Exception as exc:  # noqa: BLE001 - whatever the worker raised while loading
        raise ValueError(f"executor: the Dask workers cannot load the scene ({_one_line(exc)}): install that module "
                         "on the workers, or put its code into the scene's file") from None


class SweepTable(dict):
    """Columns of a sweep: parameters, outputs, ``status`` (Result.status; −1 failed) and
    ``error`` (the message of a failed point, else ""), one row per point in input order."""

    def save(self, path) -> list[Path]:
        """Write ``path.csv`` (:class:`~projeq.studies.table.Table`, the error message last) and
        ``path.npz`` (path without suffix), each under a temporary name renamed when complete
        (the directory is created if it is missing, e.g. deleted during the sweep); returns
        both paths."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        csv_path, npz = path.with_suffix(".csv"), path.with_suffix(".npz")
        with written_atomically(csv_path) as temporary:
            Table.from_columns({k: self[k] for k in self if k != "error"} | {"error": self["error"]}).to_csv(temporary)
        with written_atomically(npz) as temporary:
            np.savez(temporary, **{k: np.asarray(v, dtype=object if k in ("error",) else None) for k, v in self.items()})
        return [csv_path, npz]

    @classmethod
    def load(cls, path) -> "SweepTable":
        """Read ``path.csv`` (path with or without the suffix): a table written by
        :meth:`save`, or the points of a sweep still running or killed, in the order they
        finished. Numbers come back exactly (floats are written as their round-trip repr)."""
        path = Path(path).with_suffix(".csv")
        header, rows = _read_csv(path)
        table = cls()
        for j, name in enumerate(header):
            cells = [row[j] for row in rows]
            if name == "error":
                table[name] = cells
            elif name == "status":
                table[name] = np.array([int(c) for c in cells], dtype=int)
            else:
                values = [_value(c) for c in cells]
                scalar = all(not isinstance(v, (tuple, str)) for v in values)
                # tuples stay objects: the None keeps numpy from making them a 2-d array
                table[name] = np.array(values) if scalar else np.array(values + [None], dtype=object)[:-1]
        return table


def _value(text: str):
    """A CSV cell back to its value: int, float, a tuple, a bool, else the text."""
    for parse in (int, float):
        try:
            return parse(text)
        except ValueError:
            pass
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return text


def _read_csv(path: Path) -> tuple[list[str], list[list[str]]]:
    """Header and rows of a sweep CSV; a last line cut off without its newline (a process
    killed while appending) is left out; ValueError naming the file if it is not a sweep table."""
    try:
        text = path.read_text()
    except OSError as exc:
        raise ValueError(f"path: cannot read the sweep table {str(path)!r}: {exc.strerror or exc}") from None
    if not text.endswith("\n"):
        text = text[: text.rfind("\n") + 1]
    lines = list(csv.reader(io.StringIO(text)))
    if not lines or lines[0][-2:] != ["status", "error"]:
        raise ValueError(f"path: {str(path)!r} is not a sweep table (its header must end with status,error)")
    bad = [i + 2 for i, row in enumerate(lines[1:]) if len(row) != len(lines[0])]
    if bad:
        raise ValueError(f"path: {str(path)!r} line {bad[0]} has a different number of cells than its header")
    return lines[0], lines[1:]


class _Log:
    """``path.csv`` while a sweep runs: the header and the points kept from an earlier run,
    then one line appended per finished point. Each line is one ``os.write`` to a file opened
    for appending, and an append that fails (a full disk) is cut off again, so the file holds
    whole rows only; after a failure the points are kept in memory only (a warning says so)."""

    def __init__(self, path: Path, header: list, kept_rows: list):
        path.parent.mkdir(parents=True, exist_ok=True)
        with written_atomically(path) as temporary:
            temporary.write_text(csv_line(header) + "".join(csv_line(row) for row in kept_rows))
        self.path, self.fd = path, os.open(path, os.O_WRONLY | os.O_APPEND)

    def append(self, row) -> None:
        if self.fd is None:
            return
        line, size = csv_line(row).encode(), os.fstat(self.fd).st_size
        try:
            while line:
                line = line[os.write(self.fd, line):]
        except OSError as exc:
            os.ftruncate(self.fd, size)
            self.close()
            warnings.warn(f"path: cannot append to {str(self.path)!r} ({exc.strerror or exc}); the sweep goes on "
                          "with its points in memory only", RuntimeWarning, stacklevel=2)

    def close(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None


def _points(grid, samples) -> list[dict]:
    if (grid is None) == (samples is None):
        raise ValueError("grid, samples: give exactly one of them")
    if grid is not None:
        if not isinstance(grid, dict) or not grid:
            raise ValueError(f"grid: expected a non-empty dict name -> values, got {grid!r}")
        _check_columns("grid", grid)
        empty = [name for name, values in grid.items() if not len(values)]
        if empty:
            raise ValueError(f"grid: {empty[0]} has no values; give it at least one")
        return [dict(zip(grid, values)) for values in itertools.product(*grid.values())]
    if isinstance(samples, dict):
        _check_columns("samples", samples)
        lengths = {len(v) for v in samples.values()}
        if len(lengths) != 1:
            raise ValueError(f"samples: all columns must have the same length, got {sorted(lengths)}")
        points = [dict(zip(samples, values)) for values in zip(*samples.values())]
    else:
        points = [dict(p) for p in samples]
    if not points or not points[0]:
        raise ValueError(f"samples: expected at least one point with at least one parameter, got {samples!r}")
    return [_same_parameters(i, p, list(points[0])) for i, p in enumerate(points)]


def _outputs(outputs, point: dict) -> list:
    """The outputs as a list of distinct names, none a parameter's: the table has one column per
    name, so a parameter q0 and the output q0 (the final q[0]) would share it."""
    if isinstance(outputs, str):
        raise ValueError(f"outputs: expected a sequence of output names, got the string {outputs!r} "
                         f"(write [{outputs!r}])")
    outputs = list(outputs)
    repeated = sorted({name for name in outputs if outputs.count(name) > 1})
    if repeated:
        raise ValueError(f"outputs: {repeated} asked for more than once; the table has one column per name")
    clash = [name for name in outputs if name in point]
    if clash:
        raise ValueError(f"outputs: {clash} are parameters of the sweep too; the table has one column per name "
                         "(ask for a final coordinate by its name, subsystem.coordinate)")
    return outputs


def _end_time(t_end, t_start) -> float:
    """``t_end`` checked once for all points (else each point would fail alike)."""
    t_end = float(finite_array("t_end", t_end, ()))
    if not t_end > float(finite_array("t_start", t_start, ())):
        raise ValueError(f"t_end: must be after t_start = {t_start}, got {t_end}")
    return t_end


def _check_columns(name: str, columns: dict) -> None:
    """Each parameter's values are a sequence (a bare number or text would be no column)."""
    for parameter, values in columns.items():
        if isinstance(values, str) or not np.iterable(values):
            raise ValueError(f"{name}: {parameter} must be a sequence of values, got {values!r} "
                             f"(write [{values!r}])")


def _same_parameters(i: int, point: dict, names: list) -> dict:
    """Point i with the parameters of the first point, in their order: the table's columns and
    each CSV line are written in that order."""
    if sorted(point) != sorted(names):
        raise ValueError(f"samples[{i}]: sets the parameters {sorted(point)}, the first point {sorted(names)}; "
                         "every point must set the same ones (the table has one column per parameter)")
    return {name: point[name] for name in names}


def process_pool(workers: int | None = None) -> cf.ProcessPoolExecutor:
    """The default executor: local processes (``workers``, default one per core) whose
    points stop on Ctrl-C and return what they have (:func:`interruptible_worker`)."""
    return cf.ProcessPoolExecutor(workers, initializer=interruptible_worker)


def _executor(executor, workers):
    """(executor, owned): a Dask Client becomes its concurrent.futures view; None, a pool of
    ``workers`` local processes that :func:`sweep` owns (replaces when broken, stops on an
    interrupt)."""
    if workers is not None and (not isinstance(workers, (int, np.integer)) or isinstance(workers, bool) or workers < 1):
        raise ValueError(f"workers: expected a positive number of processes, got {workers!r}")
    if executor is None:
        return process_pool(workers), True
    if workers is not None:
        raise ValueError("workers: only for the default process pool; the executor given sets its own workers")
    if hasattr(executor, "get_executor"):  # dask.distributed.Client
        if getattr(executor, "status", "running") != "running":
            raise ValueError(f"executor: the Dask client is not connected (status {executor.status!r})")
        return executor.get_executor(), False
    if not isinstance(executor, cf.Executor):
        raise ValueError(f"executor: expected a concurrent.futures.Executor or a dask Client, got {executor!r}")
    return executor, False


def sweep(scene, grid=None, samples=None, outputs=("energy_drift", "t_reached"), executor=None, *,
          t_end=None, progress: bool = True, path=None, resume: bool = False, workers: int | None = None,
          **options) -> SweepTable:
    """Simulate ``scene`` at every parameter point and gather the outputs in one table.

    Parameters
    ----------
    scene : str or Scene
        A registered scene name or a :class:`projeq.scenes.Scene`. Local worker processes
        inherit its build function; to Dask workers it is sent by value (:func:`ship`: the
        user's own module goes with it), and a worker that cannot load it within
        :data:`WORKERS_ANSWER` s is a ValueError naming the module, before any point runs.
    grid : dict name -> sequence, optional
        The Cartesian product of the values is swept.
    samples : list of dicts or dict name -> equal-length sequences, optional
        Explicit points (e.g. Monte Carlo draws). Give exactly one of grid and samples.
    outputs : sequence of str
        Names understood by :func:`output_value` (final ``q<i>``, ``s_dot<i>``, a coordinate or
        velocity by name such as ``bob1.angle``, ``energy_drift`` ...).
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Default: a local process pool of ``workers`` processes.
    t_end : float, optional
        End time (s), default the scene's.
    progress : bool
        A progress bar (tqdm) on a terminal. With more than :data:`ESTIMATE_ABOVE` points to
        run, the first two run in this process first, the second timed (the first compiles),
        and a line on stdout says how long the sweep will take: "N points, about T (≈ t per
        point × N / W workers)".
    path : str or Path, optional
        Write the table to ``path.csv`` and ``path.npz`` (path without suffix): each point is
        appended to ``path.csv`` as it finishes, and both files are complete, in input order,
        when the sweep returns (also after an interrupt).
    resume : bool
        Keep the finished points (status 0 or 1) of an earlier ``path.csv`` of the same sweep
        and run only the others (failed, interrupted or not run). ``path.json``, written when
        the sweep starts, records its scene, end time and options: a table made with others
        (or without that record) is refused, naming what differs.
    workers : int, optional
        Processes of the default pool (default one per core).
    **options
        Passed to :func:`projeq.simulate` (method, rtol, atol, n_points ...).

    Before any point runs, the first and the last point are built (one of them at least must
    be), the first buildable point's run is checked as :func:`projeq.simulate` checks its
    arguments (:func:`check_arguments`) and each output name against their models: a grid whose
    ends cannot be built, a bad option value or an output no model has is a ValueError here,
    not every point failing alike.

    Returns
    -------
    SweepTable
        A dict of columns. On Ctrl-C the points finished so far are returned, the points that
        were running with their partial results (status 2), the others marked status −1,
        error "interrupted". A point whose worker process died has status −1 and an error
        saying so (on the default pool: only a point that killed its worker twice, the second
        time running alone). Points that an executor cancels (a Dask scheduler lost) or no
        longer takes have status −1 and an error saying so; the sweep returns its table.

    >>> table = sweep("chain", grid={"n": [1, 2]}, outputs=["q0"], executor=cf.ThreadPoolExecutor(2),
    ...               t_end=0.1, progress=False)
    >>> table["n"].tolist(), table["status"].tolist()
    ([1, 2], [0, 0])
    """
    scene = get_scene(scene) if isinstance(scene, str) else scene
    points = _points(grid, samples)
    for p in points:
        check_names(scene, p)
    outputs = _outputs(outputs, points[0])
    t_end = scene.t_end if t_end is None else _end_time(t_end, options.get("t_start", 0.0))
    check_options(options)  # a misspelt option is one error here, not every point failing alike
    _check_first_run(scene, points, outputs, t_end, options)
    if resume and path is None:
        raise ValueError("resume: needs path, the table of the sweep to resume")
    header = list(points[0]) + outputs + ["status", "error"]
    rows = [None] * len(points)  # (status, outputs, error) of each point, None until it is done
    made_with = _record(scene, t_end, options)
    if resume:
        _resumed(Path(path).with_suffix(".csv"), header, points, rows, made_with)
    if executor is None or isinstance(executor, cf.ProcessPoolExecutor):
        _check_picklable(scene, options)
    pool, owned = _executor(executor, workers)
    task = lambda p: (run_point, scene, p, outputs, t_end, options)  # noqa: E731
    if hasattr(executor, "get_executor"):  # Dask: the scene by value, checked on a worker first
        shipped = ship(scene)
        _check_workers(pool, shipped)
        task = lambda p: (run_shipped_point, shipped, p, outputs, t_end, options)  # noqa: E731
    if path is not None:
        _write_record(Path(path).with_suffix(".json"), made_with)
    log = None if path is None else _Log(Path(path).with_suffix(".csv"), header,
                                         [_row(points[i], r) for i, r in enumerate(rows) if r is not None])
    from tqdm import tqdm

    def record(i, row):
        if rows[i] is not None:  # recorded already (an interrupt between recording and forgetting it)
            return
        rows[i] = row
        if log is not None:
            log.append(_row(points[i], row))
        bar.update()

    run = _Run(pool, owned, workers, task, len(outputs))
    todo = [i for i, r in enumerate(rows) if r is None]
    try:
        with tqdm(total=len(points), initial=len(points) - len(todo), unit="run",
                  disable=None if progress else True) as bar:
            if progress and len(todo) > ESTIMATE_ABOVE:
                todo = _probe(run, todo, points, record, lambda message: tqdm.write(message, file=sys.stdout))
            run.all(todo, points, record)
    finally:
        run.close()
        if log is not None:
            log.close()
    rows = [(-1, [np.nan] * len(outputs), "interrupted") if r is None else r for r in rows]
    table = _table(points, outputs, rows)
    if path is not None:
        table.save(path)
    return table


def _probe(run: "_Run", todo: list, points: list, record, say) -> list:
    """Run the first two points of ``todo`` in this process (their rows are kept), the second
    timed (the first pays for imports and compilation, once per process), and ``say``
    "N points, about T (≈ t per point × N / W workers)" for the N points to run on the
    executor's W workers; the points left to run (none after Ctrl-C during the probe)."""
    try:
        for i in todo[:2]:
            started = time.perf_counter()
            record(i, run_point(*run.task(points[i])[1:]))
    except KeyboardInterrupt:
        run.interrupted = True
        return []
    per_point, workers = time.perf_counter() - started, run.workers()
    say(f"{len(todo)} points, about {_duration(per_point * len(todo) / workers)} "
        f"(≈ {per_point:.3g} s per point × {len(todo)} / {workers} worker{'s' * (workers > 1)})")
    return todo[2:]


def _duration(seconds: float) -> str:
    """``seconds`` as s, min, h or days, three digits."""
    for unit, size in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


class _Run:
    """The points of one sweep on an executor: at most one point per worker in flight on an
    owned pool, every point at once on another executor. A worker's death breaks an owned
    pool: it is replaced, and the points that were in flight run again one at a time, so the
    point that kills its worker again is found and failed, and the others are computed.
    An interrupt gathers the running points."""

    def __init__(self, pool, owned: bool, workers, task, n_outputs: int):
        self.pool, self.owned, self.task, self.n_outputs = pool, owned, task, n_outputs
        self.window = (workers or os.cpu_count() or 1) if owned else None
        self.running = {}  # future -> point index
        self.processes = {}  # pid -> worker process of the owned pool, for the reason of a death
        self.suspects = deque()  # points in flight when a worker died, to run again alone
        self.retried = set()
        self.interrupted = False

    def all(self, todo: list, points: list, record) -> None:
        waiting = deque(todo)
        try:
            while waiting or self.suspects or self.running:
                while (self.suspects or waiting) and not self._full():
                    i = (self.suspects or waiting).popleft()
                    try:
                        self.running[self.pool.submit(*self.task(points[i]))] = i
                    except cf.BrokenExecutor as exc:  # an executor not ours, broken: nothing more runs
                        record(i, self._failure(f"not run: the executor is broken ({exc})"))
                    except Exception as exc:  # noqa: BLE001 - e.g. a Dask client whose scheduler is gone
                        if self.owned:
                            raise
                        record(i, self._failure(f"not run: the executor refused it ({_one_line(exc)})"))
                self.processes.update(getattr(self.pool, "_processes", None) or {})
                for future in _finished(self.running):
                    self._done(future, record)
                if self.owned and getattr(self.pool, "_broken", False):  # a worker died: a new pool
                    self.pool.shutdown(wait=True)  # ... once every point of the old one is marked
                    for future in [f for f in self.running if f.done()]:
                        self._done(future, record)
                    self.pool, self.processes = process_pool(self.window), {}
        except KeyboardInterrupt:
            self.interrupted = True
            self._gather(record)

    def workers(self) -> int:
        """How many points run at once: the owned pool's processes, another executor's
        ``_max_workers`` or a Dask cluster's workers where known, else 1."""
        if self.window is not None:
            return self.window
        client = getattr(self.pool, "_client", None)  # dask's concurrent.futures view
        if client is not None and hasattr(client, "scheduler_info"):
            return max(1, len(client.scheduler_info().get("workers", ())))
        return max(1, int(getattr(self.pool, "_max_workers", 1) or 1))

    def _full(self) -> bool:
        """No room for another point: one per worker, and a point run again runs alone."""
        alone = self.suspects or any(i in self.retried for i in self.running.values())
        limit = 1 if alone else self.window
        return limit is not None and len(self.running) >= limit

    def _done(self, future, record) -> None:
        """Record a finished point (or queue it to run again alone), then forget its future:
        in this order, so that an interrupt in between cannot lose it."""
        i = self.running[future]
        broken = not future.cancelled() and isinstance(future.exception(), cf.BrokenExecutor)
        if self.owned and broken and i not in self.retried:
            self.retried.add(i)
            self.suspects.append(i)
        else:
            record(i, self._outcome(future, i in self.retried))
        del self.running[future]

    def _outcome(self, future, alone: bool):
        if future.cancelled():
            return self._failure("cancelled by the executor while it ran or waited (a Dask scheduler lost?); "
                                 "with resume=True / --resume it runs again")
        exc = future.exception()
        if exc is None:
            return future.result()
        if isinstance(exc, cf.BrokenExecutor):
            when = " twice while running this point, the second time alone" if alone else " while this point was running"
            return self._failure(f"worker process died{_cause_of_death(list(self.processes.values()))}{when} "
                                 "(with resume=True / --resume it runs again)")
        return self._failure(f"{type(exc).__name__}: {exc}")

    def _failure(self, message: str) -> tuple:
        return -1, [np.nan] * self.n_outputs, message

    def _gather(self, record) -> None:
        """After an interrupt: cancel the points not started, tell the owned pool's workers
        (a SIGINT, as Ctrl-C on a terminal would), and keep the running points' partial
        results (status 2) when they return within :data:`INTERRUPT_GRACE` seconds."""
        for future in self.running:
            future.cancel()
        if self.owned:
            for process in _workers(self.pool):
                _signal(process, signal.SIGINT)
        done, _ = cf.wait(self.running, timeout=INTERRUPT_GRACE)
        for future in done:
            if not future.cancelled() and future.exception() is None:
                record(self.running[future], future.result())

    def close(self) -> None:
        """Shut an owned pool down; after an interrupt, its workers still alive are terminated."""
        if not self.owned:
            return
        processes = _workers(self.pool)
        self.pool.shutdown(wait=not self.interrupted, cancel_futures=True)
        for process in processes if self.interrupted else ():
            process.join(1.0)
            process.terminate()  # still busy after the grace: SIGTERM ends a worker (interruptible_worker)
            process.join(1.0)


def _finished(running: dict) -> list:
    """The futures among ``running`` (future -> point index) that are done, waiting for at least one,
    in their points' order: points that finished together are recorded, and appended to the table's
    file, in input order (a set's order was arbitrary)."""
    return sorted(cf.wait(running, return_when=cf.FIRST_COMPLETED)[0], key=running.get)


def _workers(pool) -> list:
    """The worker processes of a ProcessPoolExecutor (none for another executor)."""
    return list((getattr(pool, "_processes", None) or {}).values())


def _signal(process, signum) -> None:
    try:
        os.kill(process.pid, signum)
    except (ProcessLookupError, TypeError):  # gone already, or never started
        pass


def _cause_of_death(processes, wait: float = 2.0) -> str:
    """" (killed by SIGKILL ...)" from the exit codes of a broken pool's workers, else "".
    Waits up to ``wait`` s for them: the pool's own thread may be reaping them just now."""
    deadline = time.monotonic() + wait
    while True:
        codes = [process.exitcode for process in processes]
        for code in codes:
            if code is not None and code < 0 and -code != signal.SIGTERM:  # the others are terminated by the pool
                name = signal.Signals(-code).name
                return f" (killed by {name}{', as the out-of-memory killer does' if name == 'SIGKILL' else ''})"
            if code is not None and code > 0:
                return f" (exit code {code})"
        if time.monotonic() > deadline:
            return ""
        time.sleep(0.05)


def _check_picklable(scene, options) -> None:
    """ValueError before any work if the scene or the options cannot reach worker processes."""
    try:
        pickle.dumps((scene, options))
    except Exception as exc:  # noqa: BLE001 - pickling raises many types
        raise ValueError(
            f"scene: cannot be sent to worker processes ({type(exc).__name__}: {exc}); define its build "
            "function at module level of an importable module, or pass executor=concurrent.futures.ThreadPoolExecutor()"
        ) from None


def _row(point: dict, row) -> list:
    status, values, error = row
    return list(point.values()) + list(values) + [status, error]


def _record(scene, t_end: float, options: dict) -> dict:
    """What a sweep's table depends on besides its columns: the scene (its build function's name,
    not its module's, which depends on how it was imported), the end time and simulate's options,
    as JSON values (others by their repr)."""
    build = getattr(scene.build, "__qualname__", repr(scene.build))
    return json.loads(json.dumps({"scene": build, "t_end": t_end, "options": options}, default=repr))


def _write_record(path: Path, record: dict) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with written_atomically(path) as temporary:
        temporary.write_text(json.dumps(record, indent=2) + "\n")


def _resumed(path: Path, header: list, points: list, rows: list, record: dict) -> None:
    """Fill ``rows`` with the finished points (status 0 or 1) of an earlier ``path`` made with
    the same ``record`` (scene, end time, options: ``path`` with ``.json``)."""
    if not path.exists():
        return
    _same_record(path, record)
    found, lines = _read_csv(path)
    if found != header:
        raise ValueError(f"resume: {str(path)!r} has the columns {found}, this sweep writes {header}; "
                         "resume with the same grid (and --set) and outputs, or write elsewhere")
    n_parameters, n_outputs = len(points[0]), len(header) - len(points[0]) - 2
    finished = {}
    for line in lines:
        key = tuple(line[:n_parameters])
        if key not in finished:
            finished[key] = []
        if line[-2] in ("0", "1"):
            finished[key].append((int(line[-2]), [float(c) for c in line[n_parameters:n_parameters + n_outputs]], ""))
    keys = [tuple(csv_cells(p.values())) for p in points]
    foreign = set(finished) - set(keys)
    if foreign:
        raise ValueError(f"resume: {str(path)!r} holds points not in this sweep (e.g. "
                         f"{dict(zip(header, sorted(foreign)[0]))}); resume with the same grid, or write elsewhere")
    for i, key in enumerate(keys):
        if finished.get(key):
            rows[i] = finished[key].pop(0)


def _same_record(path: Path, record: dict) -> None:
    """ValueError unless the table ``path`` was made with ``record`` (its ``.json``)."""
    try:
        earlier = json.loads(path.with_suffix(".json").read_text())
    except (OSError, ValueError):
        raise ValueError(f"resume: {str(path)!r} has no readable record of the scene, end time and options it was "
                         f"made with ({str(path.with_suffix('.json'))!r}); its values may mean another sweep: "
                         "write elsewhere") from None
    differ = {key: (earlier.get(key), record[key]) for key in record if earlier.get(key) != record[key]}
    if differ.get("options"):
        was, now = differ.pop("options")
        was = was if isinstance(was, dict) else {}
        differ |= {f"options[{k!r}]": (was.get(k), now.get(k))
                   for k in sorted(set(was) | set(now)) if was.get(k) != now.get(k)}
    if differ:
        said = "; ".join(f"{key} {old!r} there, {new!r} now" for key, (old, new) in differ.items())
        raise ValueError(f"resume: {str(path)!r} was made with other settings ({said}); resume with the same "
                         "scene, end time and options, or write elsewhere")


def _check_first_run(scene, points: list, outputs: list, t_end: float, options: dict) -> None:
    """Before any point runs: the first and last points are built (a ValueError naming them when
    neither can be), the first buildable one's run checked as simulate checks its arguments
    (:func:`projeq.simulation.driver.check_arguments`), and each output found in their models
    (a ``q<i>`` beyond every one of them, a name none has)."""
    models, failures = [], []
    for point in (points[0], points[-1]) if len(points) > 1 else points[:1]:
        try:
            models.append(scene.build(**point))
        except Exception as exc:  # noqa: BLE001 - a scene's build raises what it raises
            failures.append(f"{point}: {_one_line(exc)}")
    if not models:  # one point that cannot be built is its row's failure; both ends, the sweep's
        raise ValueError(f"grid: neither the first nor the last point can be built ({'; '.join(failures)}); "
                         "nothing was run")
    try:
        check_arguments(models[0], t_end, **options)
    except ValueError:
        raise
    except Exception:  # noqa: BLE001, S110 - a model that cannot run (singular ...): its points fail, named
        pass
    for name in outputs:
        column = _column(name)
        if column is None:
            continue
        if column[0] == "named":
            _named_column(models[0].coordinates(), models[0].velocities(), name)
            continue
        sizes = [model.n_q if column[0] == "q" else model.n_s for model in models]
        if column[1] >= max(sizes):
            raise ValueError(f"outputs: {name!r} asks for {column[0]}[{column[1]}], but the models of the first and "
                             f"last points have {' and '.join(map(str, sizes))} entries ({column[0]}0 … "
                             f"{column[0]}{max(sizes) - 1})")


def _table(points, outputs, rows) -> SweepTable:
    table = SweepTable()
    for name in points[0]:
        values = [p[name] for p in points]
        table[name] = np.array(values, dtype=object) if isinstance(values[0], tuple) else np.array(values)
    for j, name in enumerate(outputs):
        table[name] = np.array([r[1][j] for r in rows], dtype=float)
    table["status"] = np.array([r[0] for r in rows], dtype=int)
    table["error"] = [r[2] for r in rows]
    return table

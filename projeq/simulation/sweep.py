"""Parameter sweeps: one simulation per parameter point, run in parallel, gathered in a table.

``sweep(scene, grid=..., outputs=...)`` runs every point on a process pool (default), on any
:class:`concurrent.futures.Executor`, or on a Dask cluster given a
``dask.distributed.Client`` (``pip install "projeq[dask]"``). A point whose build or run
fails is kept in the table with ``status = -1`` and its error message, never dropped.
Nothing is written to disk here; :meth:`SweepTable.save` writes CSV + NPZ once the table
is complete, so an unreachable scheduler or Ctrl-C leaves no half-written files.

Ctrl-C on a terminal reaches the whole process group: the pool's workers are started with
:func:`interruptible_worker`, so a point being simulated stops and returns what it has
(``status`` 2, outputs at the time reached, see :func:`projeq.simulate`) while idle workers
stay quiet, and :func:`sweep` gathers those partial points before it returns.
"""

from __future__ import annotations

import concurrent.futures as cf
import itertools
import signal
from pathlib import Path

import numpy as np

from projeq.scenes import Scene, check_names, get_scene
from projeq.studies.table import Table

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
    for prefix in ("s_dot", "q"):
        if name.startswith(prefix) and name[len(prefix):].isdigit():
            return prefix, int(name[len(prefix):])
    raise ValueError(f"outputs: unknown output {name!r}; expected one of {', '.join(BUILTIN_OUTPUTS)}, q<i>, s_dot<i>")


def output_value(result, name: str) -> float:
    """A named output of a Result: a :data:`BUILTIN_OUTPUTS` key, or ``q<i>`` / ``s_dot<i>``
    for the final value of coordinate / minimal velocity i; NaN when no time step was
    completed (a run interrupted or failed in its first segment)."""
    if not len(result.t):
        return np.nan
    column = _column(name)
    if column is None:
        return float(BUILTIN_OUTPUTS[name](result))
    return float(getattr(result, column[0])[-1, column[1]])


INTERRUPT_GRACE = 10.0  # s to wait, after Ctrl-C, for the running points to return their partial results
_simulating = False  # in a pool worker: True while run_point simulates


def _interrupt_a_running_point(signum, frame):
    if _simulating:
        raise KeyboardInterrupt


def interruptible_worker() -> None:
    """Initializer of a process-pool worker: SIGINT (Ctrl-C) stops the point it simulates
    (which :func:`projeq.simulate` turns into a partial result, status 2) and is ignored
    while the worker waits for work, so no worker dies with a traceback."""
    signal.signal(signal.SIGINT, _interrupt_a_running_point)


def run_point(scene: Scene, parameters: dict, outputs, t_end: float, options: dict):
    """Simulate one point; returns (status, output values, error message). Runs on a worker."""
    from projeq.simulation.driver import simulate

    global _simulating
    try:
        _simulating = True
        result = simulate(scene.build(**parameters), t_end, **options)
        return result.status, [output_value(result, o) for o in outputs], ""
    except Exception as exc:  # noqa: BLE001 - a failed point is reported in the table, never dropped
        return -1, [np.nan] * len(outputs), f"{type(exc).__name__}: {exc}"
    finally:
        _simulating = False


class SweepTable(dict):
    """Columns of a sweep: parameters, outputs, ``status`` (Result.status; −1 failed) and
    ``error`` (the message of a failed point, else ""), one row per point in input order."""

    def save(self, path) -> list[Path]:
        """Write ``path.csv`` (:class:`~projeq.studies.table.Table`, the error message last) and
        ``path.npz`` (path without suffix); returns both paths."""
        path = Path(path)
        csv, npz = path.with_suffix(".csv"), path.with_suffix(".npz")
        Table.from_columns({k: self[k] for k in self if k != "error"} | {"error": self["error"]}).to_csv(csv)
        np.savez(npz, **{k: np.asarray(v, dtype=object if k in ("error",) else None) for k, v in self.items()})
        return [csv, npz]


def _points(grid, samples) -> list[dict]:
    if (grid is None) == (samples is None):
        raise ValueError("grid, samples: give exactly one of them")
    if grid is not None:
        if not isinstance(grid, dict) or not grid:
            raise ValueError(f"grid: expected a non-empty dict name -> values, got {grid!r}")
        return [dict(zip(grid, values)) for values in itertools.product(*grid.values())]
    if isinstance(samples, dict):
        lengths = {len(v) for v in samples.values()}
        if len(lengths) != 1:
            raise ValueError(f"samples: all columns must have the same length, got {sorted(lengths)}")
        return [dict(zip(samples, values)) for values in zip(*samples.values())]
    return [dict(p) for p in samples]


def process_pool(workers: int | None = None) -> cf.ProcessPoolExecutor:
    """The default executor: local processes (``workers``, default one per core) whose
    points stop on Ctrl-C and return what they have (:func:`interruptible_worker`)."""
    return cf.ProcessPoolExecutor(workers, initializer=interruptible_worker)


def _executor(executor):
    """(executor, owned): a Dask Client becomes its concurrent.futures view."""
    if executor is None:
        return process_pool(), True
    if hasattr(executor, "get_executor"):  # dask.distributed.Client
        if getattr(executor, "status", "running") != "running":
            raise ValueError(f"executor: the Dask client is not connected (status {executor.status!r})")
        return executor.get_executor(), False
    if not isinstance(executor, cf.Executor):
        raise ValueError(f"executor: expected a concurrent.futures.Executor or a dask Client, got {executor!r}")
    return executor, False


def sweep(scene, grid=None, samples=None, outputs=("energy_drift", "t_reached"), executor=None, *,
          t_end=None, progress: bool = True, **options) -> SweepTable:
    """Simulate ``scene`` at every parameter point and gather the outputs in one table.

    Parameters
    ----------
    scene : str or Scene
        A registered scene name or a :class:`projeq.scenes.Scene` (its build function must be
        importable by the workers).
    grid : dict name -> sequence, optional
        The Cartesian product of the values is swept.
    samples : list of dicts or dict name -> equal-length sequences, optional
        Explicit points (e.g. Monte Carlo draws). Give exactly one of grid and samples.
    outputs : sequence of str
        Names understood by :func:`output_value` (final ``q<i>``, ``s_dot<i>``, ``energy_drift`` ...).
    executor : concurrent.futures.Executor or dask.distributed.Client, optional
        Default: a local process pool.
    t_end : float, optional
        End time (s), default the scene's.
    progress : bool
        A progress bar (tqdm) on a terminal.
    **options
        Passed to :func:`projeq.simulate` (method, rtol, atol, n_points ...).

    Returns
    -------
    SweepTable
        A dict of columns. On Ctrl-C the points finished so far are returned, the points that
        were running with their partial results (status 2), the others marked status −1,
        error "interrupted".

    >>> table = sweep("chain", grid={"n": [1, 2]}, outputs=["q0"], executor=cf.ThreadPoolExecutor(2),
    ...               t_end=0.1, progress=False)
    >>> table["n"].tolist(), table["status"].tolist()
    ([1, 2], [0, 0])
    """
    scene = get_scene(scene) if isinstance(scene, str) else scene
    points = _points(grid, samples)
    for p in points:
        check_names(scene, p)
    outputs = list(outputs)
    for name in outputs:
        _column(name)
    t_end = scene.t_end if t_end is None else float(t_end)
    pool, owned = _executor(executor)
    rows = [(-1, [np.nan] * len(outputs), "interrupted")] * len(points)
    from tqdm import tqdm

    futures = {}
    try:
        futures = {pool.submit(run_point, scene, p, outputs, t_end, options): i for i, p in enumerate(points)}
        with tqdm(total=len(points), unit="run", disable=None if progress else True) as bar:
            for future in cf.as_completed(futures):
                rows[futures[future]] = future.result()
                bar.update()
    except KeyboardInterrupt:
        _gather_interrupted(futures, rows)
    finally:
        if owned:
            pool.shutdown(wait=False, cancel_futures=True)
    return _table(points, outputs, rows)


def _gather_interrupted(futures: dict, rows: list) -> None:
    """After Ctrl-C: cancel the points not started, and keep the running points' partial
    results (status 2) when they return within :data:`INTERRUPT_GRACE` seconds."""
    for future in futures:
        future.cancel()
    done, _ = cf.wait(futures, timeout=INTERRUPT_GRACE)
    for future in done:
        if not future.cancelled() and future.exception() is None:
            rows[futures[future]] = future.result()


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

"""``projeq sweep SCENE --grid NAME=A:B:N ...``: a scene on a parameter grid, in parallel
local processes or on a Dask cluster; writes ``sweep_SCENE.csv`` and ``.npz``, and the sweep's
record ``sweep_SCENE.json``: what ``run.json`` is to a run (the scene's build function, end time
and options, by which ``--resume`` knows its table, and the fields of :func:`projeq.cli.run.run_record`
but the scene's name: fixed parameters, method, tolerances, evaluator, projeq version, command
line, start time) with the grid, the outputs and how many points failed, were interrupted or left
their model's range.

Each finished point is appended to ``sweep_SCENE.csv`` at once, so a crash loses only the
points in flight, and ``--resume`` runs only the points not finished there. Ctrl-C or
SIGTERM stops the workers and writes the table with the points finished (and the running
ones' partial results). A point that failed, was interrupted or stopped where its model left
its range (status 3) makes the exit code 1 (the table is written). The grid is checked first:
no parameter twice (in ``--grid`` or in both ``--grid`` and ``--set``), no repeated values, and
at most :data:`MAX_POINTS` points
unless ``--allow-large``. The number of points is printed first, and before a large sweep
(more than :data:`projeq.simulation.sweep.ESTIMATE_ABOVE` points) an estimate of its time
from its first two points, run here (the second timed) before the others start.
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import sys

import numpy as np

from projeq.checks import positive
from projeq.cli.options import output_directory, scene_label, simulate_options, simulation_options


MAX_POINTS = 100_000  # a larger grid needs --allow-large


def sweep_arguments(parser) -> None:
    parser.add_argument("scene", help="scene name")
    parser.add_argument("--grid", action="append", default=[], metavar="NAME=A:B:N", required=True,
                        help="N values from A to B (linspace) for parameter NAME; repeat for a product grid")
    parser.add_argument("--outputs", default="energy_drift,t_reached",
                        help="comma-separated outputs: energy_drift, constraint_residual, t_reached, wall_time, nfev, q<i>, s_dot<i>, "
                             "or a coordinate or velocity by name (bob1.angle, bob1.angle_dot)")
    parser.add_argument("--scheduler", help="address of a Dask scheduler, e.g. tcp://host:8786 (default: local processes)")
    parser.add_argument("--scheduler-timeout", type=float, default=10.0, help="seconds to wait for the scheduler (default 10)")
    parser.add_argument("--workers", type=int, default=None, help="local worker processes (default: one per CPU)")
    parser.add_argument("--resume", action="store_true",
                        help="keep the finished points of an earlier sweep_SCENE.csv in --out and run only the others")
    parser.add_argument("--allow-large", action="store_true", help=f"run a grid of more than {MAX_POINTS:,} points")
    simulation_options(parser)
    parser.set_defaults(execute=sweep_scene)


def sweep_scene(args) -> int:
    from projeq.cli.run import run_record, write_json
    from projeq.scenes import parse_settings, resolve_scene
    from projeq.simulation.sweep import sweep

    scene, label = resolve_scene(args.scene), scene_label(args.scene)
    fixed = parse_settings(scene, args.set)
    grid = _grid(scene, args.grid, fixed, args.allow_large)
    n_points = math.prod(len(values) for values in grid.values())
    grid.update({name: [value] for name, value in fixed.items()})
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers: expected a positive count, got {args.workers}")
    client = _dask_client(args.scheduler, args.scheduler_timeout) if args.scheduler else None
    options = simulate_options(args, scene)
    t_end = None if args.t_end is None else positive("t_end", args.t_end)  # before anything is printed or made
    quiet = args.quiet or args.json
    asked = run_record(args, scene, fixed, t_end, options)
    asked = {k: v for k, v in asked.items() if k not in ("scene", "t_end")}  # the sweep's own are kept
    asked["parameters"] = {k: v for k, v in asked["parameters"].items() if k not in grid or k in fixed}
    asked |= {"grid": {k: np.asarray(v).tolist() for k, v in grid.items() if k not in fixed},
              "outputs": args.outputs.split(",")}
    with _closed(client):  # a Dask client is closed also when --out is refused
        out = output_directory(args.out)
        if not quiet:
            where = f"the Dask scheduler at {args.scheduler}" if client else f"{args.workers or os.cpu_count()} local processes"
            print(f"sweep {args.scene}: {n_points} points on {where}; each is appended to "
                  f"{out / f'sweep_{label}.csv'} as it finishes", flush=True)
        table = sweep(scene, grid=grid, outputs=args.outputs.split(","), executor=client, t_end=t_end,
                      progress=not quiet, path=out / f"sweep_{label}", resume=args.resume,
                      workers=None if client else args.workers, **options)
    files = [out / f"sweep_{label}.csv", out / f"sweep_{label}.npz"]
    failed, partial = int(np.isin(table["status"], (-1, 4)).sum()), int((table["status"] == 2).sum())
    beyond = int((table["status"] == 3).sum())  # stopped where the model left its range
    record = out / f"sweep_{label}.json"  # the sweep's own (scene, t_end, options: --resume reads them)
    files.append(write_json(record, json.loads(record.read_text()) | asked | {
        "points": len(table["status"]), "failed": failed, "interrupted": partial, "out_of_range": beyond,
        "files": [f.name for f in files]}))
    if args.json:
        print(json.dumps({"scene": args.scene, "options": options, "points": len(table["status"]), "failed": failed,
                          "interrupted": partial, "out_of_range": beyond, "files": [str(f) for f in files],
                          "table": {k: np.asarray(v).tolist() for k, v in table.items()}}, indent=2, default=repr))
    elif not args.quiet:
        print(f"{len(table['status'])} points, {failed} failed or not run, {partial} interrupted with partial "
              f"results, {beyond} stopped out of their model's range; wrote " + ", ".join(str(f) for f in files))
    for i in np.flatnonzero(np.isin(table["status"], (-1, 4))):
        point = ", ".join(f"{k}={table[k][i]}" for k in grid)
        print(f"projeq: point {point} failed: {table['error'][i]}", file=sys.stderr)
    return 1 if failed or partial or beyond else 0


def _grid(scene, texts: list[str], fixed: dict, allow_large: bool) -> dict:
    """The swept axes of ``--grid`` (integer parameters rounded); ValueError for a parameter
    given twice or in both ``--grid`` and ``--set``, one that is no number (text, a switch, a
    tuple: every point would fail), repeated values, or more than
    :data:`MAX_POINTS` points without ``allow_large`` (refused before any array is made)."""
    from projeq.scenes import check_names, scene_parameters

    axes = [_grid_axis(text) for text in texts]
    sizes = [n for _, _, _, n in axes]
    if math.prod(sizes) > MAX_POINTS and not allow_large:
        raise ValueError(f"--grid: {math.prod(sizes):,} points ({' x '.join(map(str, sizes))}) is more than "
                         f"{MAX_POINTS:,}; give --allow-large to run them")
    defaults = {p.name: p.default for p in scene_parameters(scene)}
    grid = {}
    for text, (name, a, b, n) in zip(texts, axes):
        if name in grid:
            raise ValueError(f"--grid: {name} is given twice; give each parameter once")
        if name in fixed:
            raise ValueError(f"--grid: {name} is also given in --set; give it in one of them")
        check_names(scene, {name: None})
        if isinstance(defaults[name], (str, bool, tuple)):  # None: an optional number (rolling_disk's ecc)
            raise ValueError(f"--grid: {name} is not a number (its default is {defaults[name]!r}); a grid sweeps "
                             "numbers: give its value with --set, or sweep a numeric parameter")
        values = np.linspace(a, b, n)
        if type(defaults[name]) is int:
            values = values.round().astype(int)
        unique, counts = np.unique(values, return_counts=True)
        if (counts > 1).any():
            kind = f" after rounding to integers ({name} is an integer)" if values.dtype.kind == "i" else ""
            raise ValueError(f"--grid: {text!r} repeats the values {unique[counts > 1][:5].tolist()}{kind}; "
                             "each point would run more than once")
        grid[name] = values
    return grid


def _grid_axis(text: str) -> tuple[str, float, float, int]:
    """``name=a:b:n`` -> (name, a, b, n), the axis linspace(a, b, n); ValueError naming the bad part."""
    name, _, spec = text.partition("=")
    parts = spec.split(":")
    try:
        a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3 or n < 1 or not (np.isfinite(a) and np.isfinite(b)):
            raise ValueError
    except (ValueError, IndexError):
        raise ValueError(f"--grid: expected NAME=A:B:N (numbers A, B, a count N >= 1), got {text!r}") from None
    return name.strip(), a, b, n


@contextlib.contextmanager
def _closed(client):
    """The block, then ``client`` (a Dask client, or None) closed; a client whose scheduler was
    lost during the sweep cannot close cleanly, and that is no error of the sweep (its table is
    written, its lost points named): Dask's client logs only critical errors meanwhile, not the
    tracebacks of its attempts to reconnect."""
    quiet = [logging.getLogger(name) for name in ("distributed.client", "distributed.core")] if client else []
    levels = [logger.level for logger in quiet]
    for logger in quiet:  # a lost scheduler is said once per point it held, not as Dask's tracebacks
        logger.setLevel(logging.CRITICAL)
    try:
        yield
    finally:
        if client is not None:
            try:
                client.close(timeout=5)
            except Exception:  # noqa: BLE001, S110 - the connection is gone already
                pass
        for logger, level in zip(quiet, levels):
            logger.setLevel(level)


def _dask_client(address: str, timeout: float):
    """A connected dask.distributed.Client; ValueError when Dask is missing or unreachable."""
    try:
        from dask.distributed import Client
    except ImportError:
        raise ValueError('--scheduler: Dask is not installed (pip install "projeq[dask]")') from None
    try:
        return Client(address, timeout=f"{timeout}s")
    except (OSError, TimeoutError) as exc:
        raise ValueError(f"--scheduler: cannot reach the Dask scheduler at {address!r} ({exc}); nothing was run or written") from None

"""``projeq sweep SCENE --grid NAME=A:B:N ...``: a scene on a parameter grid, in parallel
local processes or on a Dask cluster; writes ``sweep_SCENE.csv`` and ``.npz``.

A point that failed or was interrupted makes the exit code 1 (the table is written).
"""

from __future__ import annotations

import sys

import numpy as np

from projeq.cli.options import output_directory, simulation_options


def sweep_arguments(parser) -> None:
    parser.add_argument("scene", help="scene name")
    parser.add_argument("--grid", action="append", default=[], metavar="NAME=A:B:N", required=True,
                        help="N values from A to B (linspace) for parameter NAME; repeat for a product grid")
    parser.add_argument("--outputs", default="energy_drift,t_reached",
                        help="comma-separated outputs: energy_drift, constraint_residual, t_reached, wall_time, nfev, q<i>, s_dot<i>")
    parser.add_argument("--scheduler", help="address of a Dask scheduler, e.g. tcp://host:8786 (default: local processes)")
    parser.add_argument("--scheduler-timeout", type=float, default=10.0, help="seconds to wait for the scheduler (default 10)")
    parser.add_argument("--workers", type=int, default=None, help="local worker processes (default: one per CPU)")
    simulation_options(parser)
    parser.set_defaults(execute=sweep_scene)


def sweep_scene(args) -> int:
    from projeq.scenes import check_names, get_scene, parse_settings, scene_parameters
    from projeq.simulation.sweep import process_pool, sweep

    scene = get_scene(args.scene)
    fixed = parse_settings(scene, args.set)
    defaults = {p.name: p.default for p in scene_parameters(scene)}
    grid = dict(_grid_axis(text) for text in args.grid)
    check_names(scene, grid)
    grid = {k: v.round().astype(int) if type(defaults[k]) is int else v for k, v in grid.items()}
    if fixed:
        grid.update({name: [value] for name, value in fixed.items()})
    if args.workers is not None and args.workers < 1:
        raise ValueError(f"--workers: expected a positive count, got {args.workers}")
    executor = (_dask_client(args.scheduler, args.scheduler_timeout) if args.scheduler
                else process_pool(args.workers))
    options = {"method": args.method, "rtol": args.rtol}
    with executor:  # closed (a Dask client disconnected) also when --out is refused
        out = output_directory(args.out)
        table = sweep(scene, grid=grid, outputs=args.outputs.split(","), executor=executor, t_end=args.t_end,
                      progress=not args.quiet, **options)
    files = table.save(out / f"sweep_{args.scene}")
    failed, partial = int((table["status"] == -1).sum()), int((table["status"] == 2).sum())
    if not args.quiet:
        print(f"{len(table['status'])} points, {failed} failed or not run, {partial} interrupted with partial results; "
              "wrote " + ", ".join(str(f) for f in files))
    for i in np.flatnonzero(table["status"] == -1):
        point = ", ".join(f"{k}={table[k][i]}" for k in grid)
        print(f"projeq: point {point} failed: {table['error'][i]}", file=sys.stderr)
    return 1 if failed or partial else 0


def _grid_axis(text: str) -> tuple[str, np.ndarray]:
    """``name=a:b:n`` -> (name, linspace(a, b, n)); ValueError naming the bad part."""
    name, _, spec = text.partition("=")
    parts = spec.split(":")
    try:
        a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3 or n < 1:
            raise ValueError
    except (ValueError, IndexError):
        raise ValueError(f"--grid: expected NAME=A:B:N (numbers A, B, a count N >= 1), got {text!r}") from None
    return name.strip(), np.linspace(a, b, n)


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

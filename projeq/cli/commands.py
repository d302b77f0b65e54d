"""The ``projeq`` command: argparse to library calls, no logic of its own.

``projeq list [SCENE]`` names the scenes (or one scene's parameters), ``projeq run [SCENE]``
simulates one (default: the spin-up beam), prints a summary and writes NPZ, CSV, PNG plots
and a ParaView VTU series to ``--out``; ``projeq sweep`` runs a parameter grid;
``compare``, ``bench`` and ``tradeoff`` hand their arguments to their modules.
Exit codes: 0 success, 1 failed or interrupted run (partial results written), 2 bad arguments.
"""

from __future__ import annotations

import argparse
import importlib
import sys
import time
from pathlib import Path

import numpy as np

#: Subcommands implemented by their own module's ``main(argv)``.
DELEGATED = {
    "compare": ("projeq.studies.compare", "compare derivations of one system (Projection Equation, Lagrange, Kane ...)"),
    "bench": ("projeq.studies.bench", "run the performance benchmarks"),
    "tradeoff": ("projeq.studies.tradeoff", "work-precision trade-off of integrators for a scene"),
}


class UsageError(ValueError):
    """Bad command-line arguments (exit code 2)."""


def _parser() -> argparse.ArgumentParser:
    from projeq.scenes import DEFAULT_SCENE

    parser = argparse.ArgumentParser(prog="projeq", description="Multibody dynamics by Bremer's Projection Equation.")
    sub = parser.add_subparsers(dest="command", required=True)
    listing = sub.add_parser("list", help="list the scenes, or one scene's parameters")
    listing.add_argument("scene", nargs="?", help="show this scene's parameters (units, defaults)")
    run = sub.add_parser("run", help="simulate a scene and write the results")
    run.add_argument("scene", nargs="?", default=DEFAULT_SCENE, help=f"scene name (default {DEFAULT_SCENE})")
    _simulation_options(run)
    run.add_argument("--atol", type=float, default=1e-11, help="absolute tolerance (default 1e-11)")
    sweep = sub.add_parser("sweep", help="simulate a scene on a parameter grid, in parallel")
    sweep.add_argument("scene", help="scene name")
    sweep.add_argument("--grid", action="append", default=[], metavar="NAME=A:B:N", required=True,
                       help="N values from A to B (linspace) for parameter NAME; repeat for a product grid")
    sweep.add_argument("--outputs", default="energy_drift,t_reached",
                       help="comma-separated outputs: energy_drift, constraint_residual, t_reached, wall_time, nfev, q<i>, s_dot<i>")
    sweep.add_argument("--scheduler", help="address of a Dask scheduler, e.g. tcp://host:8786 (default: local processes)")
    sweep.add_argument("--scheduler-timeout", type=float, default=10.0, help="seconds to wait for the scheduler (default 10)")
    sweep.add_argument("--workers", type=int, default=None, help="local worker processes (default: one per CPU)")
    _simulation_options(sweep)
    for name, (_, text) in DELEGATED.items():
        delegated = sub.add_parser(name, help=text, add_help=False)
        delegated.add_argument("argv", nargs=argparse.REMAINDER, help=f"arguments of projeq {name} (see projeq {name} --help)")
    return parser


def _simulation_options(parser) -> None:
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override a scene parameter (see projeq list SCENE); repeatable")
    parser.add_argument("--t-end", type=float, default=None, help="end time in s (default: the scene's)")
    parser.add_argument("--method", default="DOP853", help="solve_ivp method (default DOP853)")
    parser.add_argument("--rtol", type=float, default=1e-9, help="relative tolerance (default 1e-9)")
    parser.add_argument("--out", default="projeq-out", help="output directory (default ./projeq-out)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar, print nothing but errors")


def _output_directory(text: str) -> Path:
    """The output directory, created; UsageError when it cannot be written."""
    out = Path(text)
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".projeq-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise UsageError(f"--out: cannot write to directory {text!r}: {exc.strerror or exc}") from None
    return out


def _write(result, out: Path, name: str) -> list[Path]:
    npz, csv = out / f"{name}.npz", out / f"{name}.csv"
    result.save(npz)
    columns = ["t"] + [f"q{i}" for i in range(result.q.shape[1])] + [f"s_dot{i}" for i in range(result.s_dot.shape[1])]
    table = np.column_stack((result.t, result.q, result.s_dot, result.kinetic, result.potential))
    np.savetxt(csv, table, delimiter=",", header=",".join(columns + ["kinetic", "potential"]), comments="")
    return [npz, csv]


def _plots(result, system, scene, out: Path, name: str) -> list[Path]:
    """PNG figures: time history, drift, the path in the plane, beam tip deflections."""
    from projeq.simulation import plots

    figures = {"history": plots.time_history(result), "drift": plots.drift(result)}
    if scene.plane:
        figures["path"] = plots.planar_trajectory(result, *scene.plane)
    for sub_name, sub in zip(system.names, system.subsystems):
        if sub.deforms:
            figures[f"tip_{sub_name}"] = plots.tip_deflection(result, sub)
    paths = []
    for suffix, fig in figures.items():
        paths.append(out / f"{name}_{suffix}.png")
        fig.savefig(paths[-1], dpi=100)
    return paths


def _progress_bar(t_start: float, t_end: float, quiet: bool):
    """A tqdm bar over simulated time (silent when quiet or not on a terminal)."""
    from tqdm import tqdm

    return tqdm(total=t_end - t_start, unit="s", unit_scale=True, disable=True if quiet else None,
                bar_format="{l_bar}{bar}| t = {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]")


def _run(args) -> int:
    from projeq.scenes import get_scene, parse_settings
    from projeq.simulation.driver import SimulationError, simulate

    scene = get_scene(args.scene)
    system = scene.build(**parse_settings(scene, args.set))
    t_end = scene.t_end if args.t_end is None else args.t_end
    out = _output_directory(args.out)
    cpu = time.process_time()
    with _progress_bar(0.0, t_end, args.quiet) as bar:
        try:
            # 100 segments: Ctrl-C loses at most the current 1 % of the run; each segment restarts the
            # step size (measured: +3 % evaluations for chain(5) over 10 s, +10 % for spin_up_beam over 2 s)
            result, code = simulate(system, t_end, method=args.method, rtol=args.rtol, atol=args.atol, n_points=201,
                                    n_segments=100, progress=lambda t: bar.update(t - bar.n)), 0
        except SimulationError as exc:
            print(f"projeq: {exc}", file=sys.stderr)
            result, code = exc.result, 1
    cpu = time.process_time() - cpu
    if result.status == 2:
        reached = result.t[-1] if len(result.t) else 0.0
        print(f"projeq: interrupted at t = {reached:.6g} s; the results up to there are written", file=sys.stderr)
        code = 1
    files = _write(result, out, args.scene)
    if len(result.t) > 1:
        from projeq.simulation.export import write_vtu_series

        files += _plots(result, system, scene, out, args.scene)
        files.append(write_vtu_series(result, out / "paraview", name=args.scene))
    if not args.quiet:
        _summary(args.scene, system, result, files, cpu)
    return code


def _summary(name, system, result, files, cpu: float) -> None:
    print(f"scene {name}: {len(system.names)} subsystems, n_q = {system.n_q}, n_s = {system.n_s}")
    if not len(result.t):
        print("no time step completed")
        return
    print(f"t = {result.t[-1]:.6g} s, {result.nfev} evaluations, {cpu:.3g} s CPU, {result.wall_time:.3g} s wall ({result.method})")
    print(f"final q     = {np.array2string(result.q[-1], precision=6)}")
    print(f"final s_dot = {np.array2string(result.s_dot[-1], precision=6)}")
    change = result.energy[-1] - result.energy[0]
    print(f"energy {result.energy[0]:.10g} J -> {result.energy[-1]:.10g} J (change {change:.3g} J, "
          f"{result.energy_drift:.2e} of the energy scale; not conserved where a motion is prescribed)")
    for sub_name, sub in zip(system.names, system.subsystems):
        if sub.deforms:
            tip = sub.deflection(result, sub.length)[-1]
            print(f"{sub_name}: tip displacement (u, v, w) = {np.array2string(tip, precision=5)} m at t = {result.t[-1]:.6g} s")
    if system.n_c:
        print(f"constraint drift: largest velocity-constraint residual {np.abs(result.constraint_residual).max():.2e}")
    print("wrote " + ", ".join(str(f) for f in files))


def _grid_axis(text: str) -> tuple[str, np.ndarray]:
    """``name=a:b:n`` -> (name, linspace(a, b, n)); UsageError naming the bad part."""
    name, _, spec = text.partition("=")
    parts = spec.split(":")
    try:
        a, b, n = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3 or n < 1:
            raise ValueError
    except (ValueError, IndexError):
        raise UsageError(f"--grid: expected NAME=A:B:N (numbers A, B, a count N >= 1), got {text!r}") from None
    return name.strip(), np.linspace(a, b, n)


def _sweep(args) -> int:
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
        raise UsageError(f"--workers: expected a positive count, got {args.workers}")
    executor = (_dask_client(args.scheduler, args.scheduler_timeout) if args.scheduler
                else process_pool(args.workers))
    options = {"method": args.method, "rtol": args.rtol}
    with executor:  # closed (a Dask client disconnected) also when --out is refused
        out = _output_directory(args.out)
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


def _dask_client(address: str, timeout: float):
    """A connected dask.distributed.Client; UsageError when Dask is missing or unreachable."""
    try:
        from dask.distributed import Client
    except ImportError:
        raise UsageError('--scheduler: Dask is not installed (pip install "projeq[dask]")') from None
    try:
        return Client(address, timeout=f"{timeout}s")
    except (OSError, TimeoutError) as exc:
        raise UsageError(f"--scheduler: cannot reach the Dask scheduler at {address!r} ({exc}); nothing was run or written") from None


def _delegate(command: str, argv) -> int:
    module_name = DELEGATED[command][0]
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name != module_name:
            raise
        print(f"projeq {command}: not available in this version (no module {module_name})", file=sys.stderr)
        return 2
    return int(module.main(list(argv)) or 0)


def _list(args) -> int:
    from projeq.scenes import SCENES, get_scene, scene_parameters

    if args.scene is None:
        for name, scene in SCENES.items():
            print(f"{name:22s} {scene.description}")
        return 0
    scene = get_scene(args.scene)
    print(f"{args.scene}: {scene.description} (default t_end = {scene.t_end:g} s)")
    parameters = scene_parameters(scene)
    width = max((len(p.name) for p in parameters), default=0)
    for parameter in parameters:
        print(f"  {parameter.name:{width}s}  {parameter.default!r:24s} {parameter.unit}")
    return 0


def main(argv=None) -> int:
    """Entry point of the ``projeq`` command; returns the exit code."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv and argv[0] in DELEGATED:  # their own options, --help included, go to their main
        return _delegate(argv[0], argv[1:])
    args = _parser().parse_args(argv)
    commands = {"list": _list, "run": _run, "sweep": _sweep}
    try:
        return commands[args.command](args)
    except ValueError as exc:  # bad arguments, named: a scene, a parameter, a value, --out
        print(f"projeq {args.command}: {exc}", file=sys.stderr)
        return 2

"""``projeq list [SCENE]`` and ``projeq run [SCENE]``: the scenes, and one simulated.

``projeq run`` simulates a scene (default: the spin-up beam), prints a summary and writes
NPZ, CSV, PNG plots and a ParaView VTU series to ``--out``; a failed or interrupted run
(Ctrl-C or SIGTERM) writes its results up to where it stopped and exits 1. Each file is
written under a temporary name and renamed when complete, and ``--out`` is created again
if it was deleted during the run.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from projeq.cli.options import output_directory, simulation_options


def list_arguments(parser) -> None:
    parser.add_argument("scene", nargs="?", help="show this scene's parameters (units, defaults)")
    parser.set_defaults(execute=list_scenes)


def run_arguments(parser) -> None:
    from projeq.scenes import DEFAULT_SCENE

    parser.add_argument("scene", nargs="?", default=DEFAULT_SCENE, help=f"scene name (default {DEFAULT_SCENE})")
    simulation_options(parser)
    parser.add_argument("--atol", type=float, default=1e-11, help="absolute tolerance (default 1e-11)")
    parser.set_defaults(execute=run_scene)


def list_scenes(args) -> int:
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


def run_scene(args) -> int:
    from projeq.scenes import get_scene, parse_settings
    from projeq.simulation.driver import SimulationError, simulate

    scene = get_scene(args.scene)
    system = scene.build(**parse_settings(scene, args.set))
    t_end = scene.t_end if args.t_end is None else args.t_end
    out = output_directory(args.out)
    cpu = time.process_time()
    with _progress_bar(0.0, t_end, args.quiet) as bar:
        try:
            # 100 segments: Ctrl-C loses at most the current 1 % of the run; each segment restarts the
            # step size (measured: +3 % evaluations for chain(5) over 10 s, +10 % for spin_up_beam over 2 s)
            result, code = simulate(system, t_end, method=args.method, rtol=args.rtol, atol=args.atol, n_points=201,
                                    n_segments=100, events=list(scene.events) or None,
                                    progress=lambda t: bar.update(t - bar.n)), 0
        except SimulationError as exc:
            print(f"projeq: {exc}", file=sys.stderr)
            result, code = exc.result, 1
    cpu = time.process_time() - cpu
    for event, times in zip(scene.events, result.t_events):
        if len(times):
            print(f"projeq: stopped at t = {times[0]:.6g} s: {event.description}")
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


def _progress_bar(t_start: float, t_end: float, quiet: bool):
    """A tqdm bar over simulated time (silent when quiet or not on a terminal)."""
    from tqdm import tqdm

    return tqdm(total=t_end - t_start, unit="s", unit_scale=True, disable=True if quiet else None,
                bar_format="{l_bar}{bar}| t = {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]")


def _write(result, out: Path, name: str) -> list[Path]:
    """``name.npz`` (the Result) and ``name.csv`` (:class:`~projeq.studies.table.Table`: t, q,
    ṡ, kinetic and potential energy per output time), each under a temporary name renamed
    when complete; ``out`` is created again if it was deleted during the run."""
    from projeq.simulation.export import written_atomically
    from projeq.studies.table import Table

    out.mkdir(parents=True, exist_ok=True)
    npz, csv = out / f"{name}.npz", out / f"{name}.csv"
    result.save(npz)  # under a temporary name too
    columns = (["t"] + [f"q{i}" for i in range(result.q.shape[1])] + [f"s_dot{i}" for i in range(result.s_dot.shape[1])]
               + ["kinetic", "potential"])
    rows = np.column_stack((result.t, result.q, result.s_dot, result.kinetic, result.potential))
    with written_atomically(csv) as temporary:
        Table(columns, rows.tolist(), units={"t": "s", "kinetic": "J", "potential": "J"}).to_csv(temporary)
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
    from projeq.simulation.export import written_atomically

    paths = []
    for suffix, fig in figures.items():
        paths.append(out / f"{name}_{suffix}.png")
        with written_atomically(paths[-1]) as temporary:
            fig.savefig(temporary, dpi=100)
    return paths


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

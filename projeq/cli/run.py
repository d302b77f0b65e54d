"""``projeq list [SCENE]``, ``projeq run [SCENE]`` and ``projeq export RESULT.npz``: the
scenes, one simulated, and the ParaView files of a saved run.

``projeq run`` simulates a scene (default: the spin-up beam; a registered name or the
user's ``FILE.py:FUNCTION``, :func:`projeq.scenes.resolve_scene`), prints a summary (or,
with ``--json``, one JSON document) and writes into a folder of its own,
``--out/<scene>-<date>-<time>`` (never over an earlier run): ``run.json`` (the record:
scene, parameters, tolerances, method, evaluator, projeq version, command line, wall and
CPU time, status, files), ``<scene>.npz`` (the Result with the same record,
:meth:`projeq.Result.load`), ``<scene>.csv`` (named columns with units), a ParaView series
``paraview/<scene>.pvd`` and, with ``--plots``, PNG plots ``<scene>_history.png`` ... (a scene
given as ``FILE.py:FUNCTION`` is called ``FILE-FUNCTION``). The plots are asked for, not
written by default: matplotlib's import and drawing cost more CPU time (about 1.7 s) than the
rest of the default run's writing, in a run of about 1.7 s CPU in all (1.2 s of it Python's
start, the imports of numpy, scipy and projeq and numba's start; ``benchmarks/run_profile.py``
splits it). A failed or interrupted run (Ctrl-C or SIGTERM) writes its results up to where it
stopped and exits 1. ``--out`` is checked before the run, the
run's folder made when its results are written; each file is written under a temporary
name and renamed when complete.
"""

from __future__ import annotations

import json
import sys
import textwrap
import time
from contextlib import nullcontext
from dataclasses import replace
from datetime import datetime
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from projeq.cli.options import (json_option, jsonable, output_directory, plain, scene_label, simulate_options,
                                simulation_options)

WIDTH = 100  # columns of the text output


def list_arguments(parser) -> None:
    parser.add_argument("scene", nargs="?", help="show this scene's parameters (units, defaults)")
    json_option(parser)
    parser.set_defaults(execute=list_scenes)


def run_arguments(parser) -> None:
    from projeq.scenes import DEFAULT_SCENE

    parser.add_argument("scene", nargs="?", default=DEFAULT_SCENE,
                        help=f"scene name (default {DEFAULT_SCENE}) or FILE.py:FUNCTION, a function returning a System")
    simulation_options(parser)
    parser.add_argument("--plots", action="store_true",
                        help="also write PNG plots (time history, drift, path, beam tips; matplotlib, about 1.7 s CPU more)")
    parser.set_defaults(execute=run_scene)


def export_arguments(parser) -> None:
    parser.add_argument("result", help="the .npz of a run (projeq run writes one into its folder)")
    parser.add_argument("--out", default=None, help="output directory (default: paraview/ beside the .npz)")
    parser.add_argument("--stations", type=int, default=21, help="points along each beam's centre line (default 21)")
    parser.set_defaults(execute=export_result)


def export_result(args) -> int:
    """ParaView files of a saved run: its scene rebuilt from the run record in the .npz
    (:func:`projeq.simulation.export.system_of`)."""
    from projeq.simulation.export import write_vtu_series
    from projeq.simulation.result import Result

    path = Path(args.result)
    if not path.is_file():
        raise ValueError(f"result: no file {args.result!r}")
    if args.stations < 2:
        raise ValueError(f"--stations: expected at least 2 points, got {args.stations}")
    result = Result.load(path)  # a file that is no Result is refused before the directory is made
    out = output_directory(args.out or str(path.parent / "paraview"))
    print(f"wrote {write_vtu_series(result, out, name=path.stem, stations=args.stations)}")
    return 0


def list_scenes(args) -> int:
    from projeq.scenes import SCENES, resolve_scene, scene_parameters

    if args.scene is None:
        if args.json:
            print(json.dumps({name: {"description": s.description, "t_end": s.t_end} for name, s in SCENES.items()}, indent=2))
            return 0
        for name, scene in SCENES.items():
            print(textwrap.shorten(f"{name:22s} {scene.description}", WIDTH))
        return 0
    scene = resolve_scene(args.scene)
    parameters = scene_parameters(scene)
    if args.json:
        print(json.dumps({"scene": args.scene, "description": scene.description, "t_end": scene.t_end,
                          "parameters": [p._asdict() for p in parameters]}, indent=2, default=jsonable))
        return 0
    print(f"{args.scene}: {scene.description} (default t_end = {scene.t_end:g} s)")
    width = max((len(p.name) for p in parameters), default=0)
    lines = [f"  {p.name:{width}s}  {p.default!r:24s} {p.unit}" for p in parameters]
    column = max(map(len, lines), default=0) + 2  # the descriptions' column, or below each line (6)
    column = column if WIDTH - column >= 30 else 6
    for line, parameter in zip(lines, parameters):
        if not parameter.description:
            print(line)
            continue
        first = f"{line:{column}s}" if len(line) < column else line + "\n" + " " * column
        print(textwrap.fill(plain(parameter.description), WIDTH, initial_indent=first,
                            subsequent_indent=" " * column))
    return 0


def run_scene(args) -> int:
    from projeq.cli.commands import one_line_warnings

    with one_line_warnings("projeq run") as raised:
        return _run_scene(args, raised)


def _run_scene(args, raised: list) -> int:
    """``projeq run``; ``raised``: the warnings of the run so far, printed as they come and
    recorded in run.json (``warnings``)."""
    from projeq.cli.commands import imports_frozen

    with imports_frozen():
        from projeq.scenes import parse_settings, resolve_scene
        from projeq.simulation.driver import SimulationError, simulate
        from projeq.simulation.result import OUT_OF_RANGE
        from projeq.system import check_model
    scene = resolve_scene(args.scene)
    overrides = parse_settings(scene, args.set)
    system = scene.build(**overrides)
    t_end = scene.t_end if args.t_end is None else args.t_end
    options = simulate_options(args, scene)
    check_model(system)  # as simulate does first: a FILE.py:FUNCTION returning no model is refused by name
    with imports_frozen():  # the evaluator simulate takes (cached by the model): numba's import for a compiled one
        system.evaluator(options.get("evaluator"))
    record = run_record(args, scene, overrides, t_end, options)
    label, parent = scene_label(args.scene), output_directory(args.out)
    cpu, wall = time.process_time(), time.perf_counter()
    with _progress_bar(0.0, t_end, args.quiet or args.json) as bar:
        try:
            # simulate's segments (20): Ctrl-C loses at most the current 5 % of the run; each segment
            # restarts the step size and an implicit method's Jacobian (100 segments cost the spin-up
            # beam by Radau 1.4× the CPU time of 20)
            result = simulate(system, t_end, n_points=201, events=list(scene.events) or None,
                              progress=lambda t: bar.update(t - bar.n), **options)
            code = _exit_code(result.status)
        except SimulationError as exc:
            print(f"projeq: {exc}", file=sys.stderr)
            result = exc.result
            code = _exit_code(result.status) or 1  # a failure, whatever the status of the rows kept
    record.update(cpu_time=time.process_time() - cpu, wall_time=time.perf_counter() - wall,
                  method=result.method or record["method"])  # the integrator simulate used
    result = replace(result, metadata=dict(record))
    notes = []
    for event, times in zip(scene.events, result.t_events):
        if len(times):
            notes.append(f"stopped at t = {times[0]:.6g} s: {event.description}")
    if result.status == 2:
        reached = result.t[-1] if len(result.t) else 0.0
        print(f"projeq: interrupted at t = {reached:.6g} s; the results up to there are written", file=sys.stderr)
    elif result.status == OUT_OF_RANGE:
        print(f"projeq: {result.message}; the results up to there are written", file=sys.stderr)
    out = run_directory(parent, label)
    try:
        files = _write_all(result, system, scene, out, label, args.plots)
        record.update(_outcome(system, result, code, notes), warnings=list(raised),
                      files=[str(f.relative_to(out)) for f in files])
        files.append(write_json(out / "run.json", record))
    except OSError:  # nothing half-written: the folder goes too if no file in it is complete
        if not any(out.rglob("*")):
            out.rmdir()
        raise
    if args.json:
        print(json.dumps(record | {"folder": str(out)}, indent=2, default=jsonable))
        return code
    for note in notes:  # also when quiet: why the run ended early
        print(f"projeq: {note}")
    if not args.quiet:
        _summary(args.scene, system, result, record, out, files)
        if not args.plots:
            print("(PNG plots of the run: add --plots)")
    return code


def _write_all(result, system, scene, out: Path, label: str, plots: bool) -> list[Path]:
    """The NPZ, the CSV and, when there is more than one row, the ParaView series and (if
    ``plots``) the plots."""
    files = _write(result, out, label)
    if len(result.t) > 1:
        from projeq.simulation.export import write_vtu_series

        files += _plots(result, system, scene, out, label) if plots else []
        files.append(write_vtu_series(result, out / "paraview", name=label))
    return files


def run_record(args, scene, overrides: dict, t_end: float, options: dict) -> dict:
    """What a run was asked to do: scene, all its parameters (defaults and overrides), end
    time, integrator, tolerances and evaluator (``options``; ``"default"``: simulate's own,
    the integrator then named after the run), projeq version, command line, start time."""
    from projeq import __version__
    from projeq.scenes import scene_parameters

    return {
        "scene": args.scene, "description": scene.description,
        "parameters": {p.name: overrides.get(p.name, p.default) for p in scene_parameters(scene)},
        "t_end": t_end, "method": options.get("method", "default"),
        "tolerances": {k: options.get(k, "default") for k in ("rtol", "atol")},
        "evaluator": options.get("evaluator", "default"), "projeq_version": __version__,
        "command_line": ["projeq", *getattr(args, "argv", sys.argv[1:])],
        "started": datetime.now().astimezone().isoformat(timespec="seconds"),
    }


def run_directory(out: Path, label: str) -> Path:
    """A new folder ``out/<label>-<YYYYmmdd-HHMMSS>`` (``-2``, ``-3`` ... appended when one of
    that name exists: two runs in the same second), created here."""
    stamp = datetime.now().strftime("%Y%m%d-%H%M%S")
    for n in range(1, 1000):
        folder = out / (f"{label}-{stamp}" if n == 1 else f"{label}-{stamp}-{n}")
        try:
            folder.mkdir()
            return folder
        except FileExistsError:
            continue
    raise ValueError(f"--out: cannot make a new run folder in {str(out)!r} (999 runs of {label} at {stamp})")


def _exit_code(status: int) -> int:
    """``projeq run``'s exit code for a Result's status (:mod:`projeq.cli.commands`): 0 finished
    or stopped by an event, 1 failed or interrupted, 3 out of range, 4 non-finite state."""
    from projeq.cli import commands
    from projeq.simulation import result as ends

    return {ends.FINISHED: commands.OK, ends.STOPPED: commands.OK, ends.OUT_OF_RANGE: commands.OUT_OF_RANGE,
            ends.NON_FINITE: commands.NON_FINITE}.get(status, commands.FAILED)


NOT_CONSERVED = "not conserved: a prescribed motion or non-conservative forces"


def _outcome(system, result, code: int, notes: list) -> dict:
    """How the run ended, for run.json: status, exit code, message, time reached, evaluations,
    the final state by name and the energies: initial, final, their change (J) and, where the
    system conserves energy, the drift (:attr:`projeq.Result.energy_drift`); a driven or damped
    system's drift is no check of the integration (``NOT_CONSERVED`` in its place)."""
    from projeq.simulation.result import STATUSES

    outcome = {"status": STATUSES.get(result.status, str(result.status)), "exit_code": code,
               "message": "; ".join(notes) or result.message, "nfev": result.nfev}
    if len(result.t):
        q_names, s_names = result.column_names()
        conserved = _conserves_energy(system)
        outcome |= {"t_reached": float(result.t[-1]),
                    "final_q": dict(zip(q_names, result.q[-1].tolist())),
                    "final_s_dot": dict(zip(s_names, result.s_dot[-1].tolist())),
                    "energy": {"initial": float(result.energy[0]), "final": float(result.energy[-1]),
                               "change": float(result.energy[-1] - result.energy[0]),
                               "drift": result.energy_drift if conserved else NOT_CONSERVED,
                               "conserved": conserved}}
        if system.n_c:
            outcome["constraint_drift"] = float(np.abs(result.constraint_residual).max())
    return outcome


def _conserves_energy(system) -> bool:
    from projeq.simulation.integrators import conserves_energy

    return conserves_energy(system, system.q0, system.s_dot0)


def write_json(path: Path, document: dict) -> Path:
    """``document`` as indented JSON at ``path`` (complete or not at all), its folder made."""
    from projeq.simulation.export import written_atomically

    path.parent.mkdir(parents=True, exist_ok=True)
    with written_atomically(path) as temporary:
        temporary.write_text(json.dumps(document, indent=2, default=jsonable) + "\n")
    return path


def _progress_bar(t_start: float, t_end: float, quiet: bool):
    """A tqdm bar over simulated time on a terminal (stderr) unless quiet; else one that shows
    nothing, without tqdm (its import and the monitor thread that even a disabled bar starts)."""
    if quiet or (hasattr(sys.stderr, "isatty") and not sys.stderr.isatty()):  # as tqdm's disable=None
        return nullcontext(SimpleNamespace(n=0.0, update=lambda step: None))
    from tqdm import tqdm

    return tqdm(total=t_end - t_start, unit="s", unit_scale=True,
                bar_format="{l_bar}{bar}| t = {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]")


def _write(result, out: Path, name: str) -> list[Path]:
    """``name.npz`` (the Result with its record) and ``name.csv``
    (:class:`~projeq.studies.table.Table`: t, q and ṡ by name, each header with its unit, kinetic and
    potential energy per output time), each under a temporary name renamed when complete;
    ``out`` is created again if it was deleted during the run."""
    from projeq.simulation.export import written_atomically
    from projeq.studies.table import Table

    out.mkdir(parents=True, exist_ok=True)
    npz, csv = out / f"{name}.npz", out / f"{name}.csv"
    result.save(npz)  # under a temporary name too
    q_names, s_names = result.column_names(units=True)
    rows = np.column_stack((result.t, result.q, result.s_dot, result.kinetic, result.potential))
    with written_atomically(csv) as temporary:
        Table(["t (s)", *q_names, *s_names, "kinetic (J)", "potential (J)"], rows.tolist()).to_csv(temporary)
    return [npz, csv]


def _plots(result, system, scene, out: Path, name: str) -> list[Path]:
    """PNG figures: time history, drift, the path in the plane, beam tip deflections."""
    from projeq.simulation import plots
    from projeq.simulation.export import written_atomically

    figures = {"history": plots.grouped_history(result),
               "drift": plots.drift(result, energy_conserved=_conserves_energy(system))}
    if scene.plane:
        figures["path"] = plots.planar_trajectory(result, *scene.plane)
    for sub_name, sub in zip(system.names, system.subsystems):
        if sub.deforms:
            figures[f"tip_{sub_name}"] = plots.tip_deflection(result, sub)
    paths = []
    for suffix, fig in figures.items():
        paths.append(out / f"{name}_{suffix}.png")
        with written_atomically(paths[-1]) as temporary:
            fig.savefig(temporary, dpi=100)
    return paths


def _summary(name, system, result, record: dict, out: Path, files) -> None:
    print(f"scene {name}: {len(system.names)} subsystems, n_q = {system.n_q}, n_s = {system.n_s}")
    if not len(result.t):
        print("no time step completed")
        return
    print(f"t = {result.t[-1]:.6g} s, {result.nfev} evaluations, {record['cpu_time']:.3g} s CPU, "
          f"{record['wall_time']:.3g} s wall ({result.method})")  # both of the whole simulate call
    for label, values, named in (("final q", result.q, result.coordinates),
                                 ("final s_dot", result.s_dot, result.velocities)):
        print(_named_values(label, values, named))
    change = result.energy[-1] - result.energy[0]
    print(f"energy {result.energy[0]:.10g} J -> {result.energy[-1]:.10g} J (change {change:.3g} J, "
          f"{result.energy_drift:.2e} of the energy scale)")
    if not record["energy"]["conserved"]:
        print("    (not conserved here: a prescribed motion or non-conservative forces)")
    for sub_name, sub in zip(system.names, system.subsystems):
        if sub.deforms:
            tip = sub.deflection(result, sub.length)[-1]
            print(f"{sub_name}: tip displacement (u, v, w) = {np.array2string(tip, precision=5)} m at t = {result.t[-1]:.6g} s")
    if system.n_c:
        print(f"constraint drift: largest velocity-constraint residual {record['constraint_drift']:.2e}")
    print(f"wrote {out}/: " + ", ".join(str(Path(f).relative_to(out)) for f in files))


def _named_values(label: str, values, named) -> str:
    """``label: name = value unit, ...`` of the last row, wrapped to :data:`WIDTH` columns,
    without the entries that are zero throughout the run (counted at the end)."""
    names = [name for name, _ in named] or [f"[{i}]" for i in range(values.shape[1])]
    units = [unit for _, unit in named] or [""] * values.shape[1]
    moving = np.any(values != 0.0, axis=0)
    parts = [f"{n} = {v:.6g}{' ' + u if u else ''}" for n, v, u, m in zip(names, values[-1], units, moving) if m]
    if not moving.all():
        parts.append(f"({int((~moving).sum())} zero throughout: not shown)")
    text = ", ".join(part.replace(" ", "\xa0") for part in parts) or "(none)"  # break between entries only
    return textwrap.fill(text, WIDTH, initial_indent=f"{label}: ", subsequent_indent="    ").replace("\xa0", " ")

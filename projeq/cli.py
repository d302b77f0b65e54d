"""The ``projeq`` command: argparse to library calls, no logic of its own.

``projeq run [SCENE]`` simulates a scene (default: the spin-up beam), prints a summary and
writes the result (NPZ, CSV and a ParaView VTU series) to ``--out``. ``projeq list`` names
the scenes.
Exit codes: 0 success, 1 failed run (partial results written), 2 bad arguments.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np


def _parser() -> argparse.ArgumentParser:
    from projeq.scenes import DEFAULT_SCENE

    parser = argparse.ArgumentParser(prog="projeq", description="Multibody dynamics by Bremer's Projection Equation.")
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="list the scenes")
    run = sub.add_parser("run", help="simulate a scene and write the results")
    run.add_argument("scene", nargs="?", default=DEFAULT_SCENE, help=f"scene name (default {DEFAULT_SCENE})")
    run.add_argument("--t-end", type=float, default=None, help="end time in s (default: the scene's)")
    run.add_argument("--method", default="DOP853", help="solve_ivp method (default DOP853)")
    run.add_argument("--rtol", type=float, default=1e-9, help="relative tolerance (default 1e-9)")
    run.add_argument("--atol", type=float, default=1e-11, help="absolute tolerance (default 1e-11)")
    run.add_argument("--out", default="projeq-out", help="output directory (default ./projeq-out)")
    run.add_argument("--quiet", action="store_true", help="print nothing but errors")
    return parser


def _write(result, out: Path, name: str) -> list[Path]:
    out.mkdir(parents=True, exist_ok=True)
    npz, csv = out / f"{name}.npz", out / f"{name}.csv"
    result.save(npz)
    columns = ["t"] + [f"q{i}" for i in range(result.q.shape[1])] + [f"s_dot{i}" for i in range(result.s_dot.shape[1])]
    table = np.column_stack((result.t, result.q, result.s_dot, result.kinetic, result.potential))
    np.savetxt(csv, table, delimiter=",", header=",".join(columns + ["kinetic", "potential"]), comments="")
    return [npz, csv]


def _run(args) -> int:
    from projeq.scenes import SCENES
    from projeq.simulation import SimulationError, simulate

    if args.scene not in SCENES:
        print(f"projeq: unknown scene {args.scene!r}; known scenes: {', '.join(SCENES)}", file=sys.stderr)
        return 2
    scene = SCENES[args.scene]
    system = scene.build()
    t_end = scene.t_end if args.t_end is None else args.t_end
    try:
        result, code = simulate(system, t_end, method=args.method, rtol=args.rtol, atol=args.atol, n_points=201), 0
    except SimulationError as exc:
        print(f"projeq: {exc}", file=sys.stderr)
        result, code = exc.result, 1
    except ValueError as exc:
        print(f"projeq: {exc}", file=sys.stderr)
        return 2
    files = _write(result, Path(args.out), args.scene)
    if len(result.t):
        from projeq.export import write_vtu_series

        files.append(write_vtu_series(result, Path(args.out) / "paraview", name=args.scene))
    if not args.quiet:
        print(f"scene {args.scene}: {len(system.names)} subsystems, n_q = {system.n_q}, n_s = {system.n_s}")
        print(f"t = {result.t[-1]:.6g} s, {result.nfev} evaluations, {result.wall_time:.3g} s CPU ({result.method})")
        print(f"final q     = {np.array2string(result.q[-1], precision=6)}")
        print(f"final s_dot = {np.array2string(result.s_dot[-1], precision=6)}")
        change = result.energy[-1] - result.energy[0]
        print(f"energy {result.energy[0]:.10g} J -> {result.energy[-1]:.10g} J (change {change:.3g} J, "
              f"{result.energy_drift:.2e} of the energy scale; not conserved where a motion is prescribed)")
        for name, sub in zip(system.names, system.subsystems):
            if hasattr(sub, "deflection"):
                tip = sub.deflection(result, sub.length)[-1]
                print(f"{name}: tip displacement (u, v, w) = {np.array2string(tip, precision=5)} m at t = {result.t[-1]:.6g} s")
        if system.n_c:
            print(f"largest constraint residual {np.abs(result.constraint_residual).max():.2e}")
        print("wrote " + ", ".join(str(f) for f in files))
    return code


def main(argv=None) -> int:
    """Entry point of the ``projeq`` command."""
    args = _parser().parse_args(argv)
    if args.command == "list":
        from projeq.scenes import SCENES

        for name, scene in SCENES.items():
            print(f"{name:18s} {scene.description}")
        return 0
    return _run(args)

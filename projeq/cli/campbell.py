"""``projeq campbell SCENE``: the Campbell diagram of a rotating scene — the frequencies of its
modes against the rotation speed Ω, each mode followed by its shape through crossings and
veering and labelled (flapwise / lead-lag for a blade on a hub, forward / backward whirl for a
shaft spinning about its own axis), with the critical speeds where a branch crosses an engine
order k Ω (:func:`projeq.analysis.campbell.campbell`). The scene is built at each speed with
its speed parameter (``--parameter``, default ``omega``) set and linearised about its steady
rotation. Writes SCENE_campbell.csv (Ω, each branch's frequency and damping ratio, and a
whirl's frequency seen from the inertial frame), SCENE_critical_speeds.csv and
SCENE_campbell.png into --out; prints the table.

Frequencies are in rad/s in the frame of the scene's coordinates (co-rotating for
rotating_blade and spinning_beam). Example: ``projeq campbell rotating_blade --set
hub_radius=0.5 --speeds 0:8:17``."""

from __future__ import annotations

import argparse

import numpy as np

from projeq.cli.options import output_directory, plain, scene_label, scene_settings_option


def campbell_arguments(parser) -> None:
    parser.description = plain(__doc__)
    parser.formatter_class = argparse.RawDescriptionHelpFormatter
    parser.add_argument("scene", help="a scene with a rotation-speed parameter (rotating_blade, spinning_beam) "
                                      "or FILE.py:FUNCTION")
    parser.add_argument("--speeds", default="0:8:17", metavar="START:STOP:COUNT or S,S,...",
                        help="rotation speeds in rad/s: COUNT evenly spaced from START to STOP, or a list "
                             "(default 0:8:17)")
    parser.add_argument("--parameter", default="omega", help="the scene parameter that is the speed (default omega)")
    parser.add_argument("--orders", default="1,2,3", metavar="K,K,...",
                        help="engine orders k of the lines k Ω (default 1,2,3; 0: where a frequency passes through "
                             "zero, a shaft's forward-whirl critical speed)")
    parser.add_argument("--modes", type=int, default=6, help="how many of the lowest modes to show (default 6)")
    scene_settings_option(parser)
    parser.add_argument("--out", default="projeq-out", help="output directory (default ./projeq-out)")
    parser.add_argument("--quiet", action="store_true", help="print nothing but errors")
    parser.set_defaults(execute=run_campbell)


def run_campbell(args) -> int:
    from projeq.analysis.campbell import campbell
    from projeq.scenes import parse_settings, resolve_scene
    from projeq.scenes.parameters import check_names

    scene = resolve_scene(args.scene)
    overrides = parse_settings(scene, args.set)
    check_names(scene, {args.parameter: None})
    if args.parameter in overrides:
        raise ValueError(f"--set: {args.parameter} is the swept speed (--parameter); give it by --speeds")
    speeds, orders = parse_speeds(args.speeds), _numbers("--orders", args.orders)
    out = output_directory(args.out)
    diagram = campbell(lambda speed: scene.build(**overrides, **{args.parameter: speed}), speeds, orders=orders,
                       n_modes=args.modes)
    files = _write(diagram, out, scene_label(args.scene))
    if not args.quiet:
        print(f"{args.scene}: frequencies (rad/s) against {args.parameter} (rad/s)")
        print(diagram.table())
        for c in diagram.critical_speeds:
            print(f"critical speed: {c.mode} crosses {c.order}Ω at {args.parameter} = {c.speed:.6g} rad/s "
                  f"(frequency {c.frequency:.6g} rad/s)")
        print("wrote " + ", ".join(str(f) for f in files))
    return 0


def parse_speeds(text: str) -> np.ndarray:
    """``START:STOP:COUNT`` (COUNT ≥ 2 evenly spaced values) or ``S,S,...``; ValueError naming
    --speeds (:func:`projeq.analysis.campbell.campbell` checks that they increase)."""
    if ":" not in text:
        return np.array(_numbers("--speeds", text, float))
    parts = text.split(":")
    try:
        start, stop, count = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3 or count < 2 or not np.isfinite([start, stop]).all():
            raise ValueError
    except (ValueError, IndexError):
        raise ValueError(f"--speeds: expected START:STOP:COUNT with COUNT >= 2, or a list S,S,..., "
                         f"got {text!r}") from None
    return np.linspace(start, stop, count)


def _numbers(option: str, text: str, kind=int) -> list:
    try:
        return [kind(part) for part in text.split(",")]
    except ValueError:
        raise ValueError(f"{option}: expected comma-separated numbers, got {text!r}") from None


def _write(diagram, out, label: str) -> list:
    """The two CSV files and the PNG, each under a temporary name renamed when complete."""
    from projeq.simulation.export import written_atomically

    paths = [out / f"{label}_campbell.csv", out / f"{label}_critical_speeds.csv", out / f"{label}_campbell.png"]
    for path, write in zip(paths, (diagram.write_csv, diagram.write_critical_speeds,
                                   lambda file: diagram.plot().savefig(file, dpi=100))):
        with written_atomically(path) as temporary:
            write(temporary)
    return paths

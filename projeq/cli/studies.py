"""``projeq compare NAME`` and ``projeq tradeoff SCENE``: the studies of
:mod:`projeq.studies.compare` and :mod:`projeq.studies.tradeoff` from the command line.

``projeq compare`` prints the table of formulations of one system, built in or the System of a
scene or of a user's ``FILE.py:FUNCTION`` (its numeric and symbolic Projection Equation), and
writes it as CSV with ``--csv``; ``projeq tradeoff`` runs a work-precision study and writes its CSV and PNG
plot, exit code 1 when its reference run failed or Ctrl-C stopped it (the rows finished so
far are written).
"""

from __future__ import annotations

import json
import os
import sys

import numpy as np

from projeq.cli.options import json_option, jsonable, number, output_directory, output_file, scene_settings_option
from projeq.studies.compare import COMPARISONS, TEXT_WIDTH, compare
from projeq.studies.effort import DERIVATION_REPEATS
from projeq.studies.tradeoff import METHODS, QUICK_TOLERANCES, format_table, get_study, plot, save_csv, tradeoff
from projeq.studies.tradeoff_studies import STUDIES


def compare_arguments(parser) -> None:
    parser.add_argument("name", help=f"one of: {', '.join(sorted(COMPARISONS))}; or a scene or "
                                     "FILE.py:FUNCTION returning a System (its numeric and symbolic "
                                     "Projection Equation)")
    parser.add_argument("--csv", metavar="PATH", help="also write the table as CSV")
    parser.add_argument("--no-simulate", action="store_true", help="derive and check only")
    parser.add_argument("--t-end", type=float, default=None, help="simulated time (s)")
    parser.add_argument("--formulation", action="append", help="restrict to these rows (repeatable)")
    parser.add_argument("--repeats", type=int, default=DERIVATION_REPEATS,
                        help=f"derivations per row, median reported (default {DERIVATION_REPEATS})")
    json_option(parser)
    parser.set_defaults(execute=compare_formulations)


def compare_formulations(args) -> int:
    if args.csv:
        output_file(args.csv, "--csv")
    system = args.name
    if args.name not in COMPARISONS:  # a scene's System: its numeric and symbolic Projection Equation
        from projeq.scenes import resolve_scene

        system = resolve_scene(args.name).build()
    table = compare(system, args.formulation, simulate=not args.no_simulate, t_end=args.t_end,
                    repeats=args.repeats)
    if args.json:
        print(json.dumps({"name": table.name, "rows": table.rows, "effort": table.effort, "claims": table.claims},
                         indent=2, default=jsonable))
    else:
        print(table.format())
    if args.csv:
        table.to_csv(args.csv)
    return 0


def tradeoff_arguments(parser) -> None:
    parser.add_argument("scene", help=f"one of: {', '.join(STUDIES)}")
    parser.add_argument("--quick", action="store_true", help=f"rtol {', '.join(f'{r:g}' for r in QUICK_TOLERANCES)}, "
                        "fewer knobs, a shorter end time")
    parser.add_argument("--methods", nargs="+", metavar="M", help=f"integrators (default all: {' '.join(METHODS)})")
    parser.add_argument("--tolerances", nargs="+", metavar="RTOL", help="relative tolerances (default 1e-3 ... 1e-12)")
    parser.add_argument("--knobs", nargs="+", metavar="KNOB", help="model knobs by label (default: all of the study)")
    scene_settings_option(parser)
    parser.add_argument("--t-end", help="simulated time in s (default: the study's)")
    parser.add_argument("--timeout", default="120", help="CPU seconds allowed per run (default 120)")
    parser.add_argument("--out", default="projeq-tradeoff", help="output directory (default ./projeq-tradeoff)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar and no table")
    parser.add_argument("--wide", action="store_true", help=f"print the table uncut (default: {TEXT_WIDTH} columns)")
    parser.set_defaults(execute=tradeoff_study)


def tradeoff_study(args) -> int:
    os.environ.setdefault("PROJEQ_COMPILE", "now")  # compiled from the first call: the study times the compiled path
    options = _tradeoff_options(args)
    out = options["out"]
    table = tradeoff(**options)
    files = [save_csv(table, out / f"tradeoff_{args.scene}.csv")]
    if np.any(table["failure"] == ""):
        files.append(out / f"tradeoff_{args.scene}.png")
        plot(table).savefig(files[-1], dpi=110)
    if not args.quiet:
        print(format_table(table, width=None if args.wide else TEXT_WIDTH))
    print(f"wrote {', '.join(str(f) for f in files)}")
    if not table["complete"]:
        print(f"projeq tradeoff: interrupted after {len(table['method'])} settings; those are written", file=sys.stderr)
        return 1
    return 0


def _tradeoff_options(args) -> dict:
    """Keyword arguments of :func:`projeq.studies.tradeoff.tradeoff` from the command line
    (ValueError naming the option)."""
    from projeq.scenes import get_scene, parse_settings

    study = get_study(args.scene)
    timeout = number("--timeout", args.timeout)
    if not timeout > 0:
        raise ValueError(f"--timeout: expected a positive number of seconds, got {args.timeout!r}")
    return {
        "scene": study, "quick": args.quick, "methods": args.methods or METHODS,
        "tolerances": None if args.tolerances is None else [number("--tolerances", r) for r in args.tolerances],
        "knobs": args.knobs, "t_end": None if args.t_end is None else number("--t-end", args.t_end),
        "overrides": parse_settings(get_scene(study.scene), args.set), "timeout": timeout,
        "out": output_directory(args.out), "progress": not args.quiet,
    }

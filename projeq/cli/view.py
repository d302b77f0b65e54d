"""``projeq view RUN``: the motion of a saved run as one HTML page that plays it offline
(three.js inlined, no server), or with ``--out FILE.gif`` / ``FILE.mp4`` a movie.

RUN is a run folder written by ``projeq run`` (its ``run.json`` names the ``.npz``) or an ``.npz``
written by :meth:`projeq.Result.save`; the model is the scene its run record names, built again
with the recorded parameters (:func:`projeq.simulation.export.system_of`), as ``projeq export``
does. The page: :func:`projeq.simulation.animation.write_html`.
"""

from __future__ import annotations

import json
from pathlib import Path

from projeq.cli.options import output_file


def view_arguments(parser) -> None:
    parser.add_argument("run", help="a run folder of projeq run, or the .npz of a run (Result.save)")
    parser.add_argument("--out", default=None,
                        help="the file to write: .html (default: RUN's <scene>.html beside its .npz), "
                             ".gif or .mp4")
    parser.add_argument("--stations", type=int, default=21,
                        help="points along each beam's centre line (default 21)")
    parser.add_argument("--fps", type=int, default=25,
                        help="frames per second of simulated time of a .gif/.mp4 (default 25)")
    parser.set_defaults(execute=view_run)


def run_npz(text: str) -> Path:
    """The ``.npz`` of RUN: the file itself, or the one a run folder's ``run.json`` lists (else
    the folder's only ``.npz``); ValueError naming ``run`` when there is none."""
    path = Path(text)
    if path.is_file():
        return path
    if not path.is_dir():
        raise ValueError(f"run: no run folder or .npz file {text!r}")
    record = path / "run.json"
    listed = json.loads(record.read_text()).get("files", []) if record.is_file() else []
    npz = [path / f for f in listed if f.endswith(".npz")] or sorted(path.glob("*.npz"))
    if len(npz) != 1:
        raise ValueError(f"run: {text!r} holds {len(npz)} .npz files ({[p.name for p in npz]}); "
                         "expected the one of a projeq run: name it")
    return npz[0]


def view_run(args) -> int:
    from projeq.simulation.animation import SUFFIXES, animate
    from projeq.simulation.result import Result

    npz = run_npz(args.run)
    if args.stations < 2:
        raise ValueError(f"--stations: expected at least 2 points, got {args.stations}")
    out = Path(args.out) if args.out else npz.with_suffix(".html")
    if out.suffix.lower() not in SUFFIXES:
        raise ValueError(f"--out: expected a file ending in {', '.join(SUFFIXES)}, got {str(out)!r}")
    output_file(str(out), "--out")
    result = Result.load(npz)
    options = {} if out.suffix.lower() == ".html" else {"fps": args.fps}
    print(f"wrote {animate(result, out, stations=args.stations, **options)}")
    return 0

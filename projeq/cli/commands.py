"""The ``projeq`` command: one parser for every subcommand and one exit-code convention.

Each subcommand lives in a module of :mod:`projeq.cli` that adds its arguments to its
parser and names the function that runs it (``parser.set_defaults(execute=...)``); the
functions call the library and hold no logic of their own. Exit codes, for every
subcommand alike:

- 0: success;
- 2: bad arguments — refused by argparse, or a ValueError (the library's way of refusing an
  input, naming it: a scene, a parameter, a value, ``--out``) — nothing is run;
- 1: a failed or interrupted run (a RuntimeError such as a failed simulation, Ctrl-C or
  SIGTERM, a file that cannot be written, or a command's own report of failed points,
  settings or benchmarks); what was computed is written, each file complete or not at all;
- 3: ``projeq run`` stopped where a subsystem left the range its model describes (status "out of
  range": a beam beyond moderate deflections, :class:`projeq.simulation.driver.ValidityWarning`);
- 4: ``projeq run`` ended at a non-finite state (status "non-finite state": the solution blew up).
  For 3 and 4 the results up to there are written, as for 1.

Warnings are printed on stderr as one line each, ``projeq run: ValidityWarning: ...``
(:func:`one_line_warnings`), not as Python's with their source line.

SIGTERM (``kill``, a batch scheduler's time limit) is handled as Ctrl-C: a KeyboardInterrupt
that each command turns into partial results.

Only the module of the subcommand that runs is imported (:data:`COMMANDS` names it): ``projeq
run`` does not pay for the benchmark and study modules (sympy, the peers) it never calls.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import signal
import sys
import threading
import warnings
from contextlib import contextmanager

OK, FAILED, BAD_ARGUMENTS, OUT_OF_RANGE, NON_FINITE = 0, 1, 2, 3, 4

#: name → (module of projeq.cli, its function adding the subcommand's arguments, one-line help)
COMMANDS = {
    "list": ("run", "list_arguments", "list the scenes, or one scene's parameters"),
    "run": ("run", "run_arguments", "simulate a scene and write the results"),
    "export": ("run", "export_arguments", "write ParaView files of a saved run (its .npz)"),
    "view": ("view", "view_arguments", "write an HTML page (or GIF, MP4) that plays a saved run's motion"),
    "sweep": ("sweep", "sweep_arguments", "simulate a scene on a parameter grid, in parallel"),
    "compare": ("studies", "compare_arguments", "compare derivations of one system (Projection Equation, Lagrange, Kane ...)"),
    "bench": ("bench", "bench_arguments", "run the performance benchmarks"),
    "tradeoff": ("studies", "tradeoff_arguments", "work-precision trade-off of integrators for a scene"),
    "campbell": ("campbell", "campbell_arguments", "Campbell diagram of a rotating scene: frequencies against speed"),
}


def parser(argv=None) -> argparse.ArgumentParser:
    """The parser of ``projeq``: every subcommand, with the arguments of those named in
    ``argv`` (default: of all), so that only their modules are imported."""
    from projeq import __version__

    top = argparse.ArgumentParser(prog="projeq", description="Multibody dynamics by Bremer's Projection Equation.")
    top.add_argument("--version", action="version", version=f"projeq {__version__}")
    sub = top.add_subparsers(dest="command", required=True)
    for name, (module, arguments, text) in COMMANDS.items():
        command = sub.add_parser(name, help=text, description=text)
        if argv is None or name in argv:
            with imports_frozen():
                getattr(importlib.import_module(f"projeq.cli.{module}"), arguments)(command)
    return top


def main(argv=None) -> int:
    """Entry point of the ``projeq`` command (and ``python -m projeq``): runs one subcommand
    and returns its exit code (module docstring); never raises SystemExit."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = parser(argv).parse_args(argv)
        args.argv = argv  # the command line, for run records
    except SystemExit as exit_:  # --help (0) or a usage error (2), printed by argparse
        return OK if exit_.code is None else int(exit_.code)
    try:
        with sigterm_as_ctrl_c(), one_line_warnings(f"projeq {args.command}"):
            return int(args.execute(args) or OK)
    except ValueError as exc:
        print(f"projeq {args.command}: {exc}", file=sys.stderr)
        return BAD_ARGUMENTS
    except RuntimeError as exc:
        print(f"projeq {args.command}: {exc}", file=sys.stderr)
        return FAILED
    except OSError as exc:  # a file that cannot be written (a full disk): nothing left half-written
        print(f"projeq {args.command}: cannot write {exc.filename or 'a file'}: {exc.strerror or exc}", file=sys.stderr)
        return FAILED
    except KeyboardInterrupt:
        print(f"projeq {args.command}: interrupted", file=sys.stderr)
        return FAILED


#: the cyclic collector's thresholds in the command's process: a young generation of 10,000
#: objects instead of Python 3.11's 700. The imports of scipy and numba leave some 130,000 long-lived
#: tracked objects, and with 700 the collector walked all of them in 3 full collections during ``projeq
#: run`` (0.21–0.23 s CPU in 307 collections, 0.10–0.13 s of it the full ones); with 10,000 it makes
#: 21 collections, none full (0.08–0.13 s; ``benchmarks/run_profile.py``'s row "cyclic garbage
#: collector"). Garbage in cycles then waits for at most 10,000 allocations.
THRESHOLDS = (10_000, 10, 10)


def command() -> int:
    """The installed ``projeq`` command and ``python -m projeq``: :func:`main` with the command
    line, the collector's :data:`THRESHOLDS` raised for the imports' long-lived objects, then
    :func:`gc.freeze` of what is alive, as the process is about to end. Without it
    the interpreter's exit collects and finalises, cycle by cycle, everything numba, llvmlite
    and scipy built (0.5 s of the 3.4 s CPU time of ``projeq run``; 0.06 s frozen, measured by
    ``benchmarks/run_profile.py``); atexit handlers and the flushing of open files still run."""
    gc.set_threshold(*THRESHOLDS)
    code = main()
    gc.freeze()
    return code


@contextmanager
def imports_frozen():
    """The block's imports (a subcommand's modules, the first time in the process: scipy's and
    numba's) with the cyclic collector paused, and, if the block imported a module, what is alive
    after it frozen (:func:`gc.freeze`): the ~130,000 long-lived objects of the imports are then
    neither walked while they are made (in ``projeq run`` 10 young-generation collections and a
    middle-generation one over ~100,000 objects: the collector 0.07 → 0.02 s CPU,
    ``benchmarks/run_profile.py --compare``) nor afterwards. A block that imports nothing new freezes nothing; the
    collector is enabled again as it was."""
    modules, enabled = len(sys.modules), gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if len(sys.modules) > modules:
            gc.freeze()
        if enabled:
            gc.enable()


@contextmanager
def one_line_warnings(prefix: str):
    """Within the block every warning shown (once per place it is raised, Python's "default"
    action) is printed on stderr as one line, ``<prefix>: <Category>: <message>``, without
    Python's file name and source line, and recorded: the block gets the list of
    ``{"category": ..., "message": ...}`` (``projeq run`` writes it into run.json)."""
    raised = []

    def show(message, category, filename, lineno, file=None, line=None):
        text = " ".join(str(message).split())
        raised.append({"category": category.__name__, "message": text})
        print(f"{prefix}: {category.__name__}: {text}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.simplefilter("default")
        warnings.showwarning = show
        yield raised


def _interrupt(signum, frame):
    raise KeyboardInterrupt


@contextmanager
def sigterm_as_ctrl_c():
    """Within the block SIGTERM raises KeyboardInterrupt, as Ctrl-C does (on the main thread
    only, where Python delivers signals); the previous handler is restored afterwards."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGTERM, _interrupt)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)

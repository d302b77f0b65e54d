"""Options and checks shared by several subcommands of ``projeq``.

A bad value is a ValueError naming the option; :func:`projeq.cli.commands.main` turns it into
exit code 2.
"""

from __future__ import annotations

import argparse
import re
from pathlib import Path


def scene_settings_option(parser: argparse.ArgumentParser) -> None:
    """``--set NAME=VALUE`` (repeatable): scene parameters, parsed by the scene."""
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override a scene parameter (see projeq list SCENE); repeatable")


def plain(text: str) -> str:
    """A docstring as help text: reStructuredText roles (``:mod:`x```) and literals
    (````x````) as the plain names."""
    return re.sub(r":\w+:`~?([^`]+)`", r"\1", text or "").replace("``", "")


def jsonable(value):
    """``default`` of ``json.dumps``: numpy arrays and numbers as JSON values, anything else
    (a tuple default, a sympy expression) as its text."""
    import numpy as np

    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    return str(value)


def json_option(parser: argparse.ArgumentParser) -> None:
    """``--json``: one JSON document on standard output instead of text."""
    parser.add_argument("--json", action="store_true", help="print one JSON document instead of text")


def simulation_options(parser: argparse.ArgumentParser, out: str = "projeq-out") -> None:
    """The options of every subcommand that simulates a scene (``projeq run``, ``projeq
    sweep``): scene settings, end time, integrator, tolerances, evaluator, output directory,
    quiet, JSON; :func:`simulate_options` turns them into :func:`projeq.simulate`'s keywords."""
    from projeq.assembly import EVALUATORS
    from projeq.simulation.driver import INTEGRATORS, OWN_SOLVERS
    from projeq.simulation.integrators import PROJECTED

    methods = [*INTEGRATORS, *OWN_SOLVERS, *PROJECTED]
    scene_settings_option(parser)
    parser.add_argument("--t-end", type=float, default=None, help="end time in s (default: the scene's)")
    parser.add_argument("--method", default=None, choices=methods, metavar="METHOD",
                        help=f"integrator: {', '.join(methods)} (default: the scene's setting, "
                             "else projeq.simulate's choice)")
    parser.add_argument("--step", type=float, default=None,
                        help="the fixed step in s of --method GeneralizedAlpha (it takes no other)")
    parser.add_argument("--rho-inf", type=float, default=None,
                        help="GeneralizedAlpha's spectral radius at infinity in [0, 1] (default 0.9)")
    parser.add_argument("--rtol", type=float, default=None,
                        help="relative tolerance (default: the scene's setting, else projeq.simulate's)")
    parser.add_argument("--atol", type=float, default=None,
                        help="absolute tolerance (default: the scene's setting, else projeq.simulate's)")
    parser.add_argument("--evaluator", choices=list(EVALUATORS), default=None,
                        help="how the accelerations are computed (default: the model's own choice)")
    parser.add_argument("--out", default=out, help=f"output directory (default ./{out})")
    parser.add_argument("--quiet", action="store_true", help="no progress bar, print nothing but errors")
    json_option(parser)


def simulate_options(args, scene) -> dict:
    """The keywords of :func:`projeq.simulate` given by :func:`simulation_options` over the
    scene's own settings (:class:`projeq.scenes.Scene` ``settings``); what neither gives is
    left to ``simulate``'s defaults, except that a run leaving its model's range stops there
    (``out_of_range="stop"``: status "out of range", exit code 3 of ``projeq run``)."""
    given = {name: getattr(args, name) for name in ("method", "rtol", "atol", "evaluator", "step", "rho_inf")
             if getattr(args, name) is not None}
    return (scene.settings or {}) | given | {"out_of_range": "stop"}  # a run leaving its model's range ends


def scene_label(scene: str) -> str:
    """The name of the scene in file names: itself, or ``FILE-FUNCTION`` for ``FILE.py:FUNCTION``."""
    return "".join(c if c.isalnum() or c in "_-" else "-" for c in Path(scene.replace(".py:", "-")).name)


def output_directory(text: str, option: str = "--out") -> Path:
    """The output directory ``text`` of ``option`` (``--out``), created; ValueError naming the
    option when it cannot be written."""
    out = Path(text)
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".projeq-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise ValueError(f"{option}: cannot write to directory {text!r}: {exc.strerror or exc}") from None
    return out


def output_file(text: str, option: str) -> Path:
    """The file ``text`` of ``option`` (``--csv``) to be written after the work: its directory
    created and writable, and no directory itself; ValueError naming the option, before the work."""
    path = Path(text)
    if path.is_dir():
        raise ValueError(f"{option}: {text!r} is a directory, not a file")
    output_directory(str(path.parent), option)
    return path


def number(option: str, text: str) -> float:
    """``float(text)``; ValueError naming ``option`` when it is not a number."""
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"{option}: expected a number, got {text!r}") from None

"""Options and checks shared by several subcommands of ``projeq``.

A bad value is a ValueError naming the option; :func:`projeq.cli.commands.main` turns it into
exit code 2.
"""

from __future__ import annotations

import argparse
from pathlib import Path


def scene_settings_option(parser: argparse.ArgumentParser) -> None:
    """``--set NAME=VALUE`` (repeatable): scene parameters, parsed by the scene."""
    parser.add_argument("--set", action="append", default=[], metavar="NAME=VALUE",
                        help="override a scene parameter (see projeq list SCENE); repeatable")


def simulation_options(parser: argparse.ArgumentParser) -> None:
    """The options of ``projeq run`` and ``projeq sweep``: scene settings, end time, integrator,
    rtol, output directory, quiet."""
    scene_settings_option(parser)
    parser.add_argument("--t-end", type=float, default=None, help="end time in s (default: the scene's)")
    parser.add_argument("--method", default="DOP853", help="solve_ivp method (default DOP853)")
    parser.add_argument("--rtol", type=float, default=1e-9, help="relative tolerance (default 1e-9)")
    parser.add_argument("--out", default="projeq-out", help="output directory (default ./projeq-out)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar, print nothing but errors")


def output_directory(text: str) -> Path:
    """The output directory ``--out``, created; ValueError when it cannot be written."""
    out = Path(text)
    try:
        out.mkdir(parents=True, exist_ok=True)
        probe = out / ".projeq-write-test"
        probe.write_text("")
        probe.unlink()
    except OSError as exc:
        raise ValueError(f"--out: cannot write to directory {text!r}: {exc.strerror or exc}") from None
    return out


def number(option: str, text: str) -> float:
    """``float(text)``; ValueError naming ``option`` when it is not a number."""
    try:
        return float(text)
    except ValueError:
        raise ValueError(f"{option}: expected a number, got {text!r}") from None

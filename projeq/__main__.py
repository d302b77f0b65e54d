"""``python -m projeq`` runs the command line (:func:`projeq.cli.command`)."""

from projeq.cli import command

raise SystemExit(command())

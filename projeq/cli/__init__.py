"""The ``projeq`` command: :func:`command` (the installed script and ``python -m projeq``) and
:func:`main` (:mod:`.commands`, the parser and the exit codes), one
module per group of subcommands (:mod:`.run`: list, run, export; :mod:`.sweep`; :mod:`.studies`:
compare, tradeoff; :mod:`.bench`) and the options they share (:mod:`.options`)."""

from projeq.cli.commands import command, main

__all__ = ["command", "main"]

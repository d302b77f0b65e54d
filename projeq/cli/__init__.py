"""The ``projeq`` command (:mod:`.commands`)."""

from projeq.cli.commands import main

__all__ = ["main"]

"""``python -m projeq`` runs the command line (:mod:`projeq.cli.commands`)."""

from projeq.cli.commands import main

raise SystemExit(main())

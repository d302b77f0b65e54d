"""``python -m projeq`` runs the command line (:func:`projeq.cli.main`)."""

from projeq.cli import main

raise SystemExit(main())

"""``python -m projeq`` runs the command line (:mod:`projeq.cli`)."""

from projeq.cli import main

raise SystemExit(main())

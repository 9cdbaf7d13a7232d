"""``python -m csplab`` runs the command line."""

from csplab.cli import main

raise SystemExit(main())

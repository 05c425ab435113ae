"""`python -m printgen` runs the command-line interface."""

from printgen.cli import main

raise SystemExit(main())

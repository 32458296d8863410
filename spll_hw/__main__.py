"""``python -m spll_hw``: the ``spll-hw`` command line."""

from .cli.main import main

raise SystemExit(main())

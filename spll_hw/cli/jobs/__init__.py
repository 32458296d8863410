"""What each sub-command does: ``spll_hw.cli.jobs.NAME`` holds ``run(args)`` of command ``NAME``
and its helpers, with their imports at the top. :func:`spll_hw.cli.main.run_job` imports it only
when its command runs; its parser (``HELP``, ``DESCRIPTION``, ``add_arguments``) is
``spll_hw.cli.NAME``, light enough for ``--help``."""

"""Command-line interface: ``spll-hw <command> --help``."""

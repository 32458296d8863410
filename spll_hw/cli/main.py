"""``spll-hw``: entry point that dispatches to one module per sub-command.

Each module in :data:`COMMANDS` defines ``register(subparsers)`` which adds its parser and sets
``func`` (called with the parsed namespace, returning an exit code). Modules are imported only
when listed here, and heavy dependencies are imported inside ``func`` so ``--help`` stays fast.

Exit status: 0 on success, 2 on invalid input (one line on stderr), 130 on Ctrl-C (the engine
stops within a fraction of a second; report files are written atomically, so none is left
half-written).
"""

from __future__ import annotations

import argparse
import importlib
import sys

from ..provenance import version
from .arguments import HelpFormatter, check_numbers
from .inputs import check_out_dir

#: Sub-command modules, in the order ``spll-hw --help`` lists them.
COMMANDS = (
    "report",
    "compare",
    "stability",
    "simulate",
    "response",
    "evaluate",
    "tune",
    "export",
    "fit",
    "backends",
    "chips",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="spll-hw",
        description="Exact golden model, hardware mappings and accuracy harness for networks of "
        "spiking phase-locked loops (sPLLs).",
    )
    parser.add_argument("--version", action="version", version=f"spll-hw {version()}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        importlib.import_module(f"spll_hw.cli.{name}").register(sub)
    for command in sub.choices.values():  # every default in --help, aliases shown once
        command.formatter_class = HelpFormatter
        check_numbers(command)  # every number's range checked where it is parsed
    return parser


def main(argv: list[str] | None = None) -> int:
    try:
        parser = build_parser()
    except KeyboardInterrupt:  # Ctrl-C while the commands are still importing
        print("spll-hw: interrupted", file=sys.stderr)
        return 130
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a bad flag (argparse said which): its code
        return int(exc.code or 0)
    try:
        if getattr(args, "out", None) is not None:  # an unwritable --out fails before any work
            check_out_dir(args.out)
        return int(args.func(args) or 0)
    except (ValueError, OSError, ImportError) as exc:  # bad input, files, a missing extra
        print(f"spll-hw {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # its message, if any, says what was (not) written
        print(f"spll-hw {args.command}: interrupted" + (f"; {exc}" if str(exc) else ""),
              file=sys.stderr)  # fmt: skip
        return 130


if __name__ == "__main__":
    sys.exit(main())

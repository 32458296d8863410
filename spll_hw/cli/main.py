"""``spll-hw``: entry point that dispatches to one module per sub-command.

Each command ``NAME`` of :data:`COMMANDS` has two modules. ``spll_hw.cli.NAME`` declares its
parser: ``HELP`` (its line in ``spll-hw --help``), ``DESCRIPTION`` and ``add_arguments(parser)``,
from which :func:`build_parser` makes the sub-parsers; it imports only what argparse needs, so
``--help`` stays fast. ``spll_hw.cli.jobs.NAME`` does the work: ``run(args)`` (called with the
parsed namespace, returning an exit code) and its helpers, with their imports at the top; it is
imported only when its command runs (:class:`Job`), where a missing optional extra is one line
on stderr like any other bad input.

Exit status (docs/cli.md, "Exit status"): 0 on success (``fit``: the network fits), 1 when
``fit``'s network does not fit, 2 on invalid input (one line on stderr), 130 on Ctrl-C (the engine
stops within a fraction of a second; report files are written atomically, so none is left
half-written), 141 when whatever reads the output closes it early (``spll-hw fit ... | head``;
128 + SIGPIPE, as the shell's own tools; nothing is printed).
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import errno
import importlib
import os
import sys
import warnings
from pathlib import Path

from ..provenance import version
from .arguments import HelpFormatter, accept_old_spellings, check_numbers

#: Sub-command modules, in the order ``spll-hw --help`` lists them.
COMMANDS = (
    "report",
    "compare",
    "stability",
    "simulate",
    "response",
    "evaluate",
    "slide",
    "robustness",
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
        module = importlib.import_module(f"spll_hw.cli.{name}")
        # every default in --help, aliases shown once
        command = sub.add_parser(name, help=module.HELP, description=module.DESCRIPTION,
                                 formatter_class=HelpFormatter)  # fmt: skip
        module.add_arguments(command)
        command.set_defaults(func=Job(name))
        check_numbers(command)  # every number's range checked where it is parsed
        accept_old_spellings(command)  # older spellings still work, with one line on stderr
    return parser


@dataclasses.dataclass(frozen=True)
class Job:
    """``args.func`` of command ``name``'s sub-parser: called with the parsed namespace, it
    imports the command's job module ``spll_hw.cli.jobs.NAME``, only now that the command runs,
    and returns what its ``run(args)`` returns."""

    name: str

    def __call__(self, args: argparse.Namespace) -> int:
        return importlib.import_module(f"spll_hw.cli.jobs.{self.name}").run(args)


def main(argv: list[str] | None = None) -> int:
    try:
        parser = build_parser()
    except KeyboardInterrupt:  # Ctrl-C while the commands are still importing
        print("spll-hw: interrupted", file=sys.stderr)
        return 130
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help, --version, or a bad flag (argparse said which): its code
        return _flushed(int(exc.code or 0))
    except BrokenPipeError:  # spll-hw COMMAND --help | head
        return _reader_gone()
    try:
        if getattr(args, "out", None) is not None:  # an unwritable --out fails before any work
            check_out_dir(args.out)
        with _warnings_as_lines(args.command):
            return _flushed(int(args.func(args) or 0))
    except BrokenPipeError:
        return _reader_gone()
    except (ValueError, OSError, ImportError) as exc:  # bad input, files, a missing extra
        print(f"spll-hw {args.command}: error: {_named(exc, args)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as exc:  # its message, if any, says what was (not) written
        print(f"spll-hw {args.command}: interrupted" + (f"; {exc}" if str(exc) else ""),
              file=sys.stderr)  # fmt: skip
        return 130


@contextlib.contextmanager
def _warnings_as_lines(command: str):
    """Warnings printed as the command's own lines (``spll-hw fit: warning: …``), not as
    Python's ``FILE:LINE: UserWarning: …`` with a line of spll-hw's source below."""
    previous = warnings.formatwarning
    warnings.formatwarning = lambda message, *_: f"spll-hw {command}: warning: {message}\n"
    try:
        yield
    finally:
        warnings.formatwarning = previous


#: Exit status when the reader of the output closed it early: 128 + SIGPIPE, as ``yes | head``.
EXIT_PIPE_CLOSED = 141


def _flushed(status: int) -> int:
    """``status`` once stdout is flushed, so that a reader that left early is found here, not
    in the interpreter's last flush (:func:`_reader_gone`)."""
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        return _reader_gone()
    return status


def _reader_gone() -> int:
    """:data:`EXIT_PIPE_CLOSED`, quietly: stdout goes to ``/dev/null`` so that the interpreter's
    last flush of what was left finds no closed pipe either."""
    os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return EXIT_PIPE_CLOSED


#: ``errno`` values of a write that failed for want of room or permission, not for its input.
_CANNOT_WRITE = {errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EFBIG, errno.EACCES}


def check_out_dir(path: str | Path, flag: str = "--out") -> Path:
    """``path`` if a report folder can be written there, checked before any work (nothing is
    created): ``ValueError`` naming ``flag`` when it, or the folder it would be made in, is a
    file or not writable."""
    path = Path(path)
    parent = path
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise ValueError(f"{flag} {path}: {parent} is a file, not a folder")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"{flag} {path}: no permission to write in {parent}")
    return path


#: The optional extras of pyproject.toml's ``[project.optional-dependencies]`` by the package a
#: missing one leaves unimportable: ``import name -> (extra, the distribution the extra
#: names)``; tests/test_cli_extras.py checks every entry against pyproject.toml.
OPTIONAL_EXTRAS = {
    "sklearn": ("pipeline", "scikit-learn"),
    "optuna": ("tune", "optuna"),
    "psycopg": ("tune", "psycopg"),
    "optuna_dashboard": ("tune", "optuna-dashboard"),
    "brian2": ("brian2", "brian2"),
    "Cython": ("brian2", "Cython"),
    "lava": ("lava", "lava-nc"),
    "nir": ("nir", "nir"),
    "usb": ("usb", "pyusb"),
}
#: pip's options an extra needs (pyproject.toml's note on ``lava``: lava-nc 0.10 declares
#: Python < 3.11).
_PIP_OPTIONS = {"lava": "--ignore-requires-python "}


def install_hint(exc: ImportError) -> str | None:
    """How to install the optional extra whose package ``exc`` found missing (``pip install
    'spll-hw[pipeline]'``), ``None`` for any other package or an error that says so already."""
    package = (exc.name or "").split(".")[0]
    if package not in OPTIONAL_EXTRAS or "spll-hw[" in str(exc) or ".[" in str(exc):
        return None
    extra, _ = OPTIONAL_EXTRAS[package]
    return f"pip install {_PIP_OPTIONS.get(extra, '')}'spll-hw[{extra}]'"


def _named(exc: Exception, args: argparse.Namespace) -> str:
    """``exc`` as one line; a failed write that names no file (a full disk fails a ``write``,
    which has none) names the command's ``--out`` folder; a missing optional extra's package
    names the extra to install (:func:`install_hint`)."""
    out = getattr(args, "out", None)
    if isinstance(exc, OSError) and exc.filename is None and exc.errno in _CANNOT_WRITE and out:
        return f"cannot write in {out}: {exc.strerror or exc}"
    if isinstance(exc, ImportError) and (hint := install_hint(exc)):
        return f"{exc}; install the optional extra: {hint}"
    return str(exc)


if __name__ == "__main__":
    sys.exit(main())

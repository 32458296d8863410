"""Rewrite the "Every option" section of ``docs/cli.md`` from the commands' ``--help`` texts.

Run after changing a command's options, from the repository root::

    python scripts/cli_reference.py          # rewrites docs/cli.md in place
    python scripts/cli_reference.py --check  # exit status 1 when docs/cli.md is stale

The help is rendered at 100 columns, one fenced block per command in the order of
``spll-hw --help``; everything above the section heading is kept as written.
"""

from __future__ import annotations

import contextlib
import io
import os
import sys
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "cli.md"
HEADING = "## Every option"
INTRO = (
    "What `spll-hw COMMAND --help` prints (at 100 columns). The help text is the reference: "
    "when\nthis page and `--help` disagree, `--help` is right and this page is stale;\n"
    "`python scripts/cli_reference.py` rewrites it."
)


def help_text(command: str) -> str:
    """What ``spll-hw COMMAND --help`` prints at 100 columns."""
    from spll_hw.cli.main import main

    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        main([command, "--help"])
    return out.getvalue().rstrip()


def section() -> str:
    """The whole "Every option" section, from its heading to the end of the page."""
    from spll_hw.cli.main import COMMANDS

    blocks = [f"### `spll-hw {c}`\n\n```text\n{help_text(c)}\n```\n" for c in COMMANDS]
    return f"{HEADING}\n\n{INTRO}\n\n" + "\n".join(blocks)


def rewrite(text: str) -> str:
    """``text`` (the page) with the section written anew below what stands above it."""
    os.environ["COLUMNS"] = "100"  # argparse wraps help at $COLUMNS
    return text[: text.index(HEADING)] + section()


def main() -> int:
    from generated_page import rewrite_or_check  # beside this script

    return rewrite_or_check(DOC, __doc__.splitlines()[0], rewrite)


if __name__ == "__main__":
    sys.exit(main())

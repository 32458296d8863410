"""Write the tables of ``docs/backends.md`` that state what the code states: every registered
backend with its capabilities and declared tolerance, every backend's options with their
defaults, and the standard exports' settings (the steps and gates they try, the check's
inputs, the consumers' steps and tolerance).

Run after changing a backend, an option's default, a tolerance or an export setting, from the
repository root::

    python scripts/doc_tables.py          # rewrites the tables in docs/backends.md in place
    python scripts/doc_tables.py --check  # exit status 1 when a table is stale

Each table sits between ``<!-- generated: NAME (scripts/doc_tables.py) -->`` and
``<!-- /generated: NAME -->``; everything outside the markers is kept as written.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "backends.md"


def percent(x: float) -> str:
    """A tolerance as ``spll-hw backends`` prints it: ``exact`` for 0, else 3 significant
    digits and `` %``."""
    return "exact" if x == 0 else f"{100 * x:.3g} %"


def micro(seconds: float) -> str:
    """A time step [s] in µs, e.g. ``100 µs`` or ``2.5 µs``."""
    return f"{1e6 * seconds:.3g} µs"


def _default(value: object) -> str:
    return "unset" if value is None else f"`{value}`"


def backends_table() -> str:
    """Every registered backend: capabilities of its default configuration, declared tolerance,
    extra and description (``spll-hw backends`` without the machine's availability)."""
    from spll_hw import backends

    rows = ["| backend | capabilities | declared tolerance | extra | what it is |",
            "|---|---|---|---|---|"]  # fmt: skip
    for e in backends.listing():
        caps = e.capabilities
        rows.append(
            f"| `{e.name}` | {caps.summary() if caps else '-'} | "
            f"{percent(caps.rate_tolerance) if caps else '-'} | {e.extra or 'core'} | "
            f"{e.description} |"
        )
    return "\n".join(rows)


def options_table() -> str:
    """Every registered backend's options with their defaults (``spll-hw backends --options``
    gives each one's help)."""
    from spll_hw import backends

    groups: dict[str, list[str]] = {}  # backends with the same options share a row
    for e in backends.listing():
        items = ", ".join(f"`{k}` ({_default(o.default)})" for k, o in e.options.items())
        groups.setdefault(items or "none", []).append(f"`{e.name}`")
    rows = ["| backend | options (default) |", "|---|---|"]
    rows += [f"| {', '.join(names)} | {items} |" for items, names in groups.items()]
    return "\n".join(rows)


def export_settings_table() -> str:
    """What the standard exports try without ``--dt`` and what their check runs, from the
    constants that decide it."""
    from mappings.lava import clocks
    from mappings.lava import dt_choice as lava_ladder
    from mappings.nir import consumers, standalone_check
    from mappings.nir import dt_choice as nir_ladder
    from mappings.nir.standard import EXPORT_LEVELS
    from spll_hw import backends
    from spll_hw.exporters import check, check_inputs
    from spll_hw.exporters.dt_ladder import EXPORT_GATES

    gate = backends.backend_class("standard-exact").OPTIONS
    gates = "; then ".join(
        f"{levels or EXPORT_LEVELS} levels, {placement}" for placement, levels in EXPORT_GATES
    )
    sums, spikes, share = standalone_check.TOLERANCE
    hold = backends.backend_class("standard-fixed-point").OPTIONS["hold"].default
    holds = ", then ".join(h or hold for h in lava_ladder.PARTS.holds)
    rows = [
        ("the backends' gate (`levels`, `placement`, `input_rate`)",
         f"{gate['levels'].default} levels, {gate['placement'].default}, placed for "
         f"{gate['input_rate'].default:g} Hz Poisson input",
         "the `standard-exact` backend's options"),
        ("`--to nir-standard` without `--dt`: the steps tried, coarsest first",
         ", ".join(micro(dt) for dt in nir_ladder.LADDER), "`mappings/nir/dt_choice.py` `LADDER`"),
        ("`--to lava-standard` without `--dt`: the steps tried, coarsest first",
         ", ".join(micro(dt) for dt in lava_ladder.LADDER),
         "`mappings/lava/dt_choice.py` `LADDER`"),
        ("the gates tried at each step, in order", gates, "`EXPORT_GATES`, `EXPORT_LEVELS`"),
        ("lava-standard's refractory holds at each step, in order",
         holds, "`mappings/lava/dt_choice.py` `PARTS.holds`"),
        ("lava-standard's last rungs, where no step passes",
         f"a clock per sPLL (R = {clocks.DEFAULT_HOLDS}, {clocks.DEFAULT_LEVELS} levels, "
         f"{clocks.DEFAULT_PLACEMENT}); then the same with graded CCO currents "
         f"({lava_ladder.GRADED_LEVELS} levels)", "`mappings/lava/dt_choice.py` `PARTS.last`"),
        ("the check's reference inputs",
         f"{check_inputs.DURATION:g} s each; golden on them "
         f"{1e3 * check.RESOLUTION_SHIFT:g} ms later states the check's resolution; "
         f"{check.LONGER:g} s where 1 s does not resolve it",
         "`spll_hw/exporters/check_inputs.py`, `check.py`"),
        ("snnTorch's step (the only one its NIR import runs)", micro(consumers.SNNTORCH_DT),
         "`mappings/nir/consumers.py` `SNNTORCH_DT`"),
        ("the finest step whose folder names Norse", micro(consumers.NORSE_MIN_DT),
         "`mappings/nir/consumers.py` `NORSE_MIN_DT`"),
        ("`check_consumer.py`'s tolerance (float32 consumers against `check.json`)",
         f"per input, a sum of differences of {100 * sums:g} % of the total; per sPLL, "
         f"{spikes} spikes or {100 * share:g} % of its count",
         "`mappings/nir/standalone_check.py` `TOLERANCE`"),
    ]  # fmt: skip
    lines = ["| setting | value | stated in |", "|---|---|---|"]
    lines += [f"| {a} | {b} | {c} |" for a, b, c in rows]
    return "\n".join(lines)


#: The generated tables by name, in the order they appear.
TABLES: dict[str, Callable[[], str]] = {
    "backends": backends_table,
    "options": options_table,
    "export-settings": export_settings_table,
}


def _markers(name: str) -> tuple[str, str]:
    return f"<!-- generated: {name} (scripts/doc_tables.py) -->", f"<!-- /generated: {name} -->"


def rewrite(text: str) -> str:
    """``text`` with every generated table written anew; ``ValueError`` where a table's
    markers are missing."""
    for name, table in TABLES.items():
        start, end = _markers(name)
        pattern = re.compile(re.escape(start) + r"\n.*?" + re.escape(end), re.S)
        if not pattern.search(text):
            raise ValueError(f"{DOC}: no {start} ... {end} block")
        text = pattern.sub(lambda _, s=start, e=end, t=table: f"{s}\n{t()}\n{e}", text)
    return text


def main() -> int:
    from generated_page import rewrite_or_check  # beside this script

    return rewrite_or_check(DOC, __doc__.splitlines()[0], rewrite)


if __name__ == "__main__":
    sys.exit(main())

"""``spll-hw backends``: every registered simulator, what it can do and whether it runs here."""

from __future__ import annotations

import argparse

from ... import backends


def run(args: argparse.Namespace) -> int:
    rows = ["| backend | available | capabilities | tolerance | extra | description |",
            "|---|---|---|---|---|---|"]  # fmt: skip
    entries = backends.listing()
    for e in entries:
        caps = e.capabilities
        rows.append(
            f"| {e.name} | {'yes' if e.unavailable is None else 'no: ' + e.unavailable} | "
            f"{caps.summary() if caps else '-'} | "
            f"{_percent(caps.rate_tolerance) if caps else '-'} | {_extra(e)} | "
            f"{e.description} |"
        )
    print("\n".join(rows))
    if args.options:
        for e in entries:
            print(f"\n{e.name}:" + ("" if e.options else " no options"))
            for key, option in e.options.items():
                print(f"  {key} (default {option.default}): {option.help}")
    print(
        "\nA spec is NAME[:key=value...], e.g. golden-fixed-point:profile=loihi2:dt=1e-5; "
        "tolerance: declared rate error against golden of the same realised network."
    )
    return 0


def _percent(x: float) -> str:
    return "exact" if x == 0 else f"{100 * x:.3g} %"


def _extra(entry) -> str:
    """The extra that installs a backend: ``core`` for none needed, or what to install by hand
    (a backend that needs packages but no extra of spll-hw, such as torch for the NIR
    consumers)."""
    if entry.extra:
        return entry.extra
    cls = backends.backend_class(entry.name)
    return f"none: {cls.install}" if getattr(cls, "install", None) else "core"

"""``spll-hw stability``: stiff and extreme parameters through every backend, golden as truth."""

from __future__ import annotations

import argparse
from dataclasses import replace

from ...backends import parse_specs
from ...files import atomic_folder, write_results, write_text
from ...harness.stability import CASES, Case, check, markdown
from ..arguments import DEFAULT_DTS, split_list
from ..inputs import default_backends, expand_specs, read_network


def run(args: argparse.Namespace) -> int:
    specs = parse_specs(args.backends or default_backends().removeprefix("golden,"))
    specs = expand_specs(specs, [float(x) for x in split_list(DEFAULT_DTS)])
    cases = chosen_cases(args)
    say = (lambda *a: None) if args.quiet else print
    say(f"{len(cases)} cases x {len(specs)} backends, each against golden:")
    outcomes = check(
        specs, cases, tolerance=args.tolerance, slack=args.slack,
        on_outcome=lambda o: say(f"  {o.case} / {o.spec}: {o.verdict}"),
    )  # fmt: skip
    with atomic_folder(args.out) as out:
        write_results(out / "results.json", {"outcomes": [o.__dict__ for o in outcomes]})
        text = markdown(outcomes)
        title = "# Stability of every backend on extreme parameters"
        write_text(out / "summary.md", f"{title}\n\n{text}\n")
    print(text.split("\n\n")[0])
    print(f"report: {args.out / 'summary.md'}")
    return 0


def chosen_cases(args: argparse.Namespace) -> list:
    """The cases ``--cases``, ``--duration`` and ``--network`` select (``ValueError`` for a
    word that matches no case, a duration or slack out of range)."""
    if args.slack < 0 or not args.tolerance >= 0:
        raise ValueError(f"--slack must be >= 0 and --tolerance >= 0, got {args.slack}, "
                         f"{args.tolerance}")  # fmt: skip
    cases = list(CASES)
    if args.cases:
        words = split_list(args.cases)
        unknown = [w for w in words if not any(w in c.name for c in CASES)]
        if unknown:
            names = "; ".join(c.name for c in CASES)
            raise ValueError(f"--cases {unknown}: no case has that in its name; cases: {names}")
        cases = [c for c in cases if any(w in c.name for w in words)]
    if args.duration is not None:
        if not (args.duration > 0 and args.duration < 1e4):
            raise ValueError(f"--duration must be in (0, 1e4) s, got {args.duration}")
        cases = [replace(c, duration=args.duration) for c in cases]
    if args.network is not None:
        network = read_network(args).config.build()
        cases.append(Case.of_network(f"network {args.network}", network, args.rate,
                                     args.duration or 1.0))  # fmt: skip
    return cases

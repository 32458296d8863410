"""``spll-hw stability``: stiff and extreme parameters through every backend, golden as truth."""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path

from ..files import atomic_folder, write_results, write_text
from .arguments import DEFAULT_DTS, add_network_argument, default_backends, split_list
from .inputs import expand_specs, read_network

#: The command's line in ``spll-hw --help``.
HELP = "sweep stiff and extreme parameters through every backend"
#: What ``spll-hw stability --help`` says first.
DESCRIPTION = (
    "Run one-sPLL networks at the edges of the parameter space (time-constant "
    "ratios 1e-3 and 1e3, equal and nearly equal constants, huge gains, input at 1/t_refr, "
    "microsecond time constants) on each backend and report where it diverges from the "
    "golden model or breaks."
)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--backends",
                   help="comma-separated backend specs, each judged against golden (see "
                   "spll-hw compare) (default: golden-fixed-point and brian2-cpp_standalone "
                   "where Brian2 is installed)")  # fmt: skip
    p.add_argument("--tolerance", type=float, default=0.02,
                   help="largest relative spike-count error judged ok")  # fmt: skip
    p.add_argument("--slack", type=int, default=1,
                   help="spike-count difference always judged ok (a clocked backend can move a "
                   "spike across the end of the run)")  # fmt: skip
    p.add_argument("--cases", help="only the cases whose name contains one of these "
                   "comma-separated words (default: every case)")  # fmt: skip
    p.add_argument("--duration", type=float,
                   help="seconds per case (default: each case's own, 1 s)")  # fmt: skip
    add_network_argument(p, default=None, why="; adds this network, under periodic input at "
                         "--rate, as one more case (default: none, the cases alone)")  # fmt: skip
    p.add_argument("--rate", type=float, default=300.0,
                   help="periodic input [Hz] of the --network case")  # fmt: skip
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.add_argument("--out", type=Path, default=Path("reports/stability"), help="report folder")


def run(args: argparse.Namespace) -> int:
    from ..backends import parse_specs
    from ..harness.stability import check, markdown

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
    from ..harness.stability import CASES, Case

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

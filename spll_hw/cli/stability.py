"""``spll-hw stability``: stiff and extreme parameters through every backend, golden as truth."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..files import write_results, write_text
from .arguments import DEFAULT_DTS, default_backends, split_list
from .inputs import expand_specs


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "stability",
        help="sweep stiff and extreme parameters through every backend",
        description="Run one-sPLL networks at the edges of the parameter space (time-constant "
        "ratios 1e-3 and 1e3, equal and nearly equal constants, huge gains, input at 1/t_refr, "
        "microsecond time constants) on each backend and report where it diverges from the "
        "golden model or breaks.",
    )
    p.add_argument("--backends",
                   help="comma-separated backend specs, each judged against golden (see "
                   "spll-hw compare) (default: golden-fixed-point and brian2-cpp_standalone "
                   "where Brian2 is installed)")  # fmt: skip
    p.add_argument("--tolerance", type=float, default=0.02,
                   help="largest relative spike-count error judged ok")  # fmt: skip
    p.add_argument("--out", type=Path, default=Path("reports/stability"), help="report folder")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..backends import parse_specs
    from ..harness.stability import check, markdown

    specs = parse_specs(args.backends or default_backends().removeprefix("golden,"))
    specs = expand_specs(specs, [float(x) for x in split_list(DEFAULT_DTS)])
    outcomes = check(specs, tolerance=args.tolerance)
    out = args.out
    out.mkdir(parents=True, exist_ok=True)
    write_results(out / "results.json", {"outcomes": [o.__dict__ for o in outcomes]})
    text = markdown(outcomes)
    title = "# Stability of every backend on extreme parameters"
    write_text(out / "summary.md", f"{title}\n\n{text}\n")
    print(text.split("\n\n")[0])
    print(f"report: {out / 'summary.md'}")
    return 0

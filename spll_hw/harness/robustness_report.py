"""The report folder of a robustness check (:mod:`spll_hw.harness.robustness`).

Layout of ``out``::

    summary.md       the table: per variation, both accuracies and the paired change, 95 % CIs
    robustness.png   the change per variation with its interval, and both accuracies
    results.json     every row, the command and the networks
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from ..datasets.recordings import format_numbers
from ..files import save_figure, write_results, write_text
from ..report.plots import _pyplot
from .robustness import VariationResult


def _pct(interval) -> str:
    return f"{100 * interval.mean:.1f} % [{100 * interval.low:.1f}, {100 * interval.high:.1f}]"


def _points(interval) -> str:
    return f"{100 * interval.mean:+.1f} [{100 * interval.low:+.1f}, {100 * interval.high:+.1f}]"


def survives(rows: Sequence[VariationResult]) -> bool:
    """Whether the tuned network's gain is above zero (interval and all) in every variation."""
    return all(r.tuned.change_against(r.reference).low > 0 for r in rows)


def table_lines(rows: Sequence[VariationResult]) -> list[str]:
    """The Markdown table: one row per variation, accuracies and change with 95 % CIs
    (bootstrap over the test recordings; the change paired sample by sample)."""
    lines = [
        "| variation | trained on | tested on | input level | tuned | reference "
        "| tuned − reference (points) |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        v, n_test = r.variation, r.tuned.correct.shape[1]
        lines.append(
            f"| {v.label} | {format_numbers(v.train)} | {format_numbers(v.test)} ({n_test} "
            f"samples) | {r.level:.4g} | {_pct(r.tuned.accuracy_ci())} | "
            f"{_pct(r.reference.accuracy_ci())} | {_points(r.tuned.change_against(r.reference))} |"
        )
    return lines


def plot_robustness(rows: Sequence[VariationResult], path: Path) -> None:
    """Left: tuned − reference [points] per variation with its 95 % CI and the zero line;
    right: both accuracies [%] with theirs."""
    plt = _pyplot()
    labels = [r.variation.label for r in rows]
    y = list(range(len(rows)))[::-1]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 0.45 * len(rows) + 1.6), sharey=True)
    change = [r.tuned.change_against(r.reference) for r in rows]
    left.errorbar([100 * c.mean for c in change], y, fmt="o", color="k",
                  xerr=[[100 * (c.mean - c.low) for c in change],
                        [100 * (c.high - c.mean) for c in change]])  # fmt: skip
    left.axvline(0.0, color="grey", lw=1)
    left.set_xlabel("tuned − reference [points]")
    left.set_yticks(y, labels)
    for offset, name, color in ((0.15, "tuned", "C0"), (-0.15, "reference", "C1")):
        ci = [getattr(r, name).accuracy_ci() for r in rows]
        right.errorbar([100 * c.mean for c in ci], [v + offset for v in y], fmt="o", color=color,
                       xerr=[[100 * (c.mean - c.low) for c in ci],
                             [100 * (c.high - c.mean) for c in ci]], label=name)  # fmt: skip
    right.set_xlabel("held-out accuracy [%]")
    right.legend(loc="lower right", fontsize="small")
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)


def write_robustness_report(
    rows: Sequence[VariationResult], out: Path, networks: dict[str, str], command: str | None
) -> Path:
    """Write the folder (module docstring) into ``out`` and return the path of ``summary.md``;
    ``networks`` names the ``"tuned"`` and ``"reference"`` network files or presets."""
    out.mkdir(parents=True, exist_ok=True)
    plot_robustness(rows, out / "robustness.png")
    verdict = (
        "The gain survives: its interval is above zero in every variation."
        if survives(rows)
        else "The gain does **not** survive: its interval reaches zero in some variation."
    )
    lines = ["# Robustness of a tuned network's figure", ""]
    if command:
        lines += ["Command:", "", f"    {command}", ""]
    lines += [
        f"Tuned network `{networks['tuned']}` against reference `{networks['reference']}`, "
        "both on the same spike trains; trained on the first recordings, tested once on the "
        "second; 95 % CIs by a bootstrap over the test recordings, the change paired sample "
        "by sample. " + verdict,
        "",
        *table_lines(rows),
        "",
        "![robustness](robustness.png)",
    ]
    write_results(out / "results.json", {"command": command, "networks": networks,
                                         "survives": survives(rows),
                                         "variations": [r.to_dict() for r in rows]})  # fmt: skip
    summary = out / "summary.md"
    write_text(summary, "\n".join(lines) + "\n")
    return summary

"""The ``summary.md`` of ``spll-hw report`` (accuracy per layout × chip profile, what each chip
costs, error against run time), one small function per section, and its console lines.

Changes are in accuracy points, a cell minus the unconstrained time-scaled reference
(:data:`spll_hw.harness.accuracy.REFERENCE`): negative is a loss.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from ..harness.accuracy import REFERENCE, AccuracyTable, Column, accuracy_text
from ..stats import Interval


@dataclass(frozen=True)
class ConstraintsRun:
    """What one ``spll-hw report`` run measured, as its summary shows it.

    Attributes:
        command: the command as typed (``None`` when run from Python).
        setting: one paragraph: dataset, encoder, network, noise and scoring scheme.
        table: the accuracy of every layout × profile cell.
        columns: the table's columns and the backends that computed them.
        chip_draws: mismatch draws pooled per analog-profile cell.
        pictures: the accuracy figures (PNG names in the report folder), shown first.
        constructions: the constructions scored against the exact cells
            (:func:`spll_hw.harness.construction.construction_cost`), maybe none.
        costs: each layout's NeuroBench metrics on every column, and its fit and cost on
            every chip with tables (:func:`spll_hw.harness.costs.layout_costs`), maybe none.
        costed_samples: samples of the dataset the costs are averaged over.
        work_precision: the error-against-run-time rows of the backends.
        confusions: one confusion-matrix PNG name per scored cell.
    """

    command: str | None
    setting: str
    table: AccuracyTable
    columns: Sequence[Column]
    chip_draws: int
    pictures: Sequence[str]
    constructions: Sequence
    costs: Sequence
    costed_samples: int
    work_precision: Sequence
    confusions: Sequence[str]


def points(ci: Interval) -> str:
    """``-1.2 points [-2.0, -0.4]``: a change (fractions) and its interval in accuracy points."""
    return f"{100 * ci.mean:+.1f} points [{100 * ci.low:+.1f}, {100 * ci.high:+.1f}]"


def headline(table: AccuracyTable) -> str:
    """The report's answer in one line: on each chip profile, the layout that loses least
    against the exact time-scaled network (without a reference cell: the most accurate cell)."""
    scored = [c for c in table.cells if c.cv is not None]
    if not scored:
        return "**No layout fits any profile**: each cell below says why."
    if not table.has_reference:
        best = max(scored, key=lambda c: c.cv.accuracy)
        return (
            f"**Most accurate: {best.layout} under {best.profile}**, {accuracy_text(best.cv)} "
            "(no exact time-scaled reference cell to measure losses against)."
        )
    profiles = list(dict.fromkeys(c.profile for c in table.cells))
    chips = [p for p in profiles if p != REFERENCE[1]] or profiles
    parts = []
    for profile in chips:
        cells = [c for c in scored if c.profile == profile and (c.layout, c.profile) != REFERENCE]
        if not cells:
            parts.append(f"{profile}: no layout fits")
            continue
        change = {c.layout: table.change_ci(c.layout, c.profile) for c in cells}
        layout = max(change, key=lambda name: change[name].mean)
        tie = "" if change[layout].distinct else ", a tie"
        parts.append(f"{profile}: {layout}, {points(change[layout])}{tie}")
    return (
        "**Least accuracy lost against the exact time-scaled network** (change, 95 % CI): "
        + "; ".join(parts)
        + "."
    )


def accuracy_section(run: ConstraintsRun) -> str:
    """The pictures, how to read the table, its columns' backends and the table."""
    draws = (
        f" (analog profiles: {run.chip_draws} mismatch draws pooled)"
        if any(c.draws for c in run.columns)
        else ""
    )
    return (
        "## Accuracy per layout x constraint profile\n\n"
        + "".join(f"![{f}]({f})\n\n" for f in run.pictures)
        + "Accuracy: mean ± half-width of its 95 % CI. In brackets: the change in points against "
        "the unconstrained time-scaled network (this cell minus the reference: negative is a "
        "loss), paired (fold by fold under CV: corrected resampled t, which accounts for "
        "overlapping training folds; sample by sample on held-out recordings: bootstrap over "
        "recordings), with its 95 % CI; **bold** changes are distinguishable from zero, the "
        f"others are ties. Each column's features come from one backend{draws}:\n\n"
        + "".join(f"- {c.label}: `{c.spec}`\n" for c in run.columns)
        + f"\n{run.table.markdown()}\n\n"
    )


def construction_section(costed: Sequence) -> str:
    """What each construction costs against the exact cells (empty without constructions)."""
    from ..harness.construction import markdown

    if not costed:
        return ""
    return (
        "## What the construction costs\n\n![construction](construction.png)\n\n"
        "Each construction (a backend that approximates the exact sPLL on purpose) scored "
        "on the same samples, folds and draws as the exact table; in brackets its paired "
        "change against the exact cell of the same layout and profile, in points, with "
        f"its 95 % CI (**bold**: distinguishable from zero).\n\n{markdown(costed)}\n\n"
    )


def costs_section(costs: Sequence, costed_samples: int) -> str:
    """Each layout's fit, cores, energy and latency on every chip with tables, then
    NeuroBench's metrics of every layout × column (empty without costs)."""
    from ..harness.costs import markdown

    if not costs:
        return ""
    chip = ""
    if any(c.fit is not None for c in costs):
        chip = (
            "## Chips: fit, cores, energy and latency\n\nEach layout mapped onto the chip of "
            f"every column with chip tables, costed on {costed_samples} of the dataset's samples "
            "simulated on the column's backend (`spll-hw chips` lists every figure and its "
            "source; `*`: rests on assumed figures). The headline is the dynamic energy, event "
            "counts × per-event costs, with the share of it that rests on assumed figures; "
            "static and core power × time on chip is shown apart and enters neither the "
            f"accuracy-energy front nor a tuning objective.\n\n{markdown(costs)}\n\n"
        )
    return chip + neurobench_section(costs, costed_samples)


def neurobench_section(costs: Sequence, costed_samples: int) -> str:
    """NeuroBench's metrics (:mod:`spll_hw.harness.neurobench`) of every layout × column."""
    from ..harness.neurobench import REFERENCE_DT, markdown

    rows = [(c.layout, c.column, c.neurobench) for c in costs]
    return (
        "## NeuroBench metrics\n\nNeuroBench 2.3's metrics (Yik et al., Nat. Commun. 2025), "
        f"counted natively from the spike counts of the same {costed_samples} samples, per "
        "sample. Footprint: parameters and state at the profile's word widths (float32 "
        "without them, as NeuroBench counts a torch model). Connection sparsity and dense "
        "synaptic operations: the network as three dense connection layers (input → TDE, "
        "CCO → TDE, TDE → CCO). Activation sparsity, dense SynOps and neuron updates: at the "
        "profile's time step, or at the reference step "
        f"{REFERENCE_DT * 1e6:g} µs where the profile has none. Effective ACs: input and "
        "feedback deliveries; the TDE gate (trigger current += gain × facilitatory current on "
        "a CCO spike) is a multiply-accumulate, one per CCO spike, in its own column. Time to "
        "decision replaces the model execution rate: the rates are read at the end of the "
        "window, so it is the window, or the time on chip when the chip is slower. "
        f"Definitions: docs/neurobench.md.\n\n{markdown(rows)}\n\n"
    )


def work_precision_section(rows: Sequence) -> str:
    """The error-against-run-time table and its plot."""
    from ..harness.workprecision import markdown_table

    return (
        f"## Error against run time (golden model = truth)\n\n{markdown_table(rows)}\n\n"
        "![work-precision](work_precision.png)\n"
    )


def quantization_section(table: AccuracyTable) -> str:
    """The per-parameter quantization report of every profile on the first layout."""
    first = table.cells[0].layout if table.cells else None
    reports = "".join(
        f"\n### {c.layout} under {c.profile}\n\n{c.report}\n"
        for c in table.cells
        if c.report and c.layout == first
    )
    return f"\n## Quantization reports\n{reports}" if reports else ""


def summary(run: ConstraintsRun) -> str:
    """The whole ``summary.md``: the answer in one line, then the sections."""
    command = f"`{run.command}`\n\n" if run.command else ""
    return (
        f"# Hardware constraints report\n\n{headline(run.table)}\n\n{command}{run.setting}\n\n"
        + accuracy_section(run)
        + construction_section(run.constructions)
        + costs_section(run.costs, run.costed_samples)
        + work_precision_section(run.work_precision)
        + quantization_section(run.table)
        + "\n## Appendix: confusion matrices\n\n"
        + "".join(f"![{f}]({f})\n" for f in run.confusions)
    )


def clamped_lines(layout: str, profile: str, realisation) -> list[str]:
    """One line per parameter that chip ``profile`` clamps at a limit of its formats in the
    ``layout`` network, summarised over the sPLLs, e.g. ``loihi2, time-scaled: tau_cco
    clamped in 3/50 sPLLs (worst -58 %; requested 0.01 ... 0.3, realised ...)``; none for a
    realisation without a per-parameter report (``realisation.detail.report``)."""
    report = getattr(realisation.detail, "report", None)
    if report is None:
        return []
    return [
        f"{profile}, {layout}: {s['name']} clamped in {s['saturated']}/{s['n']} sPLLs (worst "
        f"{100 * s['worst_rel_error']:+.0f} %; requested {_span(s['requested'])}, realised "
        f"{_span(s['realised'])})"
        for s in report.summary()
        if s["saturated"]
    ]


def _span(pair: tuple[float, float]) -> str:
    low, high = pair
    return f"{low:.4g}" if low == high else f"{low:.4g} ... {high:.4g}"

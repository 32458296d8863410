"""The ``summary.md`` of ``spll-hw report`` (accuracy per layout × chip profile, what each chip
costs, error against run time), one small function per section, and its console lines.

Changes are in accuracy points, a cell minus the unconstrained time-scaled reference
(:data:`spll_hw.harness.accuracy.REFERENCE`): negative is a loss.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from .. import backends
from ..chips import format_joules
from ..harness.accuracy import REFERENCE
from ..harness.breakdown import levers
from ..harness.breakdown import markdown as breakdown_table
from ..harness.costs import CHOICE_RULE, cheapest_ties, choose
from ..harness.costs import markdown as costs_table
from ..harness.neurobench import REFERENCE_DT
from ..harness.neurobench import markdown as neurobench_table
from ..harness.workprecision import markdown_table
from ..stats import Interval

if TYPE_CHECKING:
    from ..harness.accuracy import ScoredCell
    from .results import ReportResults


def points(ci: Interval) -> str:
    """``-1.2 points [-2.0, -0.4]``: a change (fractions) and its interval in accuracy points."""
    return f"{100 * ci.mean:+.1f} points [{100 * ci.low:+.1f}, {100 * ci.high:+.1f}]"


def headline(cells: Sequence[ScoredCell], costs: Sequence = (), note: str = "") -> str:
    """The report's answer in one line: on each column, the layout that loses least against
    the exact time-scaled network, chosen among the layouts that tie it by the one rule of
    every headline (:data:`spll_hw.harness.costs.CHOICE_RULE`, priced by ``costs``), with
    the part of the rule that chose it; without a reference cell, the most accurate cell.
    ``note``: a word on the sample size (:meth:`~.results.ReportResults.sample_note`), kept
    on the same line."""
    scored = [c for c in cells if c.accuracy is not None]
    tail = f" {note}" if note else ""
    if not scored:
        return "**No layout fits any profile**: each cell below says why."
    if not any(c.change is not None for c in scored):
        best = max(scored, key=lambda c: c.mean)
        return (
            f"**Most accurate: {best.layout} under {best.column}**, {accuracy_text(best.accuracy)} "
            f"(no exact time-scaled reference cell to measure losses against).{tail}"
        )
    profiles = list(dict.fromkeys(c.column for c in cells))
    chips = [p for p in profiles if p != REFERENCE[1]] or profiles
    parts = []
    for profile in chips:
        column = [c for c in scored if c.column == profile and (c.layout, c.column) != REFERENCE]
        if not column:
            parts.append(f"{profile}: no layout fits")
            continue
        chosen = choose(column, costs)
        parts.append(f"{profile}: {chosen.layout}, {points(chosen.change)} ({chosen.words()})")
    return (
        "**Least accuracy lost against the exact time-scaled network** (change, 95 % CI; one "
        "rule picks among the layouts that tie it, and says which part chose): "
        + "; ".join(parts)
        + f".{tail}"
    )


def energy_headline(cells: Sequence[ScoredCell], costs: Sequence) -> str:
    """The cost side's answer in one line: per chip, the layout × step that ties the exact
    network at the least dynamic energy (:func:`spll_hw.harness.costs.cheapest_ties`, the
    rule of :func:`headline`), with its range over the figures' ranges and the part of the
    rule that chose it; empty without costed chip cells."""
    found = cheapest_ties(cells, costs)
    if not found:
        return ""
    parts = []
    for f in found:
        if f.cell is None:
            parts.append(f"{f.chip}: no costed cell ties the exact network")
            continue
        c = f.cell
        example = f", e.g. {f.rivals[0]}" if f.rivals else ""
        parts.append(
            f"{f.chip}: {c.layout} on {c.column}, {c.energy.dynamic_range} "
            f"({points(f.change)}, {c.fit.cores} core(s); {f.words()}{example})"
        )
    return (
        "**Least dynamic energy per sample at a tie with the exact network** ([low, high] over "
        "the figures' ranges; accuracy change, 95 % CI): " + "; ".join(parts) + "."
    )


def setting(results: ReportResults) -> str:
    """One paragraph: dataset, encoder, network, noise and how the cells are scored."""
    s = results.scoring
    if results.test_samples is not None:
        scheme = (
            f"trained on these samples and tested once on {results.test_samples} samples of the "
            f"held-out recordings {s.test_recordings} (intervals: bootstrap over test recordings)"
        )
    else:
        scheme = f"{s.cv_repeats} x {s.folds}-fold CV of {s.cv}, the same folds for every cell"
    return (
        f"Dataset `{results.dataset}` ({results.samples} samples, {len(results.class_names)} "
        f"classes), encoder `{results.encoder}`, network `{results.network}` "
        f"({results.n_spll} sPLLs), phase noise {s.phase_noise:g} s x {s.repeats} draw(s), "
        f"{scheme}."
    )


def accuracy_section(results: ReportResults, pictures: Sequence[str]) -> str:
    """The pictures, how to read the table, its columns' backends and the table."""
    draws = (
        f" (analog profiles: {results.scoring.chip_draws} mismatch draws pooled)"
        if any(c.draws for c in results.columns)
        else ""
    )
    return (
        "## Accuracy per layout x constraint profile\n\n"
        + "".join(f"![{f}]({f})\n\n" for f in pictures)
        + "Accuracy: mean ± half-width of its 95 % CI. In brackets: the change in points against "
        "the unconstrained time-scaled network (this cell minus the reference: negative is a "
        "loss), paired (fold by fold under CV: corrected resampled t, which accounts for "
        "overlapping training folds; sample by sample on held-out recordings: bootstrap over "
        "recordings), with its 95 % CI; **bold** changes are distinguishable from zero, the "
        f"others are ties. The answer above names, per column, one layout by one rule: "
        f"{CHOICE_RULE}. Each column's features come from one backend{draws}:\n\n"
        + "".join(f"- {c.label}: `{backends.label(c.spec)}`\n" for c in results.columns)
        + (f"\n{note}\n" if (note := results.sample_note()) else "")
        + f"\n{accuracy_table(results.cells)}\n\n"
    )


def accuracy_table(cells: Sequence[ScoredCell]) -> str:
    """Accuracy (mean ± 95 % CI half-width) and its paired change against the reference with
    its 95 % CI, per layout (rows) × column; a change in bold is distinguishable from zero,
    one in plain text a tie."""
    layouts = list(dict.fromkeys(c.layout for c in cells))
    profiles = list(dict.fromkeys(c.column for c in cells))
    by_key = {(c.layout, c.column): c for c in cells}
    lines = ["| layout | " + " | ".join(profiles) + " |", "|---" * (len(profiles) + 1) + "|"]
    for layout in layouts:
        row = []
        for profile in profiles:
            c = by_key[layout, profile]
            if c.accuracy is None:
                row.append("does not fit")
                continue
            text = accuracy_text(c.accuracy)
            if c.change is not None and (layout, profile) != REFERENCE:
                text += " (" + change_text(c.change) + ")"
            row.append(text)
        lines.append(f"| {layout} | " + " | ".join(row) + " |")
    return "\n".join(lines)


def accuracy_text(ci: Interval) -> str:
    """``54.6 ± 1.8 %``: an accuracy and the half-width of its 95 % CI."""
    return f"{100 * ci.mean:.1f} ± {100 * ci.half_width:.1f} %"


def change_text(ci: Interval) -> str:
    """``**-7.9** [-11.9, -3.9]`` (bold: distinguishable from zero) in accuracy points."""
    mean = f"{100 * ci.mean:+.1f}"
    return f"{f'**{mean}**' if ci.distinct else mean} [{100 * ci.low:+.1f}, {100 * ci.high:+.1f}]"


def construction_section(costed: Sequence) -> str:
    """What each construction costs against the exact cells, in accuracy and on the chip
    (empty without constructions)."""
    if not costed:
        return ""
    return (
        "## What the construction costs\n\n![construction](construction.png)\n\n"
        "Each construction (a backend that approximates the exact sPLL on purpose) scored "
        "on the same samples, folds and draws as the exact table; in brackets its paired "
        "change against the exact cell of the same layout and profile, in points, with "
        "its 95 % CI (**bold**: distinguishable from zero). Beside it, what it costs the way "
        "its target realises it: a construction backend with a graph of standard neurons "
        "(`nir-numpy`, `standard-fixed-point`) has its neurons and synapses at its step (the "
        "profile's step where the profile is stepped), placed on the profile's chip (cores) "
        "and costed from each run's spike count of every neuron on the same samples, figures "
        "and rule as the two-compartment sPLL's cells (dynamic energy per sample, `[low, "
        "high]` over the figures' ranges); the last column sets it against the "
        "two-compartment sPLL of the same layout and column (more or less at every figure in "
        "its range, or a ranking that flips inside it). `-`: not costed (no chip tables, or "
        "a backend with no graph of neurons, such as `standard-exact`).\n\n"
        f"{construction_table(costed)}\n\n"
    )


def construction_table(cells: Sequence) -> str:
    """One row per construction x layout x profile: the exact cell's accuracy, the
    construction's accuracy and, in brackets, its paired change against exact in points
    (bold: distinguishable from zero), then what it costs (neurons, synapses, step, cores,
    dynamic energy per sample [low, high]) and how that compares with the two-compartment
    sPLL's of the same cell."""
    lines = [
        "| construction | layout | profile | exact | construction (change) | neurons | synapses "
        "| step | cores | dynamic energy / sample [low, high] (at the figures' values) "
        "| against the two-compartment sPLL |",
        "|---|---|---|---|---|---:|---:|---|---:|---:|---|",
    ]
    for c in cells:
        accuracy = "does not fit" if c.accuracy is None else accuracy_text(c.accuracy)
        if c.change is not None:
            accuracy += f" ({change_text(c.change)})"
        exact = accuracy_text(c.exact) if c.exact else "does not fit"
        graph = None if c.cost is None else c.cost.graph
        fit = None if c.cost is None else c.cost.fit
        energy = None if c.cost is None else c.cost.energy
        size = (
            ["-", "-", "-"]
            if graph is None
            else [str(graph.neurons), str(graph.synapses), graph.step_words().removeprefix("dt = ")]
        )
        cores = "-" if fit is None else str(fit.cores) if fit.fits else (
            "no: " + "; ".join(fit.problems))  # fmt: skip
        dynamic = "-" if energy is None else (
            f"{energy.dynamic_range} ({format_joules(energy.dynamic)})")  # fmt: skip
        against = "-" if c.against is None else c.against.words()
        row = [f"`{c.construction}`", c.layout, c.profile, exact, accuracy, *size, cores,
               dynamic, against]  # fmt: skip
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def costs_section(costs: Sequence, costed_samples: int) -> str:
    """Each layout's fit, cores, energy and latency on every chip with tables, then
    NeuroBench's metrics of every layout × column (empty without costs)."""
    if not costs:
        return ""
    chip = ""
    if any(c.fit is not None for c in costs):
        chip = (
            "## Chips: fit, cores, energy and latency\n\nEach layout mapped onto the chip of "
            f"every column with chip tables, costed on {costed_samples} of the dataset's samples "
            "simulated on the column's backend (`spll-hw chips` lists every figure and its "
            "source; `*`: rests on assumed figures). The headline is the dynamic energy, event "
            "counts × per-event costs, as the range the figures allow: `[low, high]` with every "
            "figure at its low and at its high end (`spll-hw chips` gives each end's source), "
            "then at the figures' single values, with the share that rests on assumed figures. "
            "One cell is called cheaper than another only where that holds wherever the figures "
            "lie in their ranges (cells of two chips: only where their ranges do not overlap), "
            "and the accuracy-energy front keeps a cell unless another is at least as accurate "
            "and cheaper at both ends. Static and core power × the window (one rule for every "
            "chip: powered for the whole sample, longer only where it cannot keep up) is shown "
            f"apart and enters neither the accuracy-energy front nor a tuning objective.\n\n"
            f"{costs_table(costs)}\n\n" + breakdown_section(costs)
        )
    return chip + neurobench_section(costs, costed_samples)


def breakdown_section(costs: Sequence) -> str:
    """What each costed cell's dynamic energy is spent on: the picture, the table and, per
    largest part, what cuts it (empty without costed cells)."""
    table = breakdown_table(costs)
    if not table:
        return ""
    return (
        "### What the energy is spent on\n\n![energy breakdown](energy_breakdown.png)\n\n"
        "Each cell's dynamic energy per sample split by what the chip pays for (count × "
        "figure): **neuron updates** (every compartment, every step), **synaptic events** "
        "(input, trigger and feedback deliveries), **spikes**, **messages and hops** (between "
        "cores and routers), **per-step energy** (the chip's own work per step, whatever runs); "
        "each at the figures' values with its share of the dynamic total, the total as "
        "`[low, high]` over the figures' ranges, static energy apart (docs/neurobench.md). "
        f"{levers(costs)}\n\n{table}\n\n"
    )


def neurobench_section(costs: Sequence, costed_samples: int) -> str:
    """NeuroBench's metrics (:mod:`spll_hw.harness.neurobench`) of every layout × column."""
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
        f"Definitions: docs/neurobench.md.\n\n{neurobench_table(rows)}\n\n"
    )


def work_precision_section(rows: Sequence) -> str:
    """The error-against-run-time table and its plot."""
    return (
        f"## Error against run time (golden model = truth)\n\n{markdown_table(rows)}\n\n"
        "![work-precision](work_precision.png)\n"
    )


def quantization_section(cells: Sequence[ScoredCell]) -> str:
    """The per-parameter quantization report of every profile on the first layout."""
    first = cells[0].layout if cells else None
    reports = "".join(
        f"\n### {c.layout} under {c.column}\n\n{c.report}\n"
        for c in cells
        if c.report and c.layout == first
    )
    return f"\n## Quantization reports\n{reports}" if reports else ""


def summary(results: ReportResults, pictures: Sequence[str], confusions: Sequence[str]) -> str:
    """The whole ``summary.md``: the answer in one line, then the sections; ``pictures`` are
    the accuracy figures (PNG names in the report folder), shown first, ``confusions`` one
    confusion-matrix PNG name per scored cell."""
    command = f"`{results.command}`\n\n" if results.command else ""
    return (
        "# Hardware constraints report\n\n"
        f"{headline(results.cells, results.costs, results.sample_note())}\n\n"
        + (f"{energy}\n\n" if (energy := energy_headline(results.cells, results.costs)) else "")
        + f"{command}"
        f"{setting(results)}\n\n"
        + accuracy_section(results, pictures)
        + construction_section(results.constructions)
        + costs_section(results.costs, results.costed_samples)
        + work_precision_section(results.work_precision)
        + quantization_section(results.cells)
        + "\n## Appendix: confusion matrices\n\n"
        + "".join(f"![{f}]({f})\n" for f in confusions)
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

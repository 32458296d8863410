"""``spll-hw chips``: the chip profiles as resources and costs.

Without ``--network`` it lists every profile with its resources, timing and energy figures and
the source of each. With ``--network`` it maps the network onto each profile that has a
``[resources]`` table and reports whether it fits, on how many cores and chips, the energy of
one Poisson sample (its spike counts from the golden model of the network as that chip
realises it, or from ``--backend``): the dynamic energy (event counts × per-event costs) with
the share of it that rests on assumed figures, static power apart; the step latency and
real-time factor; and NeuroBench's metrics of the sample on each chip and on no chip
(:mod:`spll_hw.harness.neurobench`), as Markdown, with ``results.json`` in ``--out``. Every
figure no public source gives is marked *assumed*. A ``--backend`` that runs a construction of
standard neurons (``nir-numpy``, ``standard-fixed-point``: what ``export --to nir-standard`` and
``--to lava-standard`` write) has that construction placed and costed, every neuron and synapse
at its step (:mod:`spll_hw.neuron_graph`), in place of the two-compartment sPLL.

With ``--export FOLDER`` it costs an export folder from its files, as the folder's ``cost.json``
states it (:mod:`spll_hw.exporters.cost`), on ``--profiles`` too.

With a multichannel ``--network`` (one sPLL network per sensor channel,
:mod:`spll_hw.multichannel.chips`) it maps that onto each profile: fits or why not, cores, which
channel's sPLLs on which core, input messages per channel spike, and the energy, latency and
real-time factor of one classification (the first ``--windows`` s of every channel) of the
BioTac recordings ``--recordings`` of ``--data``.
"""

from __future__ import annotations

import argparse

from tqdm.auto import tqdm

from ... import backends, chips
from ...exporters.cost import folder_report
from ...files import atomic_folder, write_results, write_text
from ...harness import neurobench
from ...multichannel.cost_report import report as multichannel_report
from ...neuron_graph import graph_cost, graph_resources, run_by
from ...simulate import poisson_spikes
from ..arguments import split_list
from ..chips import ASSUMED_MARK
from ..inputs import is_multichannel, read_network, stepped_profiles

#: Seconds after which ``--network`` shows a bar over the profiles it places, simulates and
#: costs (a 2000-sPLL network takes seconds a profile on the 2-core development machine).
PROGRESS_DELAY = 5.0

#: Units for showing figures by kind of key, (scale, unit).
_UNITS = {"s": (1e9, "ns"), "J": (1e12, "pJ"), "W": (1e3, "mW")}


def run(args: argparse.Namespace) -> int:
    if args.export is not None:
        if args.network or args.steps or args.backend:
            raise ValueError(
                "--export costs FOLDER as it was written, at its own step and on its own run: "
                "drop --network, --steps and --backend"
            )

        profiles = split_list(args.profiles) or None
        for name in profiles or ():
            chips.describe(name)
        text, payload = folder_report(args.export, profiles)
        return _written(args, text, payload)
    names = stepped_profiles(split_list(args.profiles) or chips.names(), args.steps)
    for name in names:
        chips.describe(name)  # an unknown or broken profile fails before any work
    if is_multichannel(args.network):
        text, payload = multichannel_report(args, names)
    elif args.network is None:
        if args.layout:
            raise ValueError("--layouts needs --network")
        print(listing(names))
        return 0
    else:
        text, payload = report(args, names)
    return _written(args, text, payload)


def _written(args: argparse.Namespace, text: str, payload: dict) -> int:
    """Write the report into ``--out`` and print it."""
    with atomic_folder(args.out) as out:
        write_text(out / "summary.md", text + "\n")
        write_results(out / "results.json", payload)
    print(text)
    print(f"\nreport: {args.out / 'summary.md'}")
    return 0


def _show(figure) -> str:
    """A figure's value in readable units (ns, pJ, mW) with its range ``[low, high]``, and the
    assumed mark."""
    value = figure.value
    if figure.unit in _UNITS:
        scale, unit = _UNITS[figure.unit]
        shown = f"{value * scale:.4g} {unit}"
        if figure.low is not None:
            shown += f" [{figure.low * scale:.4g}, {figure.high * scale:.4g}]"
    elif isinstance(value, list):
        shown = ", ".join(value)
    else:
        shown = str(value).lower() if isinstance(value, bool) else f"{value}"
    return f"{shown} {ASSUMED_MARK}" if figure.assumed else shown


def _sources(figure) -> str:
    """The figure's source, and each end's where it has a range."""
    if figure.low is None:
        return figure.source
    return f"{figure.source}; low: {figure.low_source}; high: {figure.high_source}"


def listing(names: list[str]) -> str:
    """Markdown: every profile, its figures and their sources."""
    out = ["# Chip profiles", ""]
    for name in names:
        info = chips.describe(name)
        out += [f"## {info.name} ({info.kind})", "", info.description, ""]
        figures = chips.figures(name)
        if not figures:
            out += ["No [resources], [timing] or [energy] tables: number formats only.", ""]
            continue
        out += ["| table | figure | value | source |", "|---|---|---:|---|"]
        out += [f"| {f.table} | {f.key} | {_show(f)} | {_sources(f)} |" for f in figures]
        out.append("")
    out.append(f"{ASSUMED_MARK} assumed: no public source gives this figure (see its source). "
               "[low, high]: the range the public sources allow, each end with its own source; "
               "every cost is also given at both ends.")  # fmt: skip
    return "\n".join(out)


def _arithmetic(network, name: str, graph, entry: dict) -> str:
    """The table's cell of :func:`spll_hw.chips.arithmetic_error` on a clocked chip (``-``
    elsewhere and for a construction, which is not run in the chip's arithmetic), recorded in
    ``entry`` as ``arithmetic_error`` (a fraction, ``None`` where not measured)."""
    found = None if graph is not None else chips.arithmetic_error(network, name)
    entry["arithmetic_error"] = None if found is None else found[0]
    return "-" if found is None else chips.percent_off(found[0])


def _share(part: float, whole: float) -> str:
    return "-" if whole == 0 else f"{100 * part / whole:.0f} %"


def report(args: argparse.Namespace, names: list[str]) -> tuple[str, dict]:
    """The Markdown report and JSON payload of ``--network`` on every profile of ``names``."""
    if not (args.rate >= 0 and args.duration > 0):
        raise ValueError("--rate must be >= 0 and --duration > 0")
    config = read_network(args).config
    network = config.build()
    train = poisson_spikes(args.rate, args.duration, args.seed)
    rows, details, skipped, results, refused = [], [], [], [], []
    exact = backends.get("golden").simulate(network, train, args.duration)
    bench = [("none", "golden", neurobench.from_results(network, [exact], args.duration))]
    costed: dict[str, None] = {}  # the constructions costed, in order
    bar = tqdm(names, desc=f"chips: {network.n_spll} sPLLs on each profile", unit="profile",
               leave=False, delay=PROGRESS_DELAY)  # fmt: skip
    for name in bar:
        if not any(f.table == "resources" for f in chips.figures(name)):
            skipped.append(name)
            continue
        try:
            backend, graph = run_by(args.backend, network, name)
        except ValueError as exc:
            if "@" not in name:
                raise
            refused.append(f"- {exc}")  # a step of a ladder the chip cannot write it at
            results.append({"profile": name, "refused": str(exc)})
            continue
        if graph is None:
            fit = chips.resources(chips.OnChip(network, name))
        else:
            fit = graph_resources(graph, name)
            costed[f"{graph.target}: {graph.description}, {graph.step_words()}"] = None
        entry = {"profile": name, "resources": fit.data}
        arithmetic = _arithmetic(network, name, graph, entry)
        dynamic = share = static = latency = rtf = "-"
        assumed = list(fit.assumed)
        section = [f"## {name}", "", fit.markdown]
        if fit.cores:
            result = backend.simulate(network, train, args.duration)
            if graph is None:
                cost = chips.cost(chips.OnChip(network, name), result)
            else:
                cost = graph_cost(graph, name, result)
            assumed = list(dict.fromkeys(assumed + list(cost.assumed)))
            mark = f" {ASSUMED_MARK}" if cost.assumed else ""
            dynamic = f"{cost.dynamic_range} ({chips.format_joules(cost.dynamic_energy)}"
            dynamic += f" {ASSUMED_MARK})" if cost.assumed_dynamic_energy else ")"
            share = _share(cost.assumed_dynamic_energy, cost.dynamic_energy)
            if cost.static_range is not None:
                static = str(cost.static_range) + (
                    f" {ASSUMED_MARK}" if cost.assumed_static_energy else ""
                )
            metrics = None
            if graph is None:  # NeuroBench's counts are the two-compartment sPLL's
                info = chips.describe(name)
                metrics = neurobench.from_results(
                    network, [result], args.duration, info, cost.time_on_chip
                )
                bench.append((name, result.backend, metrics))
            if cost.step_latency is not None:
                latency = f"{cost.step_latency * 1e6:.3g} µs{mark}"
            if cost.real_time_factor is not None:
                rtf = f"{cost.real_time_factor:.3g}{mark}"
            entry |= {
                "backend": result.backend,
                "cost": cost.data,
                "energy_j": {
                    "dynamic": cost.dynamic_energy,
                    "dynamic_range": [cost.dynamic_range.low, cost.dynamic_range.high],
                    "dynamic_assumed": cost.assumed_dynamic_energy,
                    "static": cost.static_energy,
                    "static_range": None
                    if cost.static_range is None
                    else [cost.static_range.low, cost.static_range.high],
                    "static_assumed": cost.assumed_static_energy,
                    "figure_counts": cost.figure_counts,
                },
                "neurobench": None if metrics is None else metrics.to_dict(),
            }
            section += ["", f"Sample through `{result.backend}`:", "", cost.markdown]
        rows.append(
            f"| {name} | {'yes' if fit.fits else 'no'} | {fit.cores} | {fit.chips} | {arithmetic} "
            f"| {dynamic} "
            f"| {share} | {static} | {latency} | {rtf} | {', '.join(assumed) or '-'} |"
        )
        details += section + [""]
        results.append(entry)
    construction = [] if not costed else [
        "Costed in place of the two-compartment sPLL: the construction of standard neurons "
        f"that `{args.backend}` runs, every neuron and synapse at its step ({'; '.join(costed)}"
        "); a stepped profile (NAME@STEP) builds it at that step.",
        "",
    ]  # fmt: skip
    head = [
        "# Chips: fit and cost",
        "",
        f"`{args.network}` ({config.layout}, {network.n_spll} sPLLs); one Poisson sample of "
        f"{args.rate:g} Hz, {args.duration:g} s, seed {args.seed} ({train.size} input spikes).",
        "",
        *construction,
        "| profile | fits | cores | chips | TDE rates off golden in the chip's arithmetic "
        "| dynamic energy / sample [low, high] (at the "
        "figures' values) | of it on assumed figures | static energy / sample [low, high], "
        "apart | step latency | real-time factor | assumed figures |",
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|",
        *rows,
        "",
        "TDE rates off golden: the network in a clocked chip's own integer arithmetic "
        f"(`golden-fixed-point:profile=NAME`) on a {chips.ARITHMETIC_CHECK_S:g}-s Poisson "
        "train at its median free-running frequency, sum |r - golden's| / sum golden's (what "
        "`spll-hw export --to lava` judges against its limit; - for an analog chip or a "
        f"construction). {ASSUMED_MARK} rests on assumed figures (no public source). "
        "Dynamic energy: event counts (deliveries, spikes, messages, hops, neuron updates, "
        "steps) x per-event costs, "
        "as the range the figures allow (every figure at its low, then its high end; the "
        "listing without --network gives each end's source) and at the figures' single "
        "values; static energy: static and core power x the window (powered for the whole "
        "sample, longer only where the chip cannot keep up), shown apart (no part of the "
        "dynamic figure, of a front or of a tuning objective). Real-time factor: step latency "
        "/ time step (<= 1 keeps up with real time; 1 on an analog chip). A network that does "
        "not fit is costed on the placement it would need.",
    ]
    if refused:
        head += ["", "Steps refused (the chip cannot write the network there):", "", *refused]
    if skipped:
        head.append(f"Skipped (no [resources] table): {', '.join(skipped)}.")
    head += [
        "",
        "NeuroBench metrics of the same sample (docs/neurobench.md); `none` "
        "is the exact model at float32 and the reference step"
        + (" (those of the two-compartment sPLL: a construction's are left out)" if costed else "")
        + ":",
        "",
        neurobench.markdown(
            [(name, f"`{spec}`", m) for name, spec, m in bench], keys=("profile", "backend")
        ),
    ]
    payload = {
        "network": str(args.network),
        "layout": config.layout,
        "n_spll": network.n_spll,
        "rate_hz": args.rate,
        "duration_s": args.duration,
        "seed": args.seed,
        "n_input_spikes": int(train.size),
        "profiles": results,
        "skipped": skipped,
        "neurobench_exact": bench[0][2].to_dict(),
    }
    return "\n".join(head + [""] + details).rstrip(), payload

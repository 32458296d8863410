"""What each layout costs on each chip, beside its accuracy: fit, cores, energy and latency.

For every layout × chip-profile column of an accuracy table whose profile has chip tables
(``[resources]``, :mod:`spll_hw.chips`), :func:`layout_costs` maps the layout's network onto the
chip (fits or why not, cores, chips) and costs a few of the dataset's own samples, simulated on
the column's backend: energy per sample split by category, step latency and real-time factor.
:func:`plot_accuracy_energy` draws accuracy against energy per sample with the Pareto front
(no other cell is both more accurate and cheaper) marked.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from .. import backends, chips
from ..config import NetworkConfig
from ..pareto import front
from .accuracy import AccuracyTable, Column


@dataclass(frozen=True)
class CostCell:
    """One layout on one chip column: ``fit`` (:class:`spll_hw.chips.ChipFit`), the mean
    energy per sample [J] over the costed samples (``energy``, its per-event part
    ``event_energy``, both ``None`` without an ``[energy]`` table), step latency [s] and
    real-time factor (``None`` when not modelled), and the assumed figures it rests on."""

    layout: str
    column: str
    fit: chips.ChipFit
    energy: float | None
    event_energy: float | None
    step_latency: float | None
    real_time_factor: float | None
    assumed: tuple[str, ...]

    def to_dict(self) -> dict:
        return {
            "fits": self.fit.fits, "why": list(self.fit.problems), "cores": self.fit.cores,
            "chips": self.fit.chips, "energy_J": self.energy, "event_energy_J": self.event_energy,
            "step_latency_s": self.step_latency, "real_time_factor": self.real_time_factor,
            "assumed": list(self.assumed),
        }  # fmt: skip


_STATIC = ("static", "cores")  # categories that are power x time, not per event


def layout_costs(
    config: NetworkConfig,
    layouts: Sequence[str],
    columns: Sequence[Column],
    trains: Sequence[np.ndarray],
    duration: float,
) -> list[CostCell]:
    """Cost every layout on every column whose profile has chip tables (module docstring);
    ``trains`` are the samples costed (spike times [s], each sorted), ``duration`` their
    length [s]. Columns without a profile, or whose profile has no ``[resources]`` table, are
    skipped."""
    with_tables = {c.profile for c in columns if c.profile != "none" and chips.figures(c.profile)}
    out = []
    for layout in layouts:
        network = config.with_layout(layout).build()
        for col in columns:
            if col.profile not in with_tables:
                continue
            fit = chips.resources(network, col.profile)
            try:
                chips.realise(network, col.profile)
            except ValueError as exc:  # e.g. more circuits than an analog chip's groups
                out.append(_unrealisable(layout, col.label, fit, str(exc)))
                continue
            results = backends.get(col.spec).simulate_batch(network, list(trains), duration)
            costs = [chips.cost(network, col.profile, r) for r in results]
            total = [c.total_energy for c in costs]
            events = [
                sum(v for k, v in c.energy.items() if v is not None and k not in _STATIC)
                for c in costs
            ]
            has_energy = any(v is not None for v in costs[0].energy.values())
            out.append(
                CostCell(
                    layout, col.label, fit,
                    float(np.mean(total)) if has_energy else None,
                    float(np.mean(events)) if has_energy else None,
                    costs[0].step_latency, costs[0].real_time_factor,
                    tuple(sorted(set(fit.assumed) | {a for c in costs for a in c.assumed})),
                )
            )  # fmt: skip
    return out


def _unrealisable(layout: str, column: str, fit: chips.ChipFit, why: str) -> CostCell:
    """The cell of a layout the column's chip cannot realise at all (``why``): it does not
    fit, whatever its cores would hold, and costs nothing."""
    problems = fit.problems if why in fit.problems else (why, *fit.problems)
    fit = replace(fit, fits=False, problems=problems)
    return CostCell(layout, column, fit, None, None, None, None, fit.assumed)


def fits(network, profile: str) -> bool:
    """Whether ``network`` fits chip ``profile``: the profile realises it (circuit budgets of
    analog chips, representable parameters) and, where it has chip tables, its cores and
    configurations hold it."""
    try:
        chips.realise(network, profile)
    except ValueError:
        return False
    return not chips.figures(profile) or chips.resources(network, profile).fits


def auto_groups(config: NetworkConfig, profile: str) -> int:
    """The largest number of time-scale groups G (at most the network's ``n``) for which
    ``config``'s network in layout ``grouped:G`` fits chip ``profile``; ``ValueError`` when not
    even one group does."""
    for groups in range(config.n, 0, -1):
        if fits(config.with_layout(f"grouped:{groups}").build(), profile):
            return groups
    raise ValueError(
        f"no grouped layout of this network fits profile {profile!r}, not even one group"
    )


def markdown(cells: Sequence[CostCell]) -> str:
    """One row per layout × chip column: fit, cores, chips, energy per sample [µJ] (total and
    per-event part), step latency [µs], real-time factor; ``*`` marks values resting on
    assumed figures."""
    lines = [
        "| layout | chip column | fits | cores | chips | energy / sample [µJ] | of it per event "
        "[µJ] | step latency [µs] | real-time factor |",
        "|---|---|---|---:|---:|---:|---:|---:|---:|",
    ]
    for c in cells:
        star = " *" if c.assumed else ""
        fits = "yes" if c.fit.fits else "no: " + "; ".join(c.fit.problems)
        lines.append(
            f"| {c.layout} | {c.column} | {fits} | {c.fit.cores} | {c.fit.chips} | "
            f"{_number(c.energy, 1e6)}{star} | {_number(c.event_energy, 1e6)}{star} | "
            f"{_number(c.step_latency, 1e6)}{star} | {_number(c.real_time_factor, 1)}{star} |"
        )
    return "\n".join(lines)


def _number(value: float | None, scale: float) -> str:
    return "-" if value is None else f"{scale * value:.4g}"


def pareto(points: Sequence[tuple[float, float]]) -> list[bool]:
    """For ``(energy, accuracy)`` points: whether each is on the Pareto front (no other point
    has lower-or-equal energy and higher-or-equal accuracy, one of them strictly)."""
    best = set(front(points, (-1.0, 1.0)))  # energy minimised, accuracy maximised
    return [i in best for i in range(len(points))]


def plot_accuracy_energy(table: AccuracyTable, cells: Sequence[CostCell], path: Path) -> bool:
    """Accuracy [%] (95 % CI) against energy per sample [µJ] of every fitting layout × chip
    column with an energy model, Pareto front joined; ``False`` (nothing drawn) when no cell
    has both."""
    from ..report.figure_layout import legend_outside, place_labels, readable_log_axis
    from ..report.plots import _pyplot, accuracy_bars

    rows = []
    for c in cells:
        cv = table.cell(c.layout, c.column).cv
        if c.fit.fits and c.energy is not None and cv is not None:
            rows.append((c, cv.accuracy_ci()))
    if not rows:
        return False
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    front = pareto([(c.energy, ci.mean) for c, ci in rows])
    means, errors = accuracy_bars([ci for _, ci in rows])
    for k, ((c, _), best) in enumerate(zip(rows, front, strict=True)):
        ax.errorbar(1e6 * c.energy, means[k], yerr=errors[:, k : k + 1].tolist(), fmt="o",
                    color="C3" if best else "C0", capsize=2, zorder=3)  # fmt: skip
    line = sorted((1e6 * c.energy, 100 * ci.mean) for (c, ci), b in zip(rows, front, strict=True)
                  if b)  # fmt: skip
    ax.plot(*zip(*line, strict=True), "o-", color="C3", linewidth=1,
            label="Pareto front: no other cell\nis more accurate and cheaper")  # fmt: skip
    ax.plot([], [], "o", color="C0", label="not on the front")
    ax.set_xscale("log")
    readable_log_axis(ax.xaxis)
    ax.margins(x=0.25, y=0.08)
    ax.set_xlabel("energy per sample [µJ] (* assumed figures: see the cost table)")
    ax.set_ylabel("accuracy [%] (bars: 95 % CI)")
    ax.set_title("Accuracy against energy per sample (each point: layout, chip column)")
    legend_outside(ax)
    bars = [((1e6 * c.energy, m - lo), (1e6 * c.energy, m + hi))
            for (c, _), m, lo, hi in zip(rows, means, *errors, strict=True)]  # fmt: skip
    place_labels(ax, [(1e6 * c.energy, 100 * ci.mean) for c, ci in rows],
                 [f"{c.layout}, {c.column}" for c, _ in rows],
                 lines=bars + list(itertools.pairwise(line)))  # fmt: skip
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True

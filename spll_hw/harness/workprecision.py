"""Error against run time: every backend setting against the golden model on the same samples."""

from __future__ import annotations

import itertools
import os
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import backends
from ..files import save_figure
from ..network import Network
from ..report.figure_layout import legend_outside, place_labels, readable_log_axis
from ..report.plots import _pyplot
from ..result import SimulationResult
from .metrics import count_error, rate_error, spike_time_error

#: Times every backend setting runs the samples; its wall time is the median of these runs.
TIMING_REPEATS = 3


@dataclass(frozen=True)
class WorkPrecisionRow:
    """One backend setting: wall time per sample [s] and its errors against the golden model
    (means over samples; spike-time errors pooled over samples and sPLLs).

    The samples are run ``timing_repeats`` times; each run's wall time per sample is the mean
    over the samples, ``seconds_per_sample`` the median of the runs and ``seconds_min`` /
    ``seconds_max`` their range. ``load_average`` is the machine's 1, 5 and 15 min load
    average (``os.getloadavg``, ``None`` where the platform has none) right after the runs, on
    ``cpus`` logical CPUs: a load near or above ``cpus`` slows every timing. ``spec`` is the
    backend setting as given (the dt sweep's curves read its ``dt``), ``name`` how tables and
    legends show it (:func:`row_name`: with its chip profile and its dt); ``name`` defaults to
    ``spec``.
    """

    spec: str
    seconds_per_sample: float
    rate_error: float
    count_error: float
    spike_time_median: float
    spike_time_p95: float
    matched_fraction: float
    warnings: tuple[str, ...] = ()
    seconds_min: float = float("nan")
    seconds_max: float = float("nan")
    timing_repeats: int = 1
    load_average: tuple[float, float, float] | None = None
    cpus: int | None = None
    name: str = ""

    def __post_init__(self) -> None:
        if not self.name:
            object.__setattr__(self, "name", self.spec)


def row_name(spec: str, backend: backends.Backend) -> str:
    """How a row shows backend setting ``spec`` configured as ``backend``: its
    :attr:`~spll_hw.backends.base.Backend.label` (with its chip profile also where that is the
    backend's default) and the ``dt`` that ``spec`` sets, which a label leaves out where it is
    the backend's default (``brian2-numpy:dt=1e-05``, whose label is ``brian2-numpy``)."""
    label, dt = backend.label, _dt(spec)
    return f"{label}:dt={dt}" if dt and not _dt(label) else label


def machine_load() -> tuple[tuple[float, float, float] | None, int | None]:
    """``(1, 5 and 15 min load averages or None, logical CPU count or None)`` of this machine."""
    try:
        load = tuple(round(x, 2) for x in os.getloadavg())
    except (AttributeError, OSError):  # no load average on this platform
        load = None
    return load, os.cpu_count()


def measure(
    spec: str,
    network: Network,
    trains: Sequence[np.ndarray],
    duration: float,
    golden: Sequence[SimulationResult],
    repeats: int = TIMING_REPEATS,
) -> WorkPrecisionRow:
    """Run ``trains`` on backend ``spec`` ``repeats`` times, each time as one batch through one
    configured backend (what a compilation, a runtime start or realising a chip profile costs
    is paid once per run, as a user running a workload pays it); the first run's results are
    compared with the ``golden`` results, every run is timed [s per sample]."""
    if repeats < 1:
        raise ValueError(f"timing repeats must be >= 1, got {repeats}")
    sim = backends.get(spec)

    def run() -> tuple[list[SimulationResult], float]:
        start = time.perf_counter()
        results = sim.simulate_batch(network, list(trains), duration, record_spikes=True)
        return results, (time.perf_counter() - start) / len(trains)

    results, first = run()
    runs = [first] + [run()[1] for _ in range(repeats - 1)]
    load, cpus = machine_load()
    pairs = list(zip(results, golden, strict=True))
    timing = [spike_time_error(r, g) for r, g in pairs]
    pooled = np.concatenate([errors for errors, _ in timing])
    warnings = sorted({w for r in results for w in r.info.get("warnings", ())})
    return WorkPrecisionRow(
        spec=spec,
        name=row_name(spec, sim),
        seconds_per_sample=float(np.median(runs)),
        rate_error=float(np.nanmean([rate_error(r, g) for r, g in pairs])),
        count_error=float(np.nanmean([count_error(r, g) for r, g in pairs])),
        spike_time_median=float(np.median(pooled)) if pooled.size else float("nan"),
        spike_time_p95=float(np.percentile(pooled, 95)) if pooled.size else float("nan"),
        matched_fraction=float(np.nanmean([matched for _, matched in timing])),
        warnings=tuple(warnings),
        seconds_min=float(np.min(runs)),
        seconds_max=float(np.max(runs)),
        timing_repeats=repeats,
        load_average=load,
        cpus=cpus,
    )


def check_backends(specs: Sequence[str], network: Network) -> None:
    """Configure every backend of ``specs`` and prepare ``network`` on it (realise its chip
    profile, build its integers or its construction) before any of them runs, so that a
    backend that cannot run this network fails first, not after the others' work.
    ``ValueError`` naming every spec that fails and why."""
    problems = []
    for spec in specs:
        try:
            backends.get(spec).prepared(network)
        except ValueError as exc:
            problems.append(f"{spec}: {exc}")
    if problems:
        raise ValueError(
            "these backends cannot run the network (nothing was run): " + "; ".join(problems)
        )


@dataclass(frozen=True)
class FailedRow:
    """A backend that failed while it ran: its spec and the error, as one line."""

    spec: str
    error: str


def work_precision(
    specs: Sequence[str], network: Network, trains: Sequence[np.ndarray], duration: float,
    on_row=None, repeats: int = TIMING_REPEATS, failed: list[FailedRow] | None = None,
) -> list[WorkPrecisionRow]:  # fmt: skip
    """One :class:`WorkPrecisionRow` per spec, each timed over ``repeats`` runs; the golden rows
    measure the golden model itself (error 0 by construction, its wall time is the reference
    cost). The golden results come from the registry's ``golden`` backend, as one batch.

    Every backend is checked against ``network`` first (:func:`check_backends`). With a
    ``failed`` list, a backend that fails while it runs (``ValueError``, ``RuntimeError``,
    ``OSError``) is appended to it as a :class:`FailedRow` and the others still run; without
    one, the error is raised."""
    check_backends(specs, network)
    golden = backends.get("golden").simulate_batch(network, list(trains), duration,
                                                   record_spikes=True)  # fmt: skip
    rows = []
    for spec in specs:
        try:
            rows.append(measure(spec, network, trains, duration, golden, repeats))
        except (ValueError, RuntimeError, OSError) as exc:
            if failed is None:
                raise
            failed.append(FailedRow(spec, f"{type(exc).__name__}: {exc}"))
            continue
        if on_row is not None:
            on_row(rows[-1])
    return rows


def markdown_table(rows: Sequence[WorkPrecisionRow]) -> str:
    """The rows as a Markdown table (times in ms and µs, errors in %), followed by how the
    times were taken and the machine's load meanwhile."""
    lines = [
        "| backend | ms / sample: median (min-max) | TDE-rate error | TDE-count error "
        "| spike-time error median / p95 [µs] | matched |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| `{r.name}` | {1e3 * r.seconds_per_sample:.2f} ({1e3 * r.seconds_min:.2f}-"
            f"{1e3 * r.seconds_max:.2f}) | {100 * r.rate_error:.3f} % | "
            f"{100 * r.count_error:+.3f} % | {1e6 * r.spike_time_median:.3g} / "
            f"{1e6 * r.spike_time_p95:.3g} | {100 * r.matched_fraction:.1f} % |"
        )
    return "\n".join(lines) + f"\n\n{timing_note(rows)}"


def load_text(rows: Sequence[WorkPrecisionRow]) -> str:
    """The machine's 1-min load average while the rows were timed, e.g. ``1-min load average
    3.1-4.0 on 2 CPUs``."""
    loads = [r.load_average[0] for r in rows if r.load_average is not None]
    if not loads:
        return "load average not available on this platform"
    cpus = next((r.cpus for r in rows if r.cpus), "?")
    span = f"{min(loads):.1f}" + (f"-{max(loads):.1f}" if max(loads) > min(loads) else "")
    return f"1-min load average {span} on {cpus} CPUs"


def timing_note(rows: Sequence[WorkPrecisionRow]) -> str:
    """One sentence: how the wall times were taken, and the machine's load meanwhile."""
    if not rows:
        return "Nothing was timed."
    repeats = "/".join(map(str, sorted({r.timing_repeats for r in rows})))
    return (
        f"Wall time per sample: median of {repeats} runs of every sample (min-max in "
        f"brackets); {load_text(rows)} while timing (a load near the CPU count slows every "
        "time, and unevenly)."
    )


def family(spec: str) -> str:
    """The curve a spec belongs to: the spec without its ``dt`` option
    (``golden-fixed-point:profile=fixed16:dt=1e-05`` → ``golden-fixed-point:profile=fixed16``)."""
    return ":".join(part for part in spec.split(":") if not part.startswith("dt="))


def _dt(spec: str) -> str:
    return spec.partition(":dt=")[2].split(":")[0]


def _curve_order(row: WorkPrecisionRow) -> tuple[float, float]:
    """Coarsest ``dt`` first (a curve follows its dt sweep, whatever the timings say)."""
    dt = _dt(row.spec)
    return (-float(dt) if dt else 0.0, row.seconds_per_sample)


def plot(rows: Sequence[WorkPrecisionRow], path) -> None:
    """Work-precision diagram, log-log: wall time per sample [ms] (median, bars min-max)
    against TDE-rate error, one curve per backend joining its ``dt`` sweep from coarse to fine
    (each point labelled with its dt, the curve named as :attr:`WorkPrecisionRow.name` names
    it, its dt aside); the exact golden model, whose error is 0, is the vertical
    line of its own cost (band: min-max). The subtitle says how the times were taken and the
    machine's load; with nothing but golden the figure says there is nothing to compare."""
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8.5, 4.8))
    curves: dict[str, list[WorkPrecisionRow]] = {}
    undrawn, golden = [], []
    for r in rows:
        if r.rate_error == 0 and family(r.spec) == "golden":
            golden.append(1e3 * r.seconds_per_sample)
            ax.axvspan(1e3 * r.seconds_min, 1e3 * r.seconds_max, color="0.88", zorder=0,
                       label=f"{r.name}: min-max of its runs")  # fmt: skip
            ax.axvline(1e3 * r.seconds_per_sample, color="k", linestyle="--", linewidth=1,
                       label=f"{r.name} (exact: error 0)")  # fmt: skip
        elif np.isfinite(r.rate_error) and r.rate_error > 0:
            curves.setdefault(family(r.spec), []).append(r)
        else:
            undrawn.append(f"{r.name}: error {100 * r.rate_error:g} %")
    # The golden line runs the whole height: labels keep off it too.
    points, texts, lines = [], [], [((x, 1e-300), (x, 1e300)) for x in golden]
    for members in curves.values():
        members.sort(key=_curve_order)
        x = np.array([1e3 * r.seconds_per_sample for r in members])
        low = np.array([1e3 * r.seconds_min for r in members])
        high = np.array([1e3 * r.seconds_max for r in members])
        spread = np.vstack([x - low, high - x])
        y = [100 * r.rate_error for r in members]
        ax.errorbar(x, y, xerr=spread.tolist(), marker="o", ms=4, capsize=2,
                    label=family(members[0].name))  # fmt: skip
        points += list(zip(x, y, strict=True))
        lines += [((a, v), (b, v)) for a, b, v in zip(low, high, y, strict=True)]  # error bars
        lines += list(itertools.pairwise(zip(x, y, strict=True)))  # the curve
        texts += [f"dt {_dt(r.spec)}" if _dt(r.spec) else "default dt" for r in members]
    notes = []
    if not curves:
        notes.append(
            "Only the golden model was run: nothing to compare against.\n"
            "Its error is 0 by construction; the dashed line is its wall time."
        )
        ax.set_yticks([])
    else:
        ax.set_yscale("log")
        readable_log_axis(ax.yaxis)
    if undrawn:
        notes.append("Not on the log axis: " + "; ".join(undrawn))
    for k, note in enumerate(notes):
        ax.text(0.5, 0.5 - 0.15 * k, note, transform=ax.transAxes, ha="center", va="center",
                fontsize=8, color="0.3", wrap=True)  # fmt: skip
    ax.set_xscale("log")
    readable_log_axis(ax.xaxis)
    repeats = "/".join(map(str, sorted({r.timing_repeats for r in rows})))
    ax.set_xlabel(f"wall time per sample [ms]: median of {repeats} runs (bars, band: min-max)")
    ax.set_ylabel("TDE-rate error vs golden [%]\n(mean over the samples)")
    fig.suptitle("Error against run time", fontsize=11)
    ax.set_title(f"{load_text(rows)} while timing", fontsize=8)
    ax.margins(x=0.15, y=0.2)
    legend_outside(ax)
    place_labels(ax, points, texts, lines=lines)
    save_figure(fig, path, dpi=120)
    plt.close(fig)

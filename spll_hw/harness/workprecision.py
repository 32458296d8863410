"""Error against run time: every backend setting against the golden model on the same samples."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .. import backends
from ..files import save_figure
from ..network import Network
from ..result import SimulationResult
from ..simulate import simulate
from .metrics import count_error, rate_error, spike_time_error


@dataclass(frozen=True)
class WorkPrecisionRow:
    """One backend setting: wall time per sample [s] and its errors against the golden model
    (means over samples; spike-time errors pooled over samples and sPLLs)."""

    spec: str
    seconds_per_sample: float
    rate_error: float
    count_error: float
    spike_time_median: float
    spike_time_p95: float
    matched_fraction: float
    warnings: tuple[str, ...] = ()


def measure(
    spec: str,
    network: Network,
    trains: Sequence[np.ndarray],
    duration: float,
    golden: Sequence[SimulationResult],
) -> WorkPrecisionRow:
    """Run ``trains`` on backend ``spec`` and compare with the ``golden`` results."""
    results = [backends.run(spec, network, x, duration) for x in trains]
    pairs = list(zip(results, golden, strict=True))
    timing = [spike_time_error(r, g) for r, g in pairs]
    pooled = np.concatenate([errors for errors, _ in timing])
    warnings = sorted({w for r in results for w in r.info.get("warnings", ())})
    return WorkPrecisionRow(
        spec=spec,
        seconds_per_sample=float(np.mean([r.wall_time for r in results])),
        rate_error=float(np.nanmean([rate_error(r, g) for r, g in pairs])),
        count_error=float(np.nanmean([count_error(r, g) for r, g in pairs])),
        spike_time_median=float(np.median(pooled)) if pooled.size else float("nan"),
        spike_time_p95=float(np.percentile(pooled, 95)) if pooled.size else float("nan"),
        matched_fraction=float(np.nanmean([matched for _, matched in timing])),
        warnings=tuple(warnings),
    )


def work_precision(
    specs: Sequence[str], network: Network, trains: Sequence[np.ndarray], duration: float,
    on_row=None,
) -> list[WorkPrecisionRow]:  # fmt: skip
    """One :class:`WorkPrecisionRow` per spec; the golden rows measure the golden model itself
    (error 0 by construction, its wall time is the reference cost)."""
    golden = [simulate(network, x, duration) for x in trains]
    rows = []
    for spec in specs:
        rows.append(measure(spec, network, trains, duration, golden))
        if on_row is not None:
            on_row(rows[-1])
    return rows


def markdown_table(rows: Sequence[WorkPrecisionRow]) -> str:
    """The rows as a Markdown table (times in ms and µs, errors in %)."""
    lines = [
        "| backend | ms / sample | TDE-rate error | TDE-count error "
        "| spike-time error median / p95 [µs] | matched |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| `{r.spec}` | {1e3 * r.seconds_per_sample:.2f} | {100 * r.rate_error:.3f} % | "
            f"{100 * r.count_error:+.3f} % | {1e6 * r.spike_time_median:.3g} / "
            f"{1e6 * r.spike_time_p95:.3g} | {100 * r.matched_fraction:.1f} % |"
        )
    return "\n".join(lines)


def plot(rows: Sequence[WorkPrecisionRow], path) -> None:
    """Work-precision diagram: wall time per sample against TDE-rate error, log-log."""
    from ..report.plots import _pyplot

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7, 4.5))
    floor = 1e-6  # exact rows (error 0) are drawn at this floor
    for r in rows:
        err = max(r.rate_error, floor)
        ax.scatter(1e3 * r.seconds_per_sample, 100 * err, s=30)
        ax.annotate(r.spec, (1e3 * r.seconds_per_sample, 100 * err), fontsize=7,
                    xytext=(4, 2), textcoords="offset points")  # fmt: skip
    top = max([100 * r.rate_error for r in rows if np.isfinite(r.rate_error)] + [100 * floor])
    ax.set_ylim(100 * floor / 2, 10 * top)  # before the log scale: all-exact rows share one y
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per sample [ms]")
    ax.set_ylabel("TDE-rate error vs golden [%]")
    ax.set_title("error against run time")
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)

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


def family(spec: str) -> str:
    """The curve a spec belongs to: the spec without its ``dt`` option
    (``golden-fixed-point:profile=fixed16:dt=1e-05`` → ``golden-fixed-point:profile=fixed16``)."""
    return ":".join(part for part in spec.split(":") if not part.startswith("dt="))


def plot(rows: Sequence[WorkPrecisionRow], path) -> None:
    """Work-precision diagram, log-log: wall time per sample against TDE-rate error, one curve
    per backend (its ``dt`` sweep, each point labelled with its dt); the exact golden model,
    whose error is 0, is the vertical reference line of its own cost."""
    from ..report.plots import _pyplot

    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(7.5, 4.8))
    curves: dict[str, list[WorkPrecisionRow]] = {}
    for r in rows:
        if r.rate_error == 0 and family(r.spec) == "golden":
            ax.axvline(1e3 * r.seconds_per_sample, color="k", linestyle="--", linewidth=1)
            ax.text(1e3 * r.seconds_per_sample, 0.02, " golden (exact): error 0",
                    transform=ax.get_xaxis_transform(), fontsize=7, rotation=90,
                    va="bottom")  # fmt: skip
        elif np.isfinite(r.rate_error) and r.rate_error > 0:
            curves.setdefault(family(r.spec), []).append(r)
    for name, points in curves.items():
        points.sort(key=lambda r: r.seconds_per_sample)
        x = [1e3 * r.seconds_per_sample for r in points]
        y = [100 * r.rate_error for r in points]
        ax.plot(x, y, marker="o", label=name)
        for r, xi, yi in zip(points, x, y, strict=True):
            dt = r.spec.partition(":dt=")[2].split(":")[0]
            ax.annotate(f"dt {dt}" if dt else "default dt", (xi, yi), fontsize=6,
                        xytext=(3, 3), textcoords="offset points")  # fmt: skip
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("wall time per sample [ms]")
    ax.set_ylabel("TDE-rate error vs golden [%]")
    ax.set_title("Error against run time (each point: mean over the samples)")
    if curves:
        ax.legend(fontsize=7, loc="upper right")
    ax.margins(x=0.15, y=0.2)
    fig.tight_layout()
    save_figure(fig, path, dpi=120)
    plt.close(fig)

"""Markdown summary of a pipeline run."""

from __future__ import annotations

from .. import backends
from ..pipeline import PipelineResult

_SPECTRUM_LABEL = "(pressure)"


def percent(mean: float, half_width: float) -> str:
    """``54.6 ± 1.8 %``: an accuracy fraction and the half-width of its 95 % interval; an
    interval that reaches past 0 or 100 % (few folds: the t quantile of 1 degree of freedom is
    12.7) is shown clipped, as its ends: ``58.3 % [0.0, 100.0]``, so that it reads as what it
    is, not as an accuracy of ± 146 %."""
    low, high = mean - half_width, mean + half_width
    if low >= 0 and high <= 1:
        return f"{100 * mean:.1f} ± {100 * half_width:.1f} %"
    return f"{100 * mean:.1f} % [{100 * max(low, 0.0):.1f}, {100 * min(high, 1.0):.1f}]"


def accuracy_table(result: PipelineResult) -> dict[str, dict[str, tuple[float, float]]]:
    """``table[feature][encoder or "(pressure)"] = (mean, half-width of its 95 % CI)``
    accuracy fractions (CV: corrected resampled t over the folds; held out: a bootstrap over
    the test recordings, :mod:`spll_hw.stats`)."""
    table: dict[str, dict[str, tuple[float, float]]] = {}
    for r in result.results:
        table.setdefault(r.feature, {})[r.encoder or _SPECTRUM_LABEL] = (
            r.cv.accuracy,
            r.cv.accuracy_ci().half_width,
        )
    return table


def render_summary(result: PipelineResult, figures: dict[str, str], command: str | None) -> str:
    """The ``summary.md`` text; ``figures`` maps captions to relative PNG paths."""
    s = result.samples
    cfg = result.config
    lines = [f"# Texture pipeline report: {s.name}", ""]
    if command:
        lines += ["Command:", "", f"    {command}", ""]
    lines += [
        "## Dataset",
        "",
        f"- {len(s)} samples of {s.duration:g} s at {s.fs:g} Hz, {s.n_classes} classes; "
        f"signal unit: {s.unit}",
        "- samples per class: " + ", ".join(f"{k} {v}" for k, v in s.class_counts().items()),
    ]
    lines += [f"- skipped: {note}" for note in s.skipped]
    if result.test is not None:
        recordings = len(set(result.test.recordings.tolist()))
        scheme = (
            f"trained on these samples, tested once on {len(result.test)} held-out samples of "
            f"{recordings} recordings ({', '.join(sorted(set(result.test.recordings))[:3])}, "
            "...), mean ± half-width of its 95 % CI by a bootstrap over the test recordings"
        )
    else:
        scheme = (
            f"stratified {cfg.n_splits}-fold CV of {cfg.cv}"
            + (" (every recording in one fold)" if cfg.cv == "recordings" else "")
            + ", mean ± half-width of its 95 % CI over the "
            "folds (corrected resampled t)"
        )
    lines += [
        "",
        "## Accuracy",
        "",
        f"Ridge classifier (alpha {cfg.alpha:g}, standardised features), {scheme}; "
        f"chance {100 / s.n_classes:.1f} %."
        + (
            f" Phase noise {cfg.phase_noise * 1e3:g} ms, {cfg.n_repeats} draws pooled."
            if cfg.phase_noise > 0
            else ""
        ),
        "",
    ]
    encoders = list(result.encoder_params)
    cols = ([_SPECTRUM_LABEL] if any(r.encoder is None for r in result.results) else []) + encoders
    table = accuracy_table(result)
    lines.append("| feature | " + " | ".join(cols) + " |")
    lines.append("|---" * (len(cols) + 1) + "|")
    for feature, row in table.items():
        cells = [percent(*row[c]) if c in row else "" for c in cols]
        lines.append(f"| {feature} | " + " | ".join(cells) + " |")
    lines += ["", "## Time", "", "| step | seconds |", "|---|---|"]
    for name, sec in result.encode_seconds.items():
        lines.append(f"| encode ({name}) | {sec:.2f} |")
    for r in result.results:
        lines.append(f"| {r.feature} ({r.encoder or 'pressure'}) | {r.seconds:.2f} |")
    if encoders:
        lines += ["", "## Encoders", ""]
        for name, params in result.encoder_params.items():
            rate = result.mean_rate(name)
            args = ", ".join(f"{k}={v}" for k, v in params.items())
            lines.append(f"- **{name}** ({rate:.0f} spikes/s on average): {args}")
    if "spll" in cfg.features:
        presets = ", ".join(f"{e}: `{cfg.network_for(e)}`" for e in encoders)
        ran = backends.label(cfg.backend)
        lines += ["", f"sPLL networks: {presets}; simulated on backend `{ran}`."]
    lines += ["", "## Figures", ""]
    lines += [f"![{caption}]({path})" for caption, path in figures.items()]
    return "\n".join(lines) + "\n"

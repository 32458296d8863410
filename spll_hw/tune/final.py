"""The networks a study ends with, scored for the report.

* A single-objective study ends with its best trial (``best.toml``).
* A multi-objective study (accuracy and a chip cost, :mod:`spll_hw.tune.chip`) ends with the
  Pareto front of its complete (feasible) trials; the chosen points
  (:func:`~spll_hw.tune.chip.chosen_points`: each objective's extreme and the knee) are written
  as ``best-1.toml``, ``best-2.toml``, ... (most accurate first), and ``best.toml`` is the most
  accurate of them.
* ``--compare FILE`` adds a reference network (e.g. the best network of a study tuned on the
  exact model, which the chip then quantizes afterwards), scored by the same objective on the
  same samples, noise and chip draws, so it can be placed against the front.
* ``--holdout-recordings`` scores each of them on recordings the study never saw
  (:mod:`spll_hw.tune.holdout`). In a chip study the reference is also scored there off the
  chip (the exact model, :data:`OFF_CHIP`): what the chip costs it, paired sample by sample,
  and how much of that the chip-tuned networks recover (:meth:`Final.recovery`). With
  ``--compare-profile P`` the reference is also scored on chip ``P`` (say the chip as published,
  when the study tunes for a variant of it with another time step), and the chip's cost and
  what is recovered are measured against the reference quantized on ``P``. With
  ``--attribute`` it is also scored on the chip with each parameter the chip changes kept exact
  (:func:`~spll_hw.tune.chip.exact_specs`): how much of the cost each format or mismatch
  explains (:meth:`Final.attribution_changes`).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import files
from ..classify import HoldoutResult
from ..config import NetworkConfig, NetworkFile
from ..encoders import Encoder, settings_flags, settings_table
from ..files import save_figure
from ..pareto import dominates
from ..report.figure_layout import legend_outside, place_labels
from ..report.plots import _pyplot
from ..stats import Interval
from . import import_optuna
from .chip import (
    baseline_specs,
    changed_parameters,
    chosen_points,
    exact_specs,
    pareto_front,
    signs_of,
)
from .holdout import HoldoutData, holdout_score
from .objective import Objective
from .space import breaks_constraints, trial_encoder

#: The backend that scores the reference off the chip: the exact model of the network as given.
OFF_CHIP = "golden"

#: How each objective is shown: (column title, scale from its unit, format).
SHOWN = {
    "accuracy": ("accuracy (study) [%]", 100.0, "{:.1f}"),
    "energy": ("dynamic energy / sample [µJ]", 1e6, "{:.4g}"),
    "cores": ("cores", 1.0, "{:.0f}"),
}


@dataclass
class Network:
    """One network the study ends with.

    Attributes:
        label: ``"best"``, ``"best-1"``, ... or ``"reference"``.
        role: why it is reported (``"best accuracy + knee"``, ``"reference: FILE"``).
        config: the network.
        encoder: the encoder it encodes with (``None``: the study's spike trains).
        values: the study's objectives (accuracy fraction, energy [J], cores).
        trial: its trial (``None`` for the reference).
        energy: mean dynamic energy per sample on the chip [J], when the profile models it.
        cores: cores it occupies, when the profile has a ``[resources]`` table.
        problems: why it does not fit the chip (empty: it fits).
        file: the TOML file written for it (relative to the report folder).
        holdout: its score on the held-out recordings.
    """

    label: str
    role: str
    config: NetworkConfig
    encoder: Encoder | None
    values: tuple[float, ...]
    trial: object = None
    energy: float | None = None
    cores: int | None = None
    problems: tuple[str, ...] = ()
    file: str | None = None
    holdout: HoldoutResult | None = field(default=None, repr=False)

    def to_dict(self) -> dict:
        out = {
            "label": self.label,
            "role": self.role,
            "trial": None if self.trial is None else self.trial.number,
            "values": list(self.values),
            "energy_J": self.energy,
            "cores": self.cores,
            "fits": not self.problems,
            "why_not": list(self.problems),
            "file": self.file,
        }
        if self.holdout is not None:
            out["holdout"] = self.holdout.to_dict()
        return out


def share_of(change: Interval, cost: Interval) -> float | None:
    """``change.mean`` as a share of the loss ``cost`` (a negative change in accuracy);
    ``None`` when the cost's interval does not lie below zero (nothing distinguishable is
    lost)."""
    return change.mean / -cost.mean if cost.high < 0 else None


def _share_text(share: float | None) -> str:
    return "-" if share is None else f"{100 * share:.0f} %"


@dataclass(frozen=True)
class Recovery:
    """What one chip-tuned network wins back of what the chip costs the reference.

    Attributes:
        network: the chip-tuned network (or, with ``--compare-profile``, the reference moved
            untuned to the study's chip).
        on_chip: paired 95 % interval of its held-out accuracy on the chip minus the
            reference's quantized afterwards (on the chip, or on ``--compare-profile``'s)
            [fraction].
        against_off_chip: the same against the reference off the chip (the exact model): where
            the chip-tuned network on its chip stands against not using the chip at all.
        share: ``on_chip.mean`` over what the chip costs the reference; ``None`` when that
            cost's interval does not lie below zero (nothing distinguishable is lost).
    """

    network: Network
    on_chip: Interval
    against_off_chip: Interval
    share: float | None


@dataclass(frozen=True)
class Attribution:
    """What one parameter's format (or mismatch) costs the reference on the chip.

    Attributes:
        parameter: the sPLL parameter kept exact (:data:`spll_hw.params.PARAM_NAMES`).
        holdout: the reference's held-out score on the chip with that parameter exact.
        change: paired 95 % interval of that score minus the reference's on the chip's
            formats [fraction]: positive when the parameter's format costs accuracy.
        share: ``change.mean`` over what the chip's formats cost the reference
            (:meth:`Final.formats_cost`; ``None`` when that cost's interval does not lie below
            zero).
    """

    parameter: str
    holdout: HoldoutResult
    change: Interval
    share: float | None


@dataclass
class Final:
    """What the report shows beyond the trials: the networks, the front, the held-out split."""

    objectives: tuple[str, ...]
    networks: list[Network]
    front: list = field(default_factory=list)  # the front's trials, most accurate first
    reference: Network | None = None
    holdout: HoldoutData | None = None
    reference_off_chip: HoldoutResult | None = None  # chip studies: the reference, exact model
    # --attribute: the reference on the chip's formats (golden:profile=P), and on them with
    # each parameter the chip changes kept exact: (parameter, score)
    formats_only: HoldoutResult | None = None
    attribution: list[tuple[str, HoldoutResult]] = field(default_factory=list)
    # --compare-profile P: the reference on chip P, the baseline of the chip's cost
    baseline_profile: str | None = None
    reference_on_baseline: HoldoutResult | None = None

    def quantized_reference(self) -> HoldoutResult | None:
        """The reference quantized afterwards, held out: on ``--compare-profile``'s chip when
        given, else on the study's chip."""
        if self.reference_on_baseline is not None:
            return self.reference_on_baseline
        return self.reference.holdout if self.reference is not None else None

    def comparisons(self) -> list[tuple[Network, Interval]]:
        """``(network, paired 95 % interval of its held-out accuracy minus the reference's)``
        for every network, when both were tested on held-out recordings."""
        ref = self.reference
        if ref is None or ref.holdout is None:
            return []
        return [(n, n.holdout.change_against(ref.holdout)) for n in self.networks if n.holdout]

    def chip_cost(self) -> Interval | None:
        """Paired 95 % interval of the reference's held-out accuracy quantized afterwards
        (:meth:`quantized_reference`) minus off the chip (negative: the chip costs it
        accuracy); ``None`` unless both were scored."""
        quantized = self.quantized_reference()
        if self.reference_off_chip is None or quantized is None:
            return None
        return quantized.change_against(self.reference_off_chip)

    def recovery(self) -> list[Recovery]:
        """A :class:`Recovery` for every held-out-scored network (empty unless the reference
        was scored on and off the chip). With ``--compare-profile`` the reference itself comes
        first: what moving it to the study's chip alone wins back, without tuning."""
        cost = self.chip_cost()
        if cost is None:
            return []
        quantized = self.quantized_reference()
        out = []
        moved = [self.reference] if self.reference_on_baseline is not None else []
        for n in [*moved, *self.networks]:
            if n.holdout is None:
                continue
            change = n.holdout.change_against(quantized)
            off = n.holdout.change_against(self.reference_off_chip)
            out.append(Recovery(n, change, off, share_of(change, cost)))
        return out

    def formats_cost(self) -> Interval | None:
        """Paired 95 % interval of the reference's held-out accuracy on the chip's formats
        (:attr:`formats_only`) minus off the chip; ``None`` without ``--attribute``."""
        if self.formats_only is None or self.reference_off_chip is None:
            return None
        return self.formats_only.change_against(self.reference_off_chip)

    def attribution_changes(self) -> list[Attribution]:
        """An :class:`Attribution` for every parameter of :attr:`attribution`, against the
        reference on the chip's formats."""
        cost = self.formats_cost()
        if cost is None:
            return []
        out = []
        for name, result in self.attribution:
            change = result.change_against(self.formats_only)
            out.append(Attribution(name, result, change, share_of(change, cost)))
        return out

    def dominating(self) -> list[Network]:
        """The networks whose study objectives dominate the reference's."""
        if self.reference is None:
            return []
        signs = signs_of(self.objectives)
        return [n for n in self.networks if dominates(n.values, self.reference.values, signs)]


def accuracy_of(trial) -> float:
    """A trial's accuracy (its first objective, single- or multi-objective)."""
    return float(trial.values[0])


def trial_network(objective: Objective, trial, encoder: Encoder | None, label: str, role: str):
    """The :class:`Network` of a complete trial."""
    full = objective.space.complete(trial.params)
    return Network(
        label, role, objective.config(trial.params), trial_encoder(encoder, full),
        tuple(trial.values), trial, trial.user_attrs.get("energy_j"),
        trial.user_attrs.get("cores"),
    )  # fmt: skip


def reference_encoder(reference: NetworkFile, encoder: Encoder | None) -> Encoder | None:
    """The encoder a reference network file is scored with: the study's, with the file's
    ``[encoder]`` settings when it was tuned on the same encoder."""
    if encoder is None:
        return None
    table = reference.encoder
    if table is None or table[0] != encoder.name:
        return encoder
    return dataclasses.replace(encoder, **table[1])


def score_reference(
    objective: Objective, reference: NetworkFile, encoder: Encoder | None
) -> Network:
    """The network of the file or preset ``reference`` scored as a trial would be (same
    samples, noise and chip draws, objectives); a network that does not fit the chip gets its
    problems and NaN objectives."""
    config = reference.config
    used = reference_encoder(reference, encoder)
    params = {}
    if objective.space.encoders and used is not None:
        prefix = f"{used.name}."
        params = {
            name: getattr(used, name.removeprefix(prefix))
            for name in objective.space.tuned
            if name.startswith(prefix)
        }
    fit = objective.fit(config)
    role = f"reference: {reference.source}"
    n = len(objective.settings.objectives)
    if not fit.fits:
        return Network("reference", role, config, used, (math.nan,) * n, problems=fit.problems)
    scores = objective.evaluate(config, objective.draws(params))
    values = scores.values(objective.settings.objectives, fit)
    return Network("reference", role, config, used, values, None, scores.energy, fit.cores)


def final_networks(
    study,
    objective: Objective,
    best,
    encoder: Encoder | None,
    compare: NetworkFile | None = None,
    holdout: HoldoutData | None = None,
    feasible=None,
    attribute: bool = False,
    compare_profile: str | None = None,
) -> Final:
    """The networks to report (module docstring): ``best`` (a trial) for a single-objective
    study, else the chosen points of the front of ``feasible`` trials (default: every
    complete one); then the reference and the held-out scores, and with ``attribute`` the
    reference's with each parameter the chip changes kept exact, and with ``compare_profile``
    the reference's on that chip (:func:`~spll_hw.tune.chip.baseline_specs`)."""
    objectives = objective.settings.objectives
    networks: list[Network] = []
    front: list = []
    if len(objectives) == 1:
        if best is not None:
            networks.append(trial_network(objective, best, encoder, "best", "best trial"))
    else:
        optuna = import_optuna()
        trials = feasible
        if trials is None:
            trials = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
        points = [tuple(t.values) for t in trials]
        front = [trials[i] for i in pareto_front(points, objectives)]
        for k, (i, role) in enumerate(chosen_points(points, objectives), start=1):
            networks.append(trial_network(objective, trials[i], encoder, f"best-{k}", role))
    reference = score_reference(objective, compare, encoder) if compare else None
    off_chip = formats_only = on_baseline = None
    attribution: list[tuple[str, HoldoutResult]] = []
    if holdout is not None:
        scored = reference is not None and not reference.problems
        for n in [*networks, *([reference] if scored else [])]:
            n.holdout = holdout_score(objective, n.config, n.encoder or holdout.encoder, holdout)
        if scored and objective.profile is not None:
            encoder_used = reference.encoder or holdout.encoder

            def score(specs: tuple[str, ...]) -> HoldoutResult:
                """The reference held out on backends ``specs`` instead of the study's."""
                return holdout_score(objective, reference.config, encoder_used, holdout, specs)

            off_chip = score((OFF_CHIP,))
            if attribute:
                formats = exact_specs(objective.specs)
                formats_only = reference.holdout if formats == objective.specs else score(formats)
                built = reference.config.build()
                for name in changed_parameters(built, objective.profile, objective.seeds):
                    attribution.append((name, score(exact_specs(objective.specs, name))))
            if compare_profile is not None:
                on_baseline = score(baseline_specs(objective.specs, compare_profile))
    return Final(
        objectives, networks, front, reference, holdout, off_chip, formats_only, attribution,
        compare_profile if on_baseline is not None else None, on_baseline,
    )  # fmt: skip


def network_file(
    network: Network, study_name: str, input_level: float | None = None, flags: bool = True
) -> str:
    """The TOML text of a network's file: a comment header (study, trial, objectives, held-out
    accuracy), the network and its ``[encoder]`` table with ``input_level``, the level the
    study's signals were divided by."""
    head = f"# spll-hw tune: study {study_name}"
    if network.trial is not None:
        head += f", trial {network.trial.number}, CV accuracy {100 * network.values[0]:.1f} %"
    lines = [head, f"# {network.label}: {network.role}"]
    if network.energy is not None:
        lines.append(f"# dynamic energy per sample on the chip: {network.energy * 1e6:.4g} uJ")
    if network.cores is not None:
        lines.append(f"# cores on the chip: {network.cores}")
    if network.holdout is not None:
        ci = network.holdout.accuracy_ci()
        lines.append(
            f"# held-out accuracy: {100 * ci.mean:.1f} % [{100 * ci.low:.1f}, {100 * ci.high:.1f}]"
        )
    if flags and network.encoder is not None and settings_flags(network.encoder):
        lines.append(f"# encoder settings: {settings_flags(network.encoder)}")
    table = (
        f"\n{settings_table(network.encoder, input_level)}" if network.encoder is not None else ""
    )
    return "\n".join(lines) + "\n" + network.config.to_toml() + table


def _cell(objective: str, value: float | None) -> str:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "-"
    _, scale, fmt = SHOWN[objective]
    return fmt.format(scale * value)


def _ci(result: HoldoutResult | None, change=None) -> str:
    if result is None and change is None:
        return "-"
    ci = change if change is not None else result.accuracy_ci()
    sign = "+" if change is not None else ""
    return f"{100 * ci.mean:{sign}.1f} [{100 * ci.low:{sign}.1f}, {100 * ci.high:{sign}.1f}]"


def networks_table(final: Final) -> list[str]:
    """Markdown rows: every network with its study objectives, energy, cores, held-out
    accuracy and, with a reference, the paired change against it."""
    extra = [n for n in ("energy", "cores") if n not in final.objectives]
    cols = list(final.objectives) + extra
    held = final.holdout is not None
    changes = dict((id(n), ci) for n, ci in final.comparisons())
    head = ["network", "trial", *[SHOWN[c][0] for c in cols]]
    if held:
        head.append("held-out accuracy [%] (95 % CI)")
        if final.reference is not None:
            head.append("held-out change vs reference [points] (paired 95 % CI)")
    head.append("file")
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    rows = [*final.networks, *([final.reference] if final.reference else [])]
    for n in rows:
        known = dict(zip(final.objectives, n.values, strict=True))
        known.setdefault("energy", n.energy)
        known.setdefault("cores", n.cores)
        cells = [f"{n.label} ({n.role})", "-" if n.trial is None else f"#{n.trial.number}"]
        cells += [_cell(c, known.get(c)) for c in cols]
        if held:
            cells.append(_ci(n.holdout) if n.holdout is not None else "does not fit")
            if final.reference is not None:
                cells.append(_ci(None, changes[id(n)]) if id(n) in changes else "-")
        cells.append(f"`{n.file}`" if n.file else "-")
        if n.problems:
            cells[0] += " — does not fit: " + "; ".join(n.problems)
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def recovery_lines(final: Final, profile: str | None) -> list[str]:
    """The section of a chip study with a held-out reference: what the chip costs the
    reference (on the chip against off it, paired) and how much of that each chip-tuned
    network recovers (empty when the study has no such reference)."""
    cost = final.chip_cost()
    if cost is None:
        return []
    ref, off = final.reference, final.reference_off_chip
    baseline = final.baseline_profile or profile
    if cost.high < 0:
        verdict = f"the chip costs it **{_ci(None, cost)}** points (paired)"
    elif cost.low > 0:
        verdict = (
            f"on the chip it scores **{_ci(None, cost)}** points more (paired): nothing is lost"
        )
    else:
        verdict = (
            f"the chip changes it by {_ci(None, cost)} points (paired): the interval contains "
            "zero, so no loss is distinguishable and there is nothing to recover"
        )
    text = (
        f"The reference on the held-out recordings: {_ci(off)} % off the "
        f"chip (the exact model, `{OFF_CHIP}`), {_ci(final.quantized_reference())} % on "
        f"`{baseline}`; {verdict}."
    )
    if final.baseline_profile is not None:
        text += (
            f" The study tuned for `{profile}`, where the reference scores {_ci(ref.holdout)} "
            f"%; the networks below, on `{profile}`, are paired against the reference on "
            f"`{baseline}` (`--compare-profile`)."
        )
    lines = [
        "## What the chip costs, and what tuning for it recovers",
        "",
        text,
        "",
        f"| network | change vs the reference on `{baseline}` [points] (paired 95 % CI) | "
        "share of the chip's cost recovered | change vs the reference off the chip [points] |",
        "|---|---|---|---|",
    ]
    for r in final.recovery():
        lines.append(
            f"| {r.network.label} | {_ci(None, r.on_chip)} | {_share_text(r.share)} | "
            f"{_ci(None, r.against_off_chip)} |"
        )
    return lines + [""]


def attribution_lines(final: Final) -> list[str]:
    """The section of ``--attribute``: the reference on the chip's formats with each parameter
    the chip changes kept exact, paired against it on the formats (empty without it)."""
    rows = final.attribution_changes()
    if not rows:
        return []
    cost = final.formats_cost()
    lines = [
        "## Which parameter's format costs the accuracy",
        "",
        "On the chip's formats alone (`golden:profile=P`: the exact model of the realised "
        "network, without a fixed-point chip's arithmetic) the reference scores "
        f"{_ci(final.formats_only)} % held out, {_ci(None, cost)} points against it off the "
        "chip (paired). Each row keeps one parameter at its requested value "
        "(`golden:profile=P:exact=NAME`) and is paired against the reference on the formats: "
        "a positive change is what that parameter's rounding (or mismatch) costs, and its "
        "share is of the formats' cost. The changes need not add up, as formats interact. "
        "`i_cco_offset` exact means every CCO's requested free-running frequency.",
        "",
        "| parameter kept exact | held-out accuracy [%] (95 % CI) | change vs the reference on "
        "the formats [points] (paired 95 % CI) | share of the formats' cost |",
        "|---|---|---|---|",
    ]
    for a in rows:
        lines.append(
            f"| `{a.parameter}` | {_ci(a.holdout)} | {_ci(None, a.change)} | "
            f"{_share_text(a.share)} |"
        )
    return lines + [""]


def front_table(final: Final) -> list[str]:
    """Markdown rows of the Pareto front: every front trial's objectives, the chosen ones
    marked with their file."""
    chosen = {n.trial.number: n for n in final.networks if n.trial is not None}
    head = ["trial", *[SHOWN[c][0] for c in final.objectives], "chosen"]
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for t in final.front:
        n = chosen.get(t.number)
        mark = f"`{n.file}` ({n.role})" if n is not None else ""
        cells = [f"#{t.number}", *[_cell(c, v) for c, v in zip(final.objectives, t.values,
                                                               strict=True)], mark]  # fmt: skip
        lines.append("| " + " | ".join(cells) + " |")
    return lines


def plot_front(study, final: Final, path: Path, complete: Sequence) -> None:
    """Accuracy [%] against the first cost objective of every complete trial: those the front
    was chosen from (``complete``; grey, hollow where they break the constraints yet were kept),
    the others, left out because they break the constraints (red crosses), the Pareto front
    (joined), the chosen points and the reference (star), labelled; the legend beside the axes.
    """
    optuna = import_optuna()
    cost = final.objectives[1]
    title, scale, _ = SHOWN[cost]
    every = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    kept = {t.number for t in complete}
    why = "constraints off" if any(not breaks_constraints(t) for t in every) else "none meets them"
    groups = (
        ("meet the constraints", "o", {"color": "0.6"},
         [t for t in every if t.number in kept and not breaks_constraints(t)]),
        (f"break the constraints,\nkept ({why})", "o", {"mfc": "none", "color": "0.45"},
         [t for t in every if t.number in kept and breaks_constraints(t)]),
        ("break the constraints:\nleft out of the front", "x", {"color": "C3"},
         [t for t in every if t.number not in kept]),
    )  # fmt: skip
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for label, marker, style, trials in groups:
        if trials:
            ax.plot([scale * t.values[1] for t in trials], [100 * t.values[0] for t in trials],
                    marker, ms=4, linestyle="none", label=f"{label} ({len(trials)})",
                    **style)  # fmt: skip
    fx = [scale * t.values[1] for t in final.front]
    fy = [100 * t.values[0] for t in final.front]
    order = np.argsort(fx)
    ax.plot(np.array(fx)[order], np.array(fy)[order], "o-", color="C1", ms=5,
            label="Pareto front")  # fmt: skip
    points = [(scale * n.values[1], 100 * n.values[0]) for n in final.networks]
    texts = [n.label for n in final.networks]
    ref = final.reference
    if ref is not None and not ref.problems:
        ax.plot([scale * ref.values[1]], [100 * ref.values[0]], "*", color="C3", ms=12,
                label="reference")  # fmt: skip
        points.append((scale * ref.values[1], 100 * ref.values[0]))
        texts.append("reference")
    ax.set_xlabel(title)
    ax.set_ylabel("CV accuracy (study) [%]")
    unplotted = len(study.trials) - len(every)
    ax.set_title(f"study {study.study_name}: accuracy against {cost}, {len(every)} complete trials"
                 + (f"\n({unplotted} trials without objective values not drawn)"
                    if unplotted else ""), fontsize=9)  # fmt: skip
    legend_outside(ax)
    drawn = [(scale * t.values[1], 100 * t.values[0]) for t in every]
    front = list(zip(np.array(fx)[order], np.array(fy)[order], strict=True))
    place_labels(ax, points, texts, fontsize=8, avoid=drawn, lines=list(itertools.pairwise(front)))
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def write_results(final: Final, path: Path, extra: dict) -> None:
    """``results.json``: the split, the networks (objectives, held-out scores) and the paired
    changes against the reference."""
    payload = dict(extra)
    payload["objectives"] = list(final.objectives)
    payload["networks"] = [n.to_dict() for n in final.networks]
    payload["reference"] = final.reference.to_dict() if final.reference else None
    payload["holdout"] = final.holdout.to_dict() if final.holdout else None
    payload["changes_vs_reference"] = {n.label: ci.to_dict() for n, ci in final.comparisons()}
    if final.reference_off_chip is not None:
        payload["reference_off_chip"] = final.reference_off_chip.to_dict()
        payload["chip_cost_of_reference"] = final.chip_cost().to_dict()
        if final.reference_on_baseline is not None:
            payload["compare_profile"] = final.baseline_profile
            payload["reference_on_compare_profile"] = final.reference_on_baseline.to_dict()
        recovered = final.recovery()
        payload["recovered_fraction"] = {r.network.label: r.share for r in recovered}
        payload["changes_vs_quantized_reference"] = {
            r.network.label: r.on_chip.to_dict() for r in recovered
        }
        payload["changes_vs_reference_off_chip"] = {
            r.network.label: r.against_off_chip.to_dict() for r in recovered
        }
    if final.formats_only is not None:
        payload["reference_on_formats"] = final.formats_only.to_dict()
        payload["formats_cost_of_reference"] = final.formats_cost().to_dict()
    payload["attribution"] = {
        a.parameter: {
            "holdout": a.holdout.to_dict(),
            "change_vs_reference_on_formats": a.change.to_dict(),
            "share_of_formats_cost": a.share,
        }
        for a in final.attribution_changes()
    }
    payload["front"] = [
        {"trial": t.number, "values": list(t.values)} for t in final.front
    ]  # fmt: skip
    files.write_results(path, payload)

"""The report folder of a study: best network as TOML, summary.md and PNG figures.

- ``best.toml``: the best trial's network (:meth:`~spll_hw.config.NetworkConfig.to_toml`), which
  every command accepts as ``--network``.
- ``history.png``: accuracy of every trial (pruned ones at their last reported value) and the best
  so far; ``importances.png``: fANOVA parameter importances (thesis Figure 12);
  ``response_*.png``: TDE rate against input frequency of the tuned network's lowest, middle and
  highest sPLL (thesis Figures 8-9); ``features.png``: class-mean feature vectors with the
  within-class sd (thesis Figures 11, 16); ``confusion.png``.
- ``summary.md``: the command, the study's trial counts and wall times, best parameters beside the
  search space, constraints, importances and the figures; with ``--rescore K`` the K best trials
  re-scored on every sample (the best of them is then ``best.toml``).

A chip study (:mod:`spll_hw.tune.chip`) adds its profile, chip draws and the trials pruned because
their network did not fit the chip (with the reasons); a multi-objective one its Pareto front
(``front.png``, a table, ``best-<k>.toml`` per chosen point); ``--compare`` a reference network
scored the same way; ``--holdout-recordings`` the held-out accuracies, with ``results.json``
(:mod:`spll_hw.tune.final`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from matplotlib.ticker import MaxNLocator

from ..classify import cross_validate
from ..datasets.recordings import format_numbers
from ..encoders import Encoder, settings_flags, settings_table
from ..files import atomic_folder, save_figure, write_text
from ..report.figure_layout import legend_outside
from ..report.plots import _pyplot, plot_confusion, plot_per_class
from ..report.spll_plots import plot_frequency_response
from ..simulate import frequency_response
from . import import_optuna
from .final import (
    Final,
    accuracy_of,
    attribution_lines,
    front_table,
    network_file,
    networks_table,
    plot_front,
    recovery_lines,
    write_results,
)
from .objective import Objective
from .rescore import Rescored
from .space import CONSTRAINTS, breaks_constraints, trial_encoder
from .storage import mask_url

#: Input frequencies of the response plots: from 10 Hz to this multiple of the sPLL's frequency.
RESPONSE_SPAN = 2.5
RESPONSE_POINTS = 150
#: Length [s] of each periodic input of the response plots.
RESPONSE_DURATION = 1.0
#: Below this many complete trials the fANOVA importances are flagged as unreliable.
FANOVA_RELIABLE_TRIALS = 20


def candidate_trials(study, constraints: str = "penalise") -> list:
    """Complete trials; unless the study's ``constraints`` mode is ``"off"``, only the feasible
    ones if any trial is feasible."""
    optuna = import_optuna()
    complete = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    feasible = [t for t in complete if not breaks_constraints(t)]
    if constraints == "off":
        feasible = []
    return feasible or complete


def ranked_trials(study, constraints: str = "penalise") -> list:
    """:func:`candidate_trials`, most accurate first (a multi-objective study's accuracy is
    its first objective)."""
    return sorted(candidate_trials(study, constraints), key=accuracy_of, reverse=True)


def best_trial(study, constraints: str = "penalise"):
    """The first of :func:`ranked_trials` (None if no trial completed)."""
    ranked = ranked_trials(study, constraints)
    return ranked[0] if ranked else None


def left_out_lines(study, constraints: str) -> list[str]:
    """A summary bullet saying how many complete trials :func:`candidate_trials` drops (they
    break the constraints while others meet them) and that the best network and the Pareto
    front are chosen without them; empty when none is dropped."""
    optuna = import_optuna()
    complete = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    dropped = len(complete) - len(candidate_trials(study, constraints))
    if not dropped:
        return []
    return [
        f"- left out: {dropped} of {len(complete)} complete trials break the thesis's "
        f"constraints (constraints: {constraints}, and {len(complete) - dropped} meet them), so "
        "the best network and the Pareto front are chosen among the others; the figures draw "
        "them as red crosses"
    ]


def importance_lines(study, out: Path) -> list[str]:
    """The summary section of the fANOVA importances (writes ``importances.png``), with a
    warning when they rest on fewer than :data:`FANOVA_RELIABLE_TRIALS` complete trials."""
    values, reason = importances(study)
    lines = ["", "## Parameter importances (fANOVA)", ""]
    if not values:
        return [*lines, f"Not computed: {reason}."]
    optuna = import_optuna()
    n = len(study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,)))
    plot_importances(values, out / "importances.png", n)
    if n < FANOVA_RELIABLE_TRIALS:
        lines += [
            f"**Unreliable: these rest on {n} complete trials** (fewer than "
            f"{FANOVA_RELIABLE_TRIALS}) for {len(values)} tuned parameters. fANOVA fits a random "
            "forest to the trials' parameters and accuracies and splits the variance of its "
            "prediction among the parameters; with this few trials the forest mostly fits noise, "
            "and another seed or a few more trials would rank the parameters differently. Read "
            "the table as a guess until the study has more trials.",
            "",
        ]
    lines += ["| parameter | importance |", "| --- | --- |"]
    lines += [f"| {n} | {100 * v:.1f} % |" for n, v in values.items()]
    return [*lines, "", "![importances](importances.png)"]


def trial_seconds(trial) -> float | None:
    """Wall time [s] of a finished trial."""
    if trial.datetime_start is None or trial.datetime_complete is None:
        return None
    return (trial.datetime_complete - trial.datetime_start).total_seconds()


def importances(study) -> tuple[dict[str, float], str]:
    """fANOVA importances (fractions summing to 1) of the tuned parameters, or an empty dict and
    the reason when they cannot be computed (too few complete trials)."""
    optuna = import_optuna()
    complete = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.COMPLETE,))
    if len(complete) < 2:
        return {}, f"needs at least 2 complete trials, the study has {len(complete)}"
    evaluator = optuna.importance.FanovaImportanceEvaluator(seed=0)
    target = accuracy_of if len(study.directions) > 1 else None  # of the accuracy
    try:
        found = optuna.importance.get_param_importances(study, evaluator=evaluator, target=target)
        return dict(found), ""
    except (ValueError, RuntimeError) as exc:
        return {}, str(exc)


def plot_history(study, path: Path, constraints: str = "penalise") -> None:
    """Accuracy [%] per trial: complete trials the best is chosen from (dots), complete ones
    left out because they break the constraints (red crosses, :func:`candidate_trials`),
    pruned ones (grey crosses at their last reported value), and the best eligible value so
    far; integer trial ticks, the legend beside the axes."""
    optuna = import_optuna()
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 3.5))
    state = optuna.trial.TrialState
    eligible = {t.number for t in candidate_trials(study, constraints)}
    done = [t for t in study.trials if t.state == state.COMPLETE and t.number in eligible]
    left_out = [t for t in study.trials if t.state == state.COMPLETE and t.number not in eligible]
    pruned = [t for t in study.trials if t.state == state.PRUNED and t.intermediate_values]
    if pruned:
        last = [t.intermediate_values[max(t.intermediate_values)] for t in pruned]
        ax.plot([t.number for t in pruned], 100 * np.array(last), "x", color="0.6", ms=4,
                label="pruned (last reported)")  # fmt: skip
    if left_out:
        ax.plot([t.number for t in left_out], [100 * accuracy_of(t) for t in left_out], "x",
                color="C3", ms=5, label="breaks the constraints:\nnot eligible")  # fmt: skip
    if done:
        numbers = np.array([t.number for t in done])
        values = 100 * np.array([accuracy_of(t) for t in done])
        ax.plot(numbers, values, "o", ms=3, label="complete")
        ax.step(numbers, np.maximum.accumulate(values), where="post", color="k", lw=1,
                label="best so far")  # fmt: skip
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set_xlabel("trial")
    ax.set_ylabel("CV accuracy [%]")
    unseen = sum(1 for t in study.trials if t.state == state.PRUNED and not t.intermediate_values)
    ax.set_title(f"study {study.study_name}: optimisation history"
                 + (f"\n({unseen} trials pruned before reporting a value not drawn)"
                    if unseen else ""), fontsize=10)  # fmt: skip
    legend_outside(ax, fontsize=8)
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def plot_importances(values: dict[str, float], path: Path, n_trials: int) -> None:
    """Horizontal bars of the importances [%], most important on top; the title says how many
    complete trials they rest on, and warns when that is below :data:`FANOVA_RELIABLE_TRIALS`."""
    plt = _pyplot()
    names = sorted(values, key=values.get)
    fig, ax = plt.subplots(figsize=(6, 0.35 * len(names) + 1.6))
    ax.barh(names, [100 * values[n] for n in names])
    ax.set_xlabel("importance (fANOVA) [%]")
    title = f"fANOVA importances from {n_trials} complete trials"
    if n_trials < FANOVA_RELIABLE_TRIALS:
        title += f"\nUNRELIABLE: fewer than {FANOVA_RELIABLE_TRIALS} trials (see summary.md)"
    ax.set_title(title, fontsize=9, color="C3" if n_trials < FANOVA_RELIABLE_TRIALS else "k")
    fig.tight_layout()
    save_figure(fig, path, dpi=110)
    plt.close(fig)


def plot_class_features(
    features: np.ndarray, labels: np.ndarray, class_names, frequencies: np.ndarray, path: Path
) -> None:
    """Mean TDE rate [Hz] of every class against the sPLLs' free-running frequencies, with the
    within-class sd as error bars; one panel per class (thesis Figures 11, 16)."""
    top = float(np.max(features)) * 1.05 or 1.0

    def draw(ax, c: int) -> None:
        x = features[labels == c]
        ax.errorbar(
            frequencies,
            x.mean(axis=0),
            yerr=x.std(axis=0),
            fmt="o-",
            ms=2,
            lw=0.7,
            elinewidth=0.6,
            ecolor="k",
        )
        ax.set_ylim(0, top)

    title = "Feature vectors (TDE rates [Hz]): class mean and within-class sd"
    plot_per_class(class_names, draw, "free-running frequency of the sPLL [Hz]", title, path)


def _fmt(value: float) -> str:
    return "inf" if math.isinf(value) else f"{value:.4g}"


def study_lines(
    study, objective: Objective, out: Path, storage: str, command: str | None, final
) -> list[str]:
    """The head of ``summary.md``: the command, storage, data, network and scoring, trial
    counts and wall times, the held-out split of ``final`` (when there is one) and the
    optimisation history (writes ``history.png`` into ``out``)."""
    optuna = import_optuna()
    state = optuna.trial.TrialState
    counts = {s.name.lower(): len(study.get_trials(deepcopy=False, states=(s,))) for s in state}
    lines = [f"# Tuning study `{study.study_name}`", ""]
    if command:
        lines += ["Command:", "", f"    {command}", ""]
    settings = objective.settings
    lines += [
        f"- storage: `{mask_url(storage)}` (open it with `optuna-dashboard {mask_url(storage)}`)",
        f"- data: {objective.labels.size} samples of {objective.duration:g} s, "
        f"{len(objective.class_names)} classes (fingerprint `{objective.fingerprint}`)",
        f"- network: {objective.describe_network()}; phase noise "
        f"{settings.phase_noise:g} s x {settings.n_repeats} draws; {settings.folds}-fold ridge CV "
        f"(alpha {settings.alpha:g}); first look on {settings.prune_fraction:g} of every class; "
        f"constraints: {settings.constraints}",
        "- trials: " + ", ".join(f"{v} {k}" for k, v in counts.items() if v),
        *left_out_lines(study, objective.settings.constraints),
    ]
    lines += chip_lines(study, objective)
    if final is not None and final.holdout is not None:
        lines.append(f"- recordings: {final.holdout.describe()}")
    for label, st in (("complete", state.COMPLETE), ("pruned", state.PRUNED)):
        secs = [
            s
            for t in study.get_trials(deepcopy=False, states=(st,))
            if (s := trial_seconds(t)) is not None
        ]
        if secs:
            lines.append(
                f"- wall time per {label} trial: mean {np.mean(secs):.1f} s, median "
                f"{np.median(secs):.1f} s, total {np.sum(secs) / 60:.1f} min"
            )
    starts = [t.datetime_start for t in study.trials if t.datetime_start]
    ends = [t.datetime_complete for t in study.trials if t.datetime_complete]
    if starts and ends:
        span = (max(ends) - min(starts)).total_seconds()
        lines.append(f"- first trial start to last trial end: {span / 60:.1f} min")
    lines.append("")
    plot_history(study, out / "history.png", objective.settings.constraints)
    lines += ["![history](history.png)", ""]
    return lines


def parameter_lines(best, objective: Objective) -> list[str]:
    """Markdown: the ``best`` trial's parameters beside the search space, and the thesis's
    constraints of its network (broken ones called out)."""
    lines = ["| parameter | best | search space |", "| --- | --- | --- |"]
    full = objective.space.complete(best.params)
    for name, dim in objective.space.dims.items():
        lines.append(f"| {name} | {_fmt(full[name])} | {dim.describe()} |")
    violations = best.user_attrs.get("constraints", [])
    if violations and max(violations) > 0:
        why = (
            "the study ran with constraints off"
            if objective.settings.constraints == "off"
            else "no complete trial met them"
        )
        lines += ["", f"**This network breaks the thesis's constraints** ({why})."]
    if violations:
        lines += [
            "",
            "Constraints (ratio - 1, feasible <= 0): "
            + ", ".join(f"{n} {v:+.2f}" for n, v in zip(CONSTRAINTS, violations, strict=True)),
        ]
    return lines


def written_whole(write):
    """Decorator of a report writer ``write(study, objective, out_dir, ...) -> Path`` (the
    path of its ``summary.md``): it writes into a temporary folder beside ``out_dir`` whose
    files then move into ``out_dir`` (:func:`spll_hw.files.atomic_folder`), so that a full disk
    or Ctrl-C while writing leaves ``out_dir`` as it was (an earlier report, the study's
    database) and the ``OSError`` names the folder; it returns the path of ``summary.md`` in
    ``out_dir``."""

    @functools.wraps(write)
    def whole(study, objective, out_dir: str | Path, *args, **kwargs) -> Path:
        out = Path(out_dir)
        with atomic_folder(out) as stage:
            summary = write(study, objective, stage, *args, **kwargs)
        return out / summary.relative_to(stage)

    return whole


@written_whole
def write_tune_report(
    study,
    objective: Objective,
    out: Path,
    storage: str,
    command: str | None = None,
    rescored: Sequence[Rescored] = (),
    encoder: Encoder | None = None,
    final: Final | None = None,
) -> Path:
    """Write the report folder ``out`` (module docstring), whole or not at all
    (:func:`written_whole`), and return the path of ``summary.md``.

    Re-simulates the best network once (noise draw 0, every sample) for the feature, confusion
    and response figures. With ``rescored`` (:func:`~spll_hw.tune.rescore.rescore`, best first)
    the best network is the best re-scored trial, and the re-scores are tabulated. ``encoder``
    (the study's, with its ``--set`` settings) puts the flags that re-encode as the best trial
    did in ``best.toml`` and the summary. ``final`` (:func:`~spll_hw.tune.final.final_networks`)
    adds the Pareto front, the reference network and the held-out scores, and ``results.json``.
    """
    settings = objective.settings
    lines = study_lines(study, objective, out, storage, command, final)

    best = rescored[0].trial if rescored else best_trial(study, objective.settings.constraints)
    if best is None:
        lines += ["No trial has completed yet: no best network.", ""]
        if final is not None:
            lines += final_lines(study, objective, final, out)
        summary = out / "summary.md"
        write_text(summary, "\n".join(lines))
        return summary
    config = objective.config(best.params)
    sd = best.user_attrs.get("accuracy_sd", float("nan"))
    header = (
        f"# spll-hw tune: study {study.study_name}, trial {best.number}, "
        f"CV accuracy {100 * accuracy_of(best):.1f} %\n"
    )
    best_encoder = trial_encoder(encoder, objective.space.complete(best.params))
    flags = settings_flags(best_encoder) if best_encoder is not None else ""
    if flags:
        header += f"# encoder settings: {flags}\n"
    if rescored:
        header += (
            f"# re-scored on {rescored[0].n_samples} samples: {100 * rescored[0].accuracy:.1f} %\n"
        )
    for key, what in (("energy_j", "dynamic energy per sample on the chip"), ("cores", "cores")):
        if key in best.user_attrs:
            value = best.user_attrs[key]
            header += f"# {what}: " + (f"{value * 1e6:.4g} uJ\n" if key == "energy_j" else
                                      f"{value}\n")  # fmt: skip
    table = (
        f"\n{settings_table(best_encoder, objective.input_level)}" if best_encoder is not None
        else ""
    )  # fmt: skip
    write_text(out / "best.toml", header + config.to_toml() + table)
    if final is not None:
        lines += final_lines(study, objective, final, out)
    if rescored:
        lines += [
            f"## Re-scored on all {rescored[0].n_samples} samples",
            "",
            f"The best {len(rescored)} trial(s), each scored again on every sample of the dataset "
            "(same noise draws, folds and encoder); `best.toml` is the first row.",
            "",
            "| trial | study objective | re-scored (mean of draws) | per draw |",
            "| --- | --- | --- | --- |",
        ]
        lines += [
            f"| #{r.trial.number} | {100 * accuracy_of(r.trial):.1f} % | "
            f"{100 * r.accuracy:.1f} % | "
            + ", ".join(f"{100 * a:.1f}" for a in r.accuracies)
            + " |"
            for r in rescored
        ]
        lines.append("")
    lines += [
        f"## Best trial: #{best.number}, accuracy {100 * accuracy_of(best):.1f} % (fold sd "
        f"{100 * sd:.1f})",
        "",
        "Network written to `best.toml` (use it as `--network best.toml`).",
        "",
    ]
    if flags:
        lines += [
            f"Encoder settings of this trial: `{flags}`, also in the `[encoder]` table of "
            "`best.toml`, which `spll-hw evaluate --network best.toml` applies.",
            "",
        ]
    lines += parameter_lines(best, objective)
    lines += importance_lines(study, out)

    lines += ["", "## The tuned network", ""]
    everything = np.arange(objective.labels.size)
    features = objective.rates(config, objective.draws(best.params)[0], everything)
    frequencies = config.frequencies()
    plot_class_features(
        features, objective.labels, objective.class_names, frequencies, out / "features.png"
    )
    cv = cross_validate(
        features,
        objective.labels,
        objective.class_names,
        settings.folds,
        settings.alpha,
        settings.seed,
    )
    plot_confusion(
        cv.confusion_normalized(),
        objective.class_names,
        f"best network, noise draw 0: {100 * cv.accuracy:.1f} %",
        out / "confusion.png",
    )
    lines += ["![features](features.png)", "", "![confusion](confusion.png)", ""]
    network = config.build()
    for tag, i in (("low", 0), ("mid", config.n // 2), ("high", config.n - 1)):
        f_i = float(frequencies[i])
        inputs = np.linspace(10.0, RESPONSE_SPAN * f_i, RESPONSE_POINTS)
        rates = frequency_response(
            network.spll[i], f_i, inputs, RESPONSE_DURATION, threads=objective.threads
        )
        name = f"response_{tag}.png"
        plot_frequency_response(
            inputs, rates, f_i, out / name, title=f"tuned sPLL {i} (free-running {f_i:.1f} Hz)"
        )
        lines += [f"![response {tag}]({name})", ""]
    summary = out / "summary.md"
    write_text(summary, "\n".join(lines) + "\n")
    return summary


def chip_lines(study, objective: Objective) -> list[str]:
    """Summary bullets of a chip study: profile, backends, chip draws, objectives, and the
    trials pruned because their network did not fit (counted, with the commonest reasons)."""
    settings = objective.settings
    out = []
    if settings.multi_objective:
        out.append(
            "- objectives: " + ", ".join(settings.objectives) + " (multi-objective: no pruner)"
        )
    if objective.profile is None:
        return out
    seeds = [s for s in objective.seeds if s is not None]
    draws = f"; {len(seeds)} mismatch draws (chip_seed {format_numbers(seeds)})" if seeds else ""
    out.append(
        f"- chip: profile `{objective.profile}`; every trial simulated on "
        + ", ".join(f"`{s}`" for s in objective.specs[:1])
        + (f" ... `{objective.specs[-1]}`" if len(objective.specs) > 1 else "")
        + draws
    )
    if objective.costed.size:
        out.append(
            f"- dynamic energy per sample (event counts x per-event costs, no static power): "
            f"`spll_hw.chips.cost` of {objective.costed.size} samples "
            f"({settings.energy_per_class} per class, noise draw 0, every chip draw)"
        )
    optuna = import_optuna()
    pruned = study.get_trials(deepcopy=False, states=(optuna.trial.TrialState.PRUNED,))
    unfit = [t.user_attrs["fit"] for t in pruned if "fit" in t.user_attrs]
    if unfit:
        reasons: dict[str, int] = {}
        for why in unfit:
            reasons[why] = reasons.get(why, 0) + 1
        common = sorted(reasons.items(), key=lambda kv: -kv[1])[:3]
        out.append(
            f"- did not fit `{objective.profile}` (pruned unsimulated): {len(unfit)} of "
            f"{len(pruned)} pruned trials; " + "; ".join(f"{n}x {why}" for why, n in common)
        )
    else:
        out.append(f"- did not fit `{objective.profile}`: no trial")
    return out


def final_lines(study, objective: Objective, final: Final, out: Path) -> list[str]:
    """The report sections of ``final``: networks (with their files), the Pareto front and its
    plot, the reference against the front, the held-out scores; writes the ``best-<k>.toml``
    files, ``front.png`` and ``results.json``."""
    lines: list[str] = []
    multi = len(final.objectives) > 1
    for n in final.networks:
        if multi:
            n.file = f"{n.label}.toml"
            write_text(out / n.file, network_file(n, study.study_name, objective.input_level))
        else:
            n.file = "best.toml"
    if multi:
        complete = candidate_trials(study, objective.settings.constraints)
        plot_front(study, final, out / "front.png", complete)
        lines += [
            f"## Pareto front: {' against '.join(final.objectives)}",
            "",
            f"{len(final.front)} of {len(complete)} complete trials are on the front (no other "
            "trial is at least as good in every objective and better in one). Chosen points "
            "(each objective's best and the knee, nearest the ideal point once every objective "
            "is scaled to the front's range) are written as `best-<k>.toml`; `best.toml` is "
            "the most accurate.",
            "",
            *front_table(final),
            "",
            "![front](front.png)",
            "",
        ]
    if final.reference is not None:
        ref = final.reference
        if ref.problems:
            verdict = f"it does not fit `{objective.profile}`: " + "; ".join(ref.problems)
        elif multi:
            beat = final.dominating()
            verdict = (
                "dominated by " + ", ".join(f"{n.label} (#{n.trial.number})" for n in beat)
                if beat
                else "not dominated by any chosen front point"
            )
        else:
            best = final.networks[0] if final.networks else None
            verdict = (
                f"study objective {100 * ref.values[0]:.1f} % against the best trial's "
                f"{100 * best.values[0]:.1f} %"
                if best
                else f"study objective {100 * ref.values[0]:.1f} %"
            )
        lines += [
            "## Reference network",
            "",
            f"`{ref.role.removeprefix('reference: ')}`, scored by the study's objective on the "
            "same samples, noise draws and chip draws"
            + (f" (realised on `{objective.profile}`)" if objective.profile else "")
            + f": {verdict}.",
            "",
        ]
    lines += ["## Networks", "", *networks_table(final), ""]
    if final.holdout is not None:
        h = final.holdout
        s = objective.settings
        lines += [
            "## Held-out recordings",
            "",
            f"The study {h.describe()}. Each network is trained (ridge, alpha {s.alpha:g}) on "
            f"every sample of the tuning recordings and tested once on every held-out sample, "
            f"for each of {s.n_repeats} noise draw(s) x {len(objective.specs)} chip draw(s), "
            "pooled; 95 % intervals by a bootstrap over the held-out recordings; the change "
            "against the reference pairs the two networks sample by sample. With this few "
            "recordings a difference of 1-3 points is within the noise: read the intervals.",
            "",
        ]
    lines += recovery_lines(final, objective.profile)
    lines += attribution_lines(final)
    extra = {"study": study.study_name, "profile": objective.profile}
    extra["chip_seeds"] = [x for x in objective.seeds if x is not None]
    write_results(final, out / "results.json", extra)
    lines += ["Everything above is also in `results.json`.", ""]
    return lines

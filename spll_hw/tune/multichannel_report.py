"""The report folder of a multichannel study (:mod:`spll_hw.tune.multichannel`).

- ``best.toml``: the multichannel file with the best trial's networks in its tuned tables and
  every other table as it was (``spll-hw slide --network best.toml``).
- ``summary.md``: the single network's head (command, data, trials, wall times, history) and
  best parameters beside the joined search space, importances, then the held-out choice.
- With ``--holdout-recordings`` (the choosing block, e.g. 25-32 with 1-32 loaded: tuned on
  1-24): the best file and the file as given are trained on every tuning recording and tested
  once on the held-out ones as ``spll-hw slide`` decides (one decision per recording from its
  first ``window`` s, no phase noise; :func:`spll_hw.multichannel.timecourse
  .accuracy_over_time`), with the paired change (a bootstrap over held-out recordings), in the
  summary and ``results.json`` (:func:`spll_hw.tune.final.write_results`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from ..datasets.multichannel import MultiChannelSet
from ..datasets.recordings import format_numbers, recording_numbers
from ..files import write_text
from ..multichannel.config import MultichannelConfig
from ..multichannel.timecourse import accuracy_over_time
from .final import Final, Network, accuracy_of, networks_table, write_results
from .multichannel import MultichannelObjective, describe_table
from .per_channel import ChannelStudy
from .report import best_trial, importance_lines, parameter_lines, study_lines, written_whole
from .storage import mask_url


@dataclass(frozen=True)
class ChoiceSplit:
    """The recordings of a multichannel study's held-out choice (the ``holdout`` of a
    :class:`~spll_hw.tune.final.Final`).

    Attributes:
        tuned_on, tested_on: recording numbers of each side.
        window: decision window [s] (every recording's first ``window`` s).
    """

    tuned_on: tuple[int, ...]
    tested_on: tuple[int, ...]
    window: float

    @classmethod
    def of(cls, tuning: MultiChannelSet, held: MultiChannelSet) -> ChoiceSplit:
        def numbers(samples: MultiChannelSet) -> tuple[int, ...]:
            return tuple(sorted(set(recording_numbers(samples).tolist())))

        return cls(numbers(tuning), numbers(held), tuning.duration)

    def describe(self) -> str:
        """One line: which recordings the study tuned on and which it was tested on."""
        return (
            f"tuned on recordings {format_numbers(self.tuned_on)}, tested on recordings "
            f"{format_numbers(self.tested_on)} it never saw (one decision per recording from "
            f"its first {self.window:g} s)"
        )

    def to_dict(self) -> dict:
        return {
            "tuned_on_recordings": list(self.tuned_on),
            "tested_on_recordings": list(self.tested_on),
            "window_s": self.window,
        }


def multichannel_final(
    study,
    objective: MultichannelObjective,
    tuning: MultiChannelSet | None = None,
    held: MultiChannelSet | None = None,
    backend: str = "golden",
    jobs: int = 1,
    progress: bool = False,
    given: MultichannelConfig | None = None,
    chosen: tuple[MultichannelConfig, float] | None = None,
) -> Final:
    """The best trial's file (or ``chosen``: a file and its CV accuracy, a fraction, chosen
    otherwise, e.g. by a per-channel tuning) and the file as given (the reference: ``given``,
    default the objective's file), each with the study's objective; with ``held`` (the
    held-out recordings) and ``tuning`` (every sample of the tuning recordings) also their
    held-out scores (module docstring)."""
    best = best_trial(study, objective.settings.constraints)
    s = objective.settings
    given = given or objective.file
    scores = objective.evaluate(given, objective.draws({}))
    reference = Network("reference", f"reference: {given.source} as given", given, None,
                        (scores.accuracy,))  # fmt: skip
    networks = []
    if chosen is not None:
        networks.append(Network("best", "every channel's best", chosen[0], None, chosen[1:]))
    elif best is not None:
        config = objective.config(best.params)
        networks.append(Network("best", "best trial", config, None, tuple(best.values), best))
    split = None
    if held is not None:
        split = ChoiceSplit.of(tuning, held)
        compared = {n.label: n.config for n in [*networks, reference]}
        classes = {"study": list(tuning.class_names)}
        points = accuracy_over_time(
            tuning, held, compared, classes, [split.window], s.alpha, s.seed, backend, jobs,
            progress,
        )  # fmt: skip
        results = {p.network: p.result for p in points}
        for n in [*networks, reference]:
            n.holdout = results[n.label]
    return Final(s.objectives, networks, reference=reference, holdout=split)


def channel_lines(channels: Sequence[ChannelStudy]) -> list[str]:
    """The summary section of a per-channel tuning: one row per channel's study (empty
    without one)."""
    if not channels:
        return []

    def pct(value: float | None) -> str:
        return "–" if value is None else f"{100 * value:.1f} %"

    rows = [
        f"| {c.channel} | {c.table} | `{c.study}` | {c.trials} | {pct(c.start)} | {pct(c.best)} |"
        for c in channels
    ]
    return [
        "## Channel by channel",
        "",
        "Each channel's table was tuned by its own study, in this order, every other table as "
        "the studies before left it; a study's first trial is its table as it stood. The "
        "sections below are the last study's; `best.toml` holds every channel's best.",
        "",
        "| channel | table | study | trials | CV accuracy as it stood | best |",
        "|---|---:|---|---:|---:|---:|",
        *rows,
        "",
    ]


def trial_section(
    study, objective: MultichannelObjective, best: Network, out: Path
) -> tuple[str, list[str]]:
    """``best.toml``'s header and the summary section of a study's best trial."""
    trial = best.trial
    tuned = ", ".join(describe_table(objective.file, k) for k in objective.tuned)
    header = (
        f"# spll-hw tune --network: study {study.study_name}, trial {trial.number}, "
        f"CV accuracy {100 * accuracy_of(trial):.1f} %\n"
        f"# tuned: {tuned}; every other table as in {objective.file.source}\n"
    )
    return header, [
        f"## Best trial: #{trial.number}, CV accuracy {100 * accuracy_of(trial):.1f} %",
        "",
        f"Written to `best.toml` with every table of `{objective.file.source}`: {tuned} "
        "tuned, the others unchanged (`spll-hw slide --network best.toml`). Parameters "
        "are `<table>:<parameter>`.",
        "",
        *parameter_lines(trial, objective),
        *importance_lines(study, out),
        "",
    ]


def per_channel_section(
    objective: MultichannelObjective, best: Network, channels: Sequence[ChannelStudy]
) -> tuple[str, list[str]]:
    """``best.toml``'s header and the summary section of a per-channel tuning's file."""
    names = f"{channels[0].channel} ... {channels[-1].channel}"
    cv = f"CV accuracy {100 * best.values[0]:.1f} %"
    header = (
        f"# spll-hw tune --network --per-channel: {cv}\n"
        f"# tuned: {len(channels)} one-channel tables ({names}), each by its own study; "
        f"every other table as in {objective.file.source}\n"
    )
    return header, [
        f"## Best file: {cv}",
        "",
        f"Written to `best.toml`: every channel's table ({names}) as its study left it (the "
        "table above; a study's best replaced the table only when it beat it), every other "
        "table unchanged (`spll-hw slide --network best.toml`). The studies' parameters, "
        "history and importances are in the storage, one study per channel; the sections "
        "above the table are the last study's.",
        "",
    ]


@written_whole
def write_multichannel_report(
    study,
    objective: MultichannelObjective,
    out: Path,
    storage: str,
    command: str | None,
    final: Final,
    channels: Sequence[ChannelStudy] = (),
) -> Path:
    """Write the report folder ``out`` (module docstring), whole or not at all
    (:func:`~.report.written_whole`), and return the path of ``summary.md``. ``channels``: the
    studies of a per-channel tuning (:mod:`spll_hw.tune.per_channel`; ``study`` is the last of
    them), summed up in a section of their own."""
    lines = study_lines(study, objective, out, storage, command, final)
    lines += channel_lines(channels)
    best = final.networks[0] if final.networks else None
    if best is None:
        lines += ["No trial has completed yet: no best network.", ""]
    else:
        best.file = "best.toml"
        if channels:
            header, section = per_channel_section(objective, best, channels)
        else:
            header, section = trial_section(study, objective, best, out)
        if best.holdout is not None:
            ci = best.holdout.accuracy_ci()
            header += (
                f"# held-out ({format_numbers(final.holdout.tested_on)}): "
                f"{100 * ci.mean:.1f} % [{100 * ci.low:.1f}, {100 * ci.high:.1f}]\n"
            )
        write_text(out / "best.toml", best.config.to_toml(header))
        lines += section
    lines += ["## Networks", "", *networks_table(final), ""]
    if final.holdout is not None:
        lines += [
            "## Held-out recordings",
            "",
            f"The study {final.holdout.describe()}. Each file is trained (ridge, alpha "
            f"{objective.settings.alpha:g}) on every tuning recording and tested once on every "
            "held-out one, as `spll-hw slide` decides (no phase noise); 95 % intervals by a "
            "bootstrap over the held-out recordings, the change against the file as given "
            "paired recording by recording.",
            "",
        ]
    extra = {"study": study.study_name, "storage": mask_url(storage)}
    extra["multichannel_file"] = objective.file.source
    extra["tuned_tables"] = list(objective.tuned)
    if channels:
        extra["per_channel"] = [c.to_dict() for c in channels]
    write_results(final, out / "results.json", extra)
    lines += ["Everything above is also in `results.json`.", ""]
    summary = out / "summary.md"
    write_text(summary, "\n".join(lines))
    return summary

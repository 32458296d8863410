"""Training the spiking readout (:mod:`.readout`) and scoring its held-out decisions: the
accuracy of every readout at every threshold against its mean time to decision (the anytime
curve of ``spll-hw slide --readout``).

:func:`fit_readouts` trains a :class:`~.readout.Readout` on TDE rates (float and integer
widths), :func:`fit_staged` a :class:`~.readout.StagedReadout`; :func:`scored_decisions` decides
held-out runs in the golden engine (:mod:`.decisions`) and scores them;
:func:`anytime_over_class_sets` does all of it from recordings for every class set.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..classify import HoldoutResult
from ..datasets.multichannel import MultiChannelSet
from .config import MultichannelConfig
from .decisions import engine_decisions
from .features import input_levels
from .readout import (
    PREFIXES,
    START,
    Readout,
    StagedReadout,
    causal_counts,
    stages,
    tde_spikes,
)
from .timecourse import class_subset

#: The most accuracy points [%] an integer readout may lose against its float weights on the
#: training runs (:func:`training_loss`) before ``spll-hw export`` refuses it: issue 60's
#: tolerance for 8-bit weights.
READOUT_LOSS_LIMIT = 2.0
#: Thresholds [score x s] of ``spll-hw slide --readout``: the right class's score (plus the
#: offset) is about 1 (2) on a confident run, so a threshold is roughly the time [s] it waits
#: (twice it); ``inf`` decides at the end.
THRESHOLDS = (0.1, 0.2, 0.3, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, float("inf"))
#: Offset [score] of that readout (:meth:`Readout.from_ridge`): with 0, no membrane of 20
#: classes rose early; 0.5 to 1 gave the best early decisions on training recordings 25-32
#: held out from 1-24 (1: the thresholds of :data:`THRESHOLDS` span 0.1 to 3 s).
PREFIX_OFFSET = 1.0
#: Ridge penalty of each stage of a :class:`~.readout.StagedReadout`, chosen with its switch
#: times (:data:`.readout.STAGE_EDGES`).
STAGE_ALPHA = 100.0


@dataclass(frozen=True)
class AnytimePoint:
    """Held-out decisions of one readout at one threshold: accuracy (``result``), the mean
    time to decision [s] and the share of runs a readout neuron fired in (the others decided
    at the run's end)."""

    readout: str
    threshold: float
    result: HoldoutResult
    mean_time: float
    fired: float

    def to_dict(self) -> dict:
        return {
            "readout": self.readout,
            "threshold": self.threshold if np.isfinite(self.threshold) else None,
            **self.result.accuracy_fields(),
            "mean_time_s": self.mean_time,
            "fired": self.fired,
        }


def fit_readouts(
    rates: np.ndarray,
    train_labels: np.ndarray,
    class_names: Sequence[str],
    bits: Sequence[int | None] = (None, 8),
    alpha: float = 1.0,
    groups: np.ndarray | None = None,
    offset: float = 0.0,
    per_class: bool = False,
) -> dict[str, Readout]:
    """The readout trained on TDE ``rates`` [Hz] ``(n, d)`` with ``train_labels`` (indices into
    ``class_names``), with float weights (``None`` in ``bits``, label ``"float"``) and each
    integer width (``"8-bit"``: one weight scale per ``groups`` id, and per class with
    ``per_class``, bias corrected on the training rates, :meth:`Readout.quantized`); every
    score plus ``offset`` (:meth:`Readout.from_ridge`)."""
    ridge = Readout.from_ridge(rates, train_labels, class_names, alpha, offset)
    return {
        "float" if width is None else f"{width}-bit": (
            ridge if width is None else ridge.quantized(width, groups, rates, per_class)
        )
        for width in bits
    }


def fit_staged(
    counts: np.ndarray,
    times: Sequence[float],
    train_labels: np.ndarray,
    class_names: Sequence[str],
    duration: float,
    bits: Sequence[int | None] = (None, 8),
    alpha: float | None = None,
    groups: np.ndarray | None = None,
    offset: float = 0.0,
    edges: Sequence[float] = (),
) -> dict[str, StagedReadout]:
    """:class:`StagedReadout` of :func:`stages` (``duration``, ``edges``), each stage trained
    by :func:`fit_readouts` (penalty ``alpha``, default :data:`STAGE_ALPHA`; integer widths
    with a weight scale per ``groups`` id and class) on the stacked rates at its prefix times,
    taken from ``counts`` ``(n, len(times), d)`` (:func:`causal_counts` at ``times`` [s], which
    must hold every stage's)."""
    times = [float(t) for t in times]
    alpha = STAGE_ALPHA if alpha is None else alpha
    parts = []
    for start, prefixes in stages(duration, edges):
        missing = [t for t in prefixes if not np.isclose(times, t).any()]
        if missing:
            raise ValueError(f"stage from {start:g} s trains on counts at {missing} s, not given")
        at = [int(np.flatnonzero(np.isclose(times, t))[0]) for t in prefixes]
        rates, labels = stacked_prefixes(np.asarray(counts)[:, at], prefixes, train_labels)
        parts.append(fit_readouts(rates, labels, class_names, bits, alpha, groups, offset, True))
    starts = tuple(start for start, _ in stages(duration, edges))
    return {
        width: StagedReadout(tuple(part[width] for part in parts), starts) for width in parts[0]
    }


def scored_decisions(
    readouts: dict[str, Readout | StagedReadout],
    test_spikes: Sequence[Sequence[np.ndarray]],
    test_labels: np.ndarray,
    test_recordings: np.ndarray,
    class_names: Sequence[str],
    duration: float,
    thresholds: Sequence[float],
    seed: int = 0,
    not_before: float = START,
) -> list[AnytimePoint]:
    """Every held-out run decided by every readout (label -> :class:`Readout` or
    :class:`StagedReadout`) at every
    threshold in the golden engine (:func:`.decisions.engine_decisions`), scored against
    ``test_labels`` (bootstrap over ``test_recordings`` with ``seed``)."""
    points = []
    for label, readout in readouts.items():
        made = engine_decisions(readout, test_spikes, duration, thresholds, not_before)
        for column, threshold in enumerate(thresholds):
            result = HoldoutResult.of_predictions(
                made.labels[:, column], test_labels, test_recordings, class_names, seed
            )
            points.append(
                AnytimePoint(
                    label,
                    float(threshold),
                    result,
                    float(made.times[:, column].mean()),
                    float(made.fired[:, column].mean()),
                )
            )
    return points


def training(train_on: str, duration: float) -> tuple[tuple[float, ...], float]:
    """Prefix times [s] the readout trains on and its score offset: ``"end"``, the whole
    ``duration`` only, no offset; ``"prefixes"``, every :data:`PREFIXES` time shorter than
    ``duration`` and ``duration``, :data:`PREFIX_OFFSET`; ``"staged"`` (a
    :class:`StagedReadout`), every stage's (:func:`stages`), :data:`PREFIX_OFFSET`."""
    if train_on == "end":
        return (duration,), 0.0
    if train_on == "prefixes":
        return (*(t for t in PREFIXES if t < duration), duration), PREFIX_OFFSET
    if train_on == "staged":
        every = {t for _, prefixes in stages(duration) for t in prefixes}
        return tuple(sorted(every)), PREFIX_OFFSET
    raise ValueError(f"readout training must be 'prefixes' or 'end' or 'staged', got {train_on!r}")


def stacked_prefixes(
    counts: np.ndarray, times: Sequence[float], labels: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Training samples that weigh every prefix alike: the rates ``N_i(t) / t`` [Hz] of every
    run at every ``t`` of ``times`` [s], from ``counts`` ``(n, len(times), d)``
    (:func:`causal_counts`), stacked run by run, shape ``(n * len(times), d)``, and each
    run's label repeated, shape ``(n * len(times),)``. The ridge's score is linear in the
    rates, so a readout trained on them still folds exactly (module docstring)."""
    counts = np.asarray(counts, dtype=float)
    times = np.asarray(times, dtype=float)
    if counts.ndim != 3 or counts.shape[:2] != (len(labels), times.size):
        raise ValueError(
            f"prefix counts must have shape (runs {len(labels)}, times {times.size}, TDEs), "
            f"got {counts.shape}"
        )
    rates = counts / times[None, :, None]
    return rates.reshape(-1, counts.shape[2]), np.repeat(np.asarray(labels), times.size)


@dataclass(frozen=True)
class Anytime:
    """What :func:`anytime_over_class_sets` gives: per class set (its label), the held-out
    ``points`` and the trained ``readouts`` (width label -> :class:`Readout`, as
    :func:`fit_readouts`), the channels' input ``levels`` [raw unit] they were trained with, and
    every integer width's ``losses`` against float on the training runs (width label ->
    :func:`training_loss`'s ``(points, time [s])``)."""

    points: dict[str, list[AnytimePoint]]
    readouts: dict[str, dict[str, Readout | StagedReadout]]
    levels: dict[str, float]
    losses: dict[str, dict[str, tuple[float, float]]] = field(default_factory=dict)


def anytime_over_class_sets(
    train: MultiChannelSet,
    test: MultiChannelSet,
    config: MultichannelConfig,
    class_sets: dict[str, Sequence[str]],
    duration: float,
    bits: Sequence[int | None] = (None, 8),
    alpha: float = 1.0,
    seed: int = 0,
    jobs: int = 1,
    progress: bool = False,
    train_on: str = "prefixes",
) -> Anytime:
    """The readout's held-out decisions on every class set (label -> class names), from the
    first ``duration`` s of each recording (one causal simulation of ``config`` per recording;
    channel levels from ``train``, :func:`.features.input_levels`), trained on the training
    runs' rates over the prefixes of :func:`training` (``train_on``), with its offset, and the
    readouts; ``"staged"``: a :class:`StagedReadout` (:func:`fit_staged`, its own penalty
    :data:`STAGE_ALPHA`; ``alpha`` is the single readout's)."""
    times, offset = training(train_on, duration)
    levels = input_levels(config, train)
    # every TDE's channel: each channel's readout weights get their own scale
    per_channel = [g.network.n for g in config.groups for _ in g.channels]
    channels = np.repeat(np.arange(len(per_channel)), per_channel)
    counts = causal_counts(train.first(duration), config, levels, times, jobs, progress)
    test_spikes = tde_spikes(test.first(duration), config, levels, jobs, progress)
    points, readouts, losses = {}, {}, {}
    for label, names in class_sets.items():
        tr, te, relabel = class_subset(train, test, names)
        if train_on == "staged":
            readouts[label] = fit_staged(counts[tr], times, relabel[train.labels[tr]], names,
                                         duration, bits, None, channels, offset)  # fmt: skip
        else:
            rates, labels = stacked_prefixes(counts[tr], times, relabel[train.labels[tr]])
            readouts[label] = fit_readouts(rates, labels, names, bits, alpha, channels, offset)
        widths = readouts[label]
        if "float" in widths:
            losses[label] = {
                width: training_loss(
                    r, widths["float"], counts[tr], times, relabel[train.labels[tr]]
                )  # fmt: skip
                for width, r in widths.items()
                if width != "float"
            }
        points[label] = scored_decisions(
            readouts[label],
            [s for s, keep in zip(test_spikes, te, strict=True) if keep],
            relabel[test.labels[te]],
            test.recordings[te], names, duration, THRESHOLDS, seed,
        )  # fmt: skip
    return Anytime(points, readouts, dict(levels), losses)


def training_loss(
    readout: Readout | StagedReadout,
    reference: Readout | StagedReadout,
    counts: np.ndarray,
    times: Sequence[float],
    labels: np.ndarray,
) -> tuple[float, float]:
    """How many accuracy points [%] ``readout`` loses against ``reference`` (its float
    weights) on the training runs, and when: at every training prefix time ``times`` [s] the
    readout on then (a :class:`StagedReadout`'s stage) decides every run by its largest score on
    the rates so far (``counts`` ``(n, len(times), d)`` of :func:`causal_counts`, ``labels``
    ``(n,)``); the largest loss and its time [s]. Integer weights whose largest membrane
    differs from the float one's on the training rates cannot decide as the float readout does
    on held-out runs either."""
    worst = (-np.inf, float("nan"))
    for i, t in enumerate(times):
        rates = np.asarray(counts)[:, i] / t
        right = [_on_at(r, t).scores(rates).argmax(axis=1) == labels for r in (readout, reference)]
        loss = 100.0 * float(right[1].mean() - right[0].mean())
        if loss > worst[0]:
            worst = (loss, float(t))
    return worst


def _on_at(readout: Readout | StagedReadout, t: float) -> Readout:
    """The readout that decides at ``t`` [s]: a :class:`StagedReadout`'s stage on then."""
    if isinstance(readout, Readout):
        return readout
    return readout.stages[max(0, int(np.searchsorted(readout.starts, t, side="right")) - 1)]

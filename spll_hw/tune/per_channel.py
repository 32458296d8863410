"""Tuning a multichannel file channel by channel (``spll-hw tune --network FILE
--per-channel``).

The tables ``--groups`` names are split into one table per channel
(:meth:`~spll_hw.multichannel.config.MultichannelConfig.split`: the same networks and
features), then each channel's table is tuned by a study of its own, in the file's order,
every other table as the studies before left it (coordinate ascent on the CV accuracy of
all channels' features). A channel's table changes only when a trial beats it as it stands
(the study's first trial; a tie keeps it), so the file's CV
accuracy never falls from one channel to the next (with the same noise draws it is the
previous study's best), unless a study prefers a feasible trial to an infeasible start
(``--constraints penalise``) or the start lies outside the search space. One
:class:`~spll_hw.tune.multichannel.MultichannelObjective` serves every study (its
:meth:`~spll_hw.tune.multichannel.MultichannelObjective.focus`): the samples are encoded once
and a table is simulated again only when its network changed.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from ..multichannel.config import MultichannelConfig
from .final import accuracy_of
from .multichannel import MultichannelObjective, first_params
from .report import best_trial
from .study import StudySettings, finished, run_study


@dataclass(frozen=True)
class ChannelStudy:
    """One channel's study of a per-channel tuning.

    Attributes:
        table: the channel's table number in the split file.
        channel: its channel.
        study: the study's name.
        trials: finished trials.
        start: CV accuracy (fraction) of the table as it stood (the study's first trial), or
            ``None`` when that trial did not complete or the table lay outside the space.
        best: the best trial's CV accuracy (fraction), or ``None`` when no trial completed.
    """

    table: int
    channel: str
    study: str
    trials: int
    start: float | None
    best: float | None

    def to_dict(self) -> dict:
        return dict(self.__dict__)


#: TPE seed offset from one channel's study to the next, so channels do not share their
#: random start-up trials.
SEED_STRIDE = 1000


def split_settings(settings: StudySettings, channel: str, position: int) -> StudySettings:
    """The study settings of ``channel``'s study, the ``position``-th (0-based): named
    ``<name>-<channel>`` (every channel's study lives in the same storage), seeded
    ``seed + position *`` :data:`SEED_STRIDE`."""
    return replace(
        settings, name=f"{settings.name}-{channel}", seed=settings.seed + position * SEED_STRIDE
    )


def tune_each(
    settings: StudySettings,
    objective: MultichannelObjective,
    tables: Sequence[int],
    workers: int = 1,
    resume: bool = False,
    progress: bool = False,
) -> tuple[MultichannelConfig, float | None, object, list[ChannelStudy]]:
    """Tune ``tables`` of ``objective``'s file one after the other (module docstring).

    Args:
        settings: the per-channel study's settings; each channel's study is named
            ``<name>-<channel>``, seeded apart (:func:`split_settings`) and runs
            ``settings.trials`` trials.
        objective: built on the split file with every table of ``tables`` kept
            (``retunable``).
        tables: table numbers of the split file, one channel each, in tuning order.
        workers, resume: as :func:`~spll_hw.tune.study.run_study`.
        progress: progress bars when a table is simulated again.

    Returns:
        the file with every table tuned, its CV accuracy (a fraction; ``None`` when no trial
        of the last study completed), the last channel's study and one
        :class:`ChannelStudy` per table.
    """
    file, accuracy, study, rows = objective.file, None, None, []
    constraints = objective.settings.constraints
    for position, k in enumerate(tables):
        (channel,) = file.groups[k - 1].channels
        objective.focus(k, file, progress)
        enqueue, outside = first_params(objective)
        own = split_settings(settings, channel, position)
        study = run_study(own, objective, workers, resume, enqueue)
        best = best_trial(study, constraints)
        first = min(study.get_trials(deepcopy=False), key=lambda t: t.number, default=None)
        ran = first is not None and first.values and not outside
        start = accuracy_of(first) if ran else None
        if best is not None and (start is None or accuracy_of(best) > start):
            file, accuracy = objective.config(best.params), accuracy_of(best)
        elif start is not None:
            accuracy = start
        rows.append(ChannelStudy(k, channel, own.name, finished(study), start,
                                 accuracy_of(best) if best is not None else None))  # fmt: skip
    return file, accuracy, study, rows

"""What one ``spll-hw report`` run measured, as plain numbers and names: the one object that the
report folder (figures, ``params.toml``, ``results.json``, ``summary.md``) is written from.

The scoring step (:func:`spll_hw.report.constraints_score.score`) computes everything here
in one pass; the writing step reads it and computes nothing: no classifier results, chip
profiles or backends are consulted while the folder is written.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

#: Below this many samples per class the intervals are called wide (or test recordings,
#: where intervals are a bootstrap over held-out recordings).
SMALL_SAMPLE = 20

if TYPE_CHECKING:
    from ..harness.accuracy import Column, ScoredCell
    from ..harness.construction import ConstructionCell
    from ..harness.costs import CostCell
    from ..harness.workprecision import WorkPrecisionRow


@dataclass(frozen=True)
class Scoring:
    """How each cell is scored: noise, folds and draws (the same for every cell, so that the
    cells' changes are paired).

    Attributes:
        phase_noise: Gaussian jitter of input spikes [s] (0: none).
        repeats: noise draws per sample.
        seed: seed of noise, folds and inputs.
        folds: CV folds.
        cv_repeats: CV repeats with fresh fold shuffles.
        cv: ``"samples"`` or ``"recordings"`` (folds of whole recordings).
        chip_draws: mismatch draws pooled per cell of a profile that draws mismatch.
        test_recordings: the held-out recordings as typed (``None``: cross-validation).
        jobs: worker processes.
    """

    phase_noise: float
    repeats: int
    seed: int
    folds: int
    cv_repeats: int
    cv: str
    chip_draws: int
    test_recordings: str | None
    jobs: int


@dataclass(frozen=True)
class ReportResults:
    """Everything a report run measured, ready to write.

    Attributes:
        command: the command as typed (``None`` from Python).
        dataset: the dataset's name.
        samples: the number of training (or cross-validated) samples.
        class_names: the dataset's classes.
        test_samples: the number of held-out samples (``None``: cross-validation).
        encoder: the encoder as the summary names it (its settings included).
        encoder_name: the encoder's CLI name.
        encoder_params: every setting of the encoder, JSON-ready.
        network: the network file or preset as given.
        n_spll: sPLLs in its network.
        input_level: ``(level, source)``: what every signal was divided by [the dataset's raw
            unit] and where that level comes from.
        scoring: noise, folds and draws.
        columns: the accuracy table's columns and the backends that computed them.
        cells: every layout × column, scored (:class:`~spll_hw.harness.accuracy.ScoredCell`).
        constructions: the constructions scored against the exact cells, maybe none.
        costs: each layout's NeuroBench metrics on every column, and its fit and cost on every
            chip with tables (:class:`~spll_hw.harness.costs.CostCell`).
        costed_samples: samples of the dataset the costs are averaged over.
        work_precision: the error-against-run-time rows of the backends.
        params_toml: the network and the encoder's settings as ``params.toml`` holds them.
        per_class: the fewest samples of one class the intervals come from (the test samples
            where recordings are held out; ``None``: not known).
        held_out_recordings: the test recordings the intervals resample (``None``:
            cross-validation).
    """

    command: str | None
    dataset: str
    samples: int
    class_names: tuple[str, ...]
    test_samples: int | None
    encoder: str
    encoder_name: str
    encoder_params: dict
    network: str
    n_spll: int
    input_level: tuple[float, str]
    scoring: Scoring
    columns: tuple[Column, ...]
    cells: tuple[ScoredCell, ...]
    constructions: tuple[ConstructionCell, ...]
    costs: tuple[CostCell, ...]
    costed_samples: int
    work_precision: tuple[WorkPrecisionRow, ...]
    params_toml: str
    per_class: int | None = None
    held_out_recordings: int | None = None

    @property
    def small_sample(self) -> bool:
        """Whether the intervals come from fewer than :data:`SMALL_SAMPLE` samples per class
        (or held-out recordings)."""
        few = self.per_class is not None and self.per_class < SMALL_SAMPLE
        return few or (
            self.held_out_recordings is not None and self.held_out_recordings < SMALL_SAMPLE
        )

    def sample_note(self) -> str:
        """One line on the sample size where it is small (empty otherwise): ``"*6 test samples
        per class: intervals are wide; ...*"``."""
        if not self.small_sample:
            return ""
        test = "" if self.held_out_recordings is None else " test"
        held = (
            ""
            if self.held_out_recordings is None
            else f" from {self.held_out_recordings} held-out recordings"
        )
        return (
            f"*{self.per_class}{test} samples per class{held}: intervals are wide; a tie may "
            f"hide a loss and a bold change may not hold, so measure on {SMALL_SAMPLE} or more "
            "per class before relying on either.*"
        )

    @property
    def has_reference(self) -> bool:
        """Whether the exact time-scaled reference cell fits, so every fitting cell has a
        change against it."""
        return any(c.change is not None for c in self.cells)

    def to_dict(self) -> dict:
        """The ``results.json`` payload (changes are the cell minus the reference, negative =
        worse)."""
        s = self.scoring
        return {
            "dataset": self.dataset, "samples": self.samples, "encoder": self.encoder_name,
            "network": self.network,
            "input_level": dict(zip(("level", "source"), self.input_level, strict=True)),
            "columns": {c.label: list(c.specs) for c in self.columns},
            "cv": {"scheme": s.cv, "n_splits": s.folds, "repeats": s.cv_repeats,
                   "noise_draws": s.repeats, "chip_draws": s.chip_draws, "seed": s.seed,
                   "test_recordings": s.test_recordings},
            "encoder_params": self.encoder_params, "accuracy": accuracy_json(self.cells),
            "work_precision": [dataclasses.asdict(r) for r in self.work_precision],
            "costs": [{"layout": c.layout, "column": c.column} | c.to_dict() for c in self.costs],
            "constructions": [c.to_dict() for c in self.constructions],
            "small_sample": self.small_sample, "samples_per_class": self.per_class,
            "held_out_recordings": self.held_out_recordings,
        }  # fmt: skip


def accuracy_json(cells: Sequence[ScoredCell]) -> dict:
    """``{layout: {column: cell}}`` of the scored cells (:meth:`ScoredCell.to_dict`)."""
    out: dict = {}
    for c in cells:
        out.setdefault(c.layout, {})[c.column] = c.to_dict()
    return out

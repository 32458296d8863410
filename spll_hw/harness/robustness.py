"""Robustness of a tuned network's figure: its held-out accuracy, and its gain over a reference
network, with the training recordings, the test recordings and the input scale varied.

A :class:`Variation` trains the ridge classifier on some recordings and tests it once on others
(:func:`~spll_hw.classify.holdout`), with the signals divided by the tuned network file's
``input_level`` (or, without one, the median RMS of the variation's training samples) times a
factor. :func:`standard_variations` gives the check of issue 37: every recording outside the test
block, fewer training recordings, a second disjoint test block, and the scale at ±10 % and ±25 %.

Both networks read the same spike trains (encoded with the tuned file's encoder settings), so
their accuracies pair sample by sample: the change is a bootstrap over the test recordings
(:meth:`~spll_hw.classify.HoldoutResult.change_against`). A sample's phase-noise draw ``r`` is
seeded by ``(seed + r, its index in the loaded set)`` in every variation, so two variations at
one scale share their features and differ only in which recordings train and test. An input
level whose spike trains are bit for bit those of a level already simulated (an encoder that
normalises each sample, such as the Pacinian model at a fixed ``rms_um``, or the peak encoder)
reuses that level's features instead of simulating them again.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..classify import HoldoutResult, combine, holdout
from ..datasets.recordings import format_numbers, recording_numbers
from ..datasets.samples import SampleSet
from ..encoders import Encoder, train_duration
from ..features.spll import spll_features
from ..network import Network
from ..pipeline import encode_samples, jitter


@dataclass(frozen=True)
class Variation:
    """One robustness setting.

    Attributes:
        label: what it varies, for the table (``"train 1-24"``, ``"scale x 0.9"``).
        train, test: recording numbers (:attr:`~spll_hw.datasets.SampleSet.numbers`) the
            classifier trains on and is tested on; disjoint.
        level_factor: the input level is multiplied by it (1.1: every signal reaches the
            encoder 1/1.1 times as large).
    """

    label: str
    train: tuple[int, ...]
    test: tuple[int, ...]
    level_factor: float = 1.0

    def __post_init__(self) -> None:
        if set(self.train) & set(self.test):
            raise ValueError(f"{self.label}: training and test recordings overlap "
                             f"({format_numbers(set(self.train) & set(self.test))})")  # fmt: skip
        if not (np.isfinite(self.level_factor) and self.level_factor > 0):
            raise ValueError(f"{self.label}: level factor must be > 0, got {self.level_factor}")


@dataclass(frozen=True)
class VariationResult:
    """Both networks' held-out results of one :class:`Variation` (``correct`` of shape
    ``(draws, n_test)``) and the input level used [the dataset's raw unit]."""

    variation: Variation
    tuned: HoldoutResult
    reference: HoldoutResult
    level: float

    def to_dict(self) -> dict:
        v = self.variation
        return {
            "label": v.label, "train_recordings": list(v.train), "test_recordings": list(v.test),
            "level_factor": v.level_factor, "input_level": self.level,
            "n_test_samples": int(self.tuned.correct.shape[1]),
            "tuned": self.tuned.accuracy_ci().to_dict(),
            "reference": self.reference.accuracy_ci().to_dict(),
            "change": self.tuned.change_against(self.reference).to_dict(),
        }  # fmt: skip


def standard_variations(
    loaded: Sequence[int],
    test: Sequence[int],
    train_blocks: Sequence[Sequence[int]] = (),
    test_blocks: Sequence[Sequence[int]] = (),
    level_factors: Sequence[float] = (0.75, 0.9, 1.1, 1.25),
) -> list[Variation]:
    """The baseline (train on every ``loaded`` recording outside ``test``, test on ``test``),
    then one variation per training block of ``train_blocks`` (tested on ``test``), per extra
    test block of ``test_blocks`` (trained on every other loaded recording) and per factor of
    ``level_factors`` (the baseline's recordings at that input level)."""
    loaded, test = sorted(set(loaded)), tuple(sorted(set(test)))
    others = tuple(n for n in loaded if n not in test)
    out = [Variation(f"baseline: train {format_numbers(others)}", others, test)]
    out += [Variation(f"train {format_numbers(b)}", tuple(sorted(b)), test) for b in train_blocks]
    for block in test_blocks:
        rest = tuple(n for n in loaded if n not in block)
        out.append(Variation(f"test {format_numbers(block)}", rest, tuple(sorted(block))))
    out += [Variation(f"scale x {f:g}", others, test, float(f)) for f in level_factors]
    return out


def score_variations(
    samples: SampleSet,
    encoder: Encoder,
    tuned: Network,
    reference: Network,
    variations: Sequence[Variation],
    input_level: float | None = None,
    phase_noise: float = 5e-4,
    repeats: int = 3,
    seed: int = 0,
    backend: str = "golden",
    jobs: int = 1,
    say: Callable[[str], None] = lambda line: None,
) -> list[VariationResult]:
    """Score ``tuned`` and ``reference`` (``spll`` features, ridge classifier) on every
    variation (module docstring). ``samples`` hold every recording any variation names (raw
    units, numbered); ``input_level`` is the tuned file's level [raw unit] or ``None``.
    ``ValueError`` names a variation whose recordings are not loaded or leave a class out."""
    numbers = recording_numbers(samples, "a robustness check")
    window = train_duration(encoder, samples.duration)
    features: dict[float, dict[str, list[np.ndarray]]] = {}
    simulated: list[tuple[float, list[np.ndarray]]] = []  # (level, its spike trains)
    out = []
    for v in variations:
        train, test = _masks(samples, numbers, v)
        base, _ = samples.subset(np.flatnonzero(train)).input_scale(input_level)
        level = base * v.level_factor
        if level not in features:
            say(f"{v.label}: encoding {len(samples)} samples at input level {level:.6g}")
            trains = encode_samples(encoder, samples.normalized(level, "robustness"), jobs)
            same = next((lv for lv, t in simulated if _identical(t, trains)), None)
            if same is not None:
                say(f"{v.label}: the spike trains are those at input level {same:.6g} "
                    f"(the encoder ignores the scale): their features reused")  # fmt: skip
                features[level] = features[same]
            else:
                simulated.append((level, trains))
                noisy = [jitter(trains, phase_noise, window, seed + r) for r in range(repeats)]
                features[level] = {
                    name: [spll_features(t, window, net, threads=jobs, backend=backend)
                           for t in noisy]
                    for name, net in (("tuned", tuned), ("reference", reference))
                }  # fmt: skip
        scored = {
            name: combine([
                holdout(x[train], samples.labels[train], x[test], samples.labels[test],
                        samples.recordings[test], samples.class_names, seed=seed)
                for x in per_draw
            ])
            for name, per_draw in features[level].items()
        }  # fmt: skip
        out.append(VariationResult(v, scored["tuned"], scored["reference"], level))
        say(f"{v.label}: tuned {100 * scored['tuned'].accuracy:.1f} %, reference "
            f"{100 * scored['reference'].accuracy:.1f} %")  # fmt: skip
    return out


def _identical(a: Sequence[np.ndarray], b: Sequence[np.ndarray]) -> bool:
    """Whether two lists of spike trains are bit for bit the same."""
    return len(a) == len(b) and all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))


def _masks(samples: SampleSet, numbers: np.ndarray, v: Variation) -> tuple[np.ndarray, ...]:
    """Boolean masks ``(n,)`` of ``v``'s training and test samples; ``ValueError`` when a
    recording of ``v`` is not loaded or a class has no sample on one side."""
    missing = sorted((set(v.train) | set(v.test)) - set(numbers.tolist()))
    if missing:
        raise ValueError(f"{v.label}: recording(s) {format_numbers(missing)} are not loaded "
                         f"(loaded: {format_numbers(numbers.tolist())})")  # fmt: skip
    masks = np.isin(numbers, v.train), np.isin(numbers, v.test)
    for mask, side in zip(masks, ("training", "test"), strict=True):
        absent = sorted(set(range(samples.n_classes)) - set(samples.labels[mask].tolist()))
        if absent:
            names = [samples.class_names[k] for k in absent]
            raise ValueError(f"{v.label}: class(es) {names} have no {side} samples")
    return masks

"""The texture pipeline end to end (thesis Figure 1): samples → encoders → features → accuracy.

:func:`run_pipeline` normalises the samples by their dataset's median RMS
(:meth:`~spll_hw.datasets.SampleSet.normalized`), computes the ``spectrum`` features from the
pressure signals once, encodes every sample with every encoder (in parallel over samples), turns
the spike trains into ``sfft`` / ``isi`` / ``spll`` features and cross-validates a ridge
classifier on each feature set (:mod:`spll_hw.classify`).

Phase noise (thesis 2.9): with ``phase_noise > 0`` every spike train is jittered before feature
extraction, ``repeats`` times with different noise; each repeat trains its own classifiers (same
folds) and the reported accuracy pools all repeats' folds, as the thesis averages three classifiers.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass, field

import numpy as np
from tqdm.auto import tqdm

from .classify import CVResult, HoldoutResult, combine, cross_validate, holdout
from .config import NetworkConfig
from .datasets import SampleSet
from .encoders import Encoder, train_duration
from .features import FEATURES, SPIKE_FEATURES, isi_edges, isi_features, sfft_features
from .features.spectrum import pressure_spectrum_features
from .features.spll import spll_features
from .simulate import add_phase_noise


@dataclass(frozen=True)
class PipelineConfig:
    """Settings of one pipeline run.

    Attributes:
        features: feature names from :data:`~spll_hw.features.FEATURES`.
        phase_noise: standard deviation [s] of the spike-time jitter (0: none).
        repeats: noise draws per sample when ``phase_noise > 0``.
        seed: seed of the noise draws and of the CV fold shuffling.
        n_splits: CV folds.
        cv: ``"samples"`` (stratified folds of samples) or ``"recordings"`` (folds of whole
            recordings, :attr:`~spll_hw.datasets.SampleSet.recordings`: no recording is cut
            between a training and a test fold).
        alpha: ridge L2 penalty.
        isi_spacing: ISI bin spacing, ``"linear"`` or ``"geometric"``.
        network: sPLL network for ``spll``: a preset (:mod:`spll_hw.presets`) or a network
            TOML file such as a tuning study's ``best.toml``; ``{encoder}`` in it is
            replaced by each encoder's name, so ``"biotac-vary-offset-{encoder}"`` gives every
            encoder its own tuned network.
        backend: simulator of the ``spll`` features (a spec of :mod:`spll_hw.backends`, e.g.
            ``golden-fixed-point:profile=loihi2`` for a chip's own arithmetic).
        jobs: worker processes for encoding / engine threads for ``spll``.
        progress: show progress bars.
    """

    features: tuple[str, ...] = ("spectrum", "sfft", "isi")
    phase_noise: float = 0.0
    repeats: int = 1
    seed: int = 0
    n_splits: int = 5
    cv: str = "samples"
    alpha: float = 1.0
    isi_spacing: str = "linear"
    network: str = "biotac-vary-offset-lif"
    backend: str = "golden"
    jobs: int = 1
    progress: bool = False

    def __post_init__(self) -> None:
        unknown = [f for f in self.features if f not in FEATURES]
        if unknown or not self.features:
            raise ValueError(f"unknown feature(s) {unknown}; choose from {list(FEATURES)}")
        if not (np.isfinite(self.phase_noise) and self.phase_noise >= 0):
            raise ValueError(f"phase noise must be >= 0 s, got {self.phase_noise!r}")
        if self.cv not in ("samples", "recordings"):
            raise ValueError(f"cv must be 'samples' or 'recordings', got {self.cv!r}")
        if self.repeats < 1 or self.jobs < 1 or self.n_splits < 2:
            raise ValueError("repeats and jobs must be >= 1 and n_splits >= 2")

    def network_for(self, encoder: str) -> str:
        """The sPLL network (preset or TOML file) used for spike trains of ``encoder``."""
        return self.network.replace("{encoder}", encoder)

    @property
    def n_repeats(self) -> int:
        """Noise draws actually used (1 without phase noise: repeats would be identical)."""
        return self.repeats if self.phase_noise > 0 else 1


@dataclass
class FeatureResult:
    """Cross-validated accuracy of one encoder × feature (``encoder`` is None for ``spectrum``).

    ``features`` are those of the first repeat, shape ``(n, d)``; ``seconds`` is the wall time of
    one extraction over the whole dataset (mean over repeats), excluding encoding.
    """

    encoder: str | None
    feature: str
    cv: CVResult
    features: np.ndarray
    seconds: float

    def to_dict(self) -> dict:
        return {
            "encoder": self.encoder,
            "feature": self.feature,
            "seconds": self.seconds,
        } | self.cv.to_dict()


@dataclass
class PipelineResult:
    """Everything a report needs: dataset summary, per-encoder trains and timings, results.
    ``input_level`` is what every signal was divided by before encoding [the dataset's raw
    unit] (a network file's ``input_level``, or the training samples' median RMS)."""

    samples: SampleSet
    config: PipelineConfig
    test: SampleSet | None = None
    input_level: float | None = None
    encoder_params: dict[str, dict] = field(default_factory=dict)
    encode_seconds: dict[str, float] = field(default_factory=dict)
    trains: dict[str, list[np.ndarray]] = field(default_factory=dict)
    windows: dict[str, float] = field(default_factory=dict)
    results: list[FeatureResult] = field(default_factory=list)

    def get(self, encoder: str | None, feature: str) -> FeatureResult:
        for r in self.results:
            if r.encoder == encoder and r.feature == feature:
                return r
        raise KeyError((encoder, feature))

    def mean_rate(self, encoder: str) -> float:
        """Mean spike rate [Hz] of ``encoder``'s trains over their window (:attr:`windows`)."""
        return float(np.mean([t.size for t in self.trains[encoder]]) / self.windows[encoder])

    def to_dict(self) -> dict:
        return {
            "dataset": self.samples.summary(),
            "config": asdict(self.config),
            "encoders": {
                name: {
                    "params": params,
                    "encode_seconds": self.encode_seconds[name],
                    "mean_rate_hz": self.mean_rate(name),
                    "train_duration_s": self.windows[name],
                }
                for name, params in self.encoder_params.items()
            },  # fmt: skip
            "results": [r.to_dict() for r in self.results],
            "input_level": self.input_level,
        }


def _encode_chunk(
    encoder: Encoder, signals: np.ndarray, fs: float, ids: np.ndarray
) -> list[np.ndarray]:
    return encoder.encode(signals, fs, ids=ids)


def encode_samples(
    encoder: Encoder, samples: SampleSet, jobs: int = 1, progress: bool = False
) -> list[np.ndarray]:
    """Spike trains of every sample, encoded in ``4 * jobs`` chunks over ``jobs`` processes.

    A stochastic encoder seeds each sample's noise by :attr:`SampleSet.noise_ids` (its recording
    window), so a sample's train does not depend on the other samples, their order or the
    chunking."""
    n = len(samples)
    ids = samples.noise_ids
    bounds = np.linspace(0, n, min(n, 4 * jobs) + 1).round().astype(int)
    chunks = [np.arange(a, b) for a, b in zip(bounds[:-1], bounds[1:], strict=True) if b > a]
    bar = tqdm(total=n, desc=f"encoding ({encoder.name})", unit="sample", disable=not progress)
    out: list[np.ndarray] = []
    with bar:
        if jobs == 1:
            for idx in chunks:
                out.extend(_encode_chunk(encoder, samples.signals[idx], samples.fs, ids[idx]))
                bar.update(idx.size)
            return out
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = [
                pool.submit(_encode_chunk, encoder, samples.signals[idx], samples.fs, ids[idx])
                for idx in chunks
            ]
            for fut, idx in zip(futures, chunks, strict=True):
                out.extend(fut.result())
                bar.update(idx.size)
    return out


def jitter(
    trains: Sequence[np.ndarray], sigma: float, duration: float, seed: int
) -> list[np.ndarray]:
    """Phase noise on every train (:func:`spll_hw.simulate.add_phase_noise`), train ``i`` with a
    generator seeded by ``(seed, i)``; ``sigma = 0`` returns the trains unchanged."""
    return [
        add_phase_noise(
            np.asarray(t, dtype=float), sigma, np.random.default_rng([seed, i]), duration
        )
        for i, t in enumerate(trains)
    ]


def spike_features(
    feature: str,
    trains: Sequence[np.ndarray],
    duration: float,
    config: PipelineConfig,
    encoder: str = "",
    network=None,
) -> np.ndarray:
    """``sfft``, ``isi`` or ``spll`` features of ``trains`` (shape ``(n, d)``) from ``encoder``;
    ``spll`` runs ``network`` (a :class:`~spll_hw.network.Network`; default: the one
    ``config`` names for ``encoder``, :func:`encoder_network`)."""
    if feature == "sfft":
        return sfft_features(trains, duration)
    if feature == "isi":
        return isi_features(trains, isi_edges(spacing=config.isi_spacing))
    if feature == "spll":
        network = network if network is not None else encoder_network(config, encoder)
        desc = f"spll ({encoder})"
        with tqdm(total=len(trains), desc=desc, unit="sample", disable=not config.progress) as bar:
            return spll_features(
                trains,
                duration,
                network,
                threads=config.jobs,
                on_chunk=bar.update,
                backend=config.backend,
            )
    raise ValueError(
        f"{feature!r} is not a spike-train feature; choose from {list(SPIKE_FEATURES)}"
    )


def encoder_network(config: PipelineConfig, encoder: str):
    """The :class:`~spll_hw.network.Network` of ``encoder``'s ``spll`` features: the preset or
    file ``config.network_for(encoder)``, read and built."""
    return NetworkConfig.load(config.network_for(encoder)).build()


def run_pipeline(
    samples: SampleSet,
    encoders: Sequence[Encoder],
    config: PipelineConfig,
    test: SampleSet | None = None,
    networks: Mapping | None = None,
    input_level: float | None = None,
) -> PipelineResult:
    """Run the pipeline (module docstring) and return every accuracy and timing.

    With ``test`` (held-out recordings of the same classes, scaled like ``samples``) every
    feature set trains on all of ``samples`` and is scored once on ``test``
    (:func:`~spll_hw.classify.holdout`) instead of by cross-validation. ``networks`` maps an
    encoder's name to the built network of its ``spll`` features, for a caller that has read
    the files already; an encoder it leaves out gets :func:`encoder_network` (read once).
    Every signal (``test``'s too) is divided by ``input_level`` [the dataset's raw unit] (the
    level a network file's encoder was tuned at), or without one by the median RMS of
    ``samples`` (:meth:`~spll_hw.datasets.SampleSet.normalized`).
    """
    level, source = samples.input_scale(input_level)
    samples = samples.normalized(level, source)
    result = PipelineResult(samples=samples, config=config, input_level=level)
    labels, names = samples.labels, samples.class_names
    n_train = len(samples)
    groups = samples.recordings if config.cv == "recordings" else None
    if test is not None:
        test = test.normalized(level, source)
        result.test = test
        samples = samples.joined(test)  # features of both, in one pass

    def evaluate(features: np.ndarray) -> CVResult | HoldoutResult:
        if test is None:
            return cross_validate(
                features, labels, names, config.n_splits, config.alpha, config.seed, groups=groups
            )
        return holdout(
            features[:n_train], labels, features[n_train:], test.labels, test.recordings, names,
            config.alpha, config.seed,
        )  # fmt: skip

    if "spectrum" in config.features:
        start = time.perf_counter()
        x = pressure_spectrum_features(samples.signals, samples.fs)
        result.results.append(
            FeatureResult(None, "spectrum", evaluate(x), x, time.perf_counter() - start)
        )
    spike_feats = [f for f in config.features if f in SPIKE_FEATURES]
    if not spike_feats:
        return result
    for encoder in encoders:
        start = time.perf_counter()
        trains = encode_samples(encoder, samples, config.jobs, config.progress)
        result.encode_seconds[encoder.name] = time.perf_counter() - start
        result.encoder_params[encoder.name] = asdict(encoder)
        result.trains[encoder.name] = trains
        window = result.windows[encoder.name] = train_duration(encoder, samples.duration)
        network = None
        if "spll" in spike_feats:
            network = (networks or {}).get(encoder.name) or encoder_network(config, encoder.name)
        for feature in spike_feats:
            cvs, first, seconds = [], None, 0.0
            for r in range(config.n_repeats):
                noisy = jitter(trains, config.phase_noise, window, config.seed + r)
                start = time.perf_counter()
                x = spike_features(feature, noisy, window, config, encoder.name, network)
                seconds += time.perf_counter() - start
                first = x if first is None else first
                cvs.append(evaluate(x))
            result.results.append(
                FeatureResult(
                    encoder.name, feature, combine(cvs), first, seconds / config.n_repeats
                )
            )
    return result
